/// \file condition.hpp
/// Boundary condition of one box face (a variant, chosen once per face per stage,
/// never inside a cell loop) and the set of six faces, ordered x−, x+, y−, y+, z−, z+.
/// Optional sponge layer: a source −σ(ξ)(U − U_∞) over the outer `cells` cells next
/// to far-field faces, σ rising as a cubic from 0 to σ_max = strength · c_∞ / L_sponge.
#pragma once
#include <array>
#include <string>
#include <variant>

#include "far_field.hpp"
#include "inflow.hpp"
#include "outflow.hpp"
#include "periodic.hpp"
#include "slip_wall.hpp"

namespace parafsi::boundary {

using condition = std::variant<far_field, slip_wall, periodic, inflow, outflow>;

inline std::string name_of(const condition& c) {
  return std::visit([](const auto& b) { return std::string(b.name()); }, c);
}

struct sponge {
  int cells = 0;          ///< sponge thickness in cells (0: off)
  double strength = 0.5;  ///< σ_max L_sponge / c_∞
};

struct set {
  std::array<condition, 6> face{far_field{}, far_field{}, far_field{}, far_field{}, far_field{}, far_field{}};
  sponge layer{};

  static set all(const condition& c) {
    set s;
    s.face.fill(c);
    return s;
  }
  set& axis(int d, const condition& c) {
    face[std::size_t(2 * d)] = c;
    face[std::size_t(2 * d + 1)] = c;
    return *this;
  }
  set& side(int d, int hi, const condition& c) {
    face[std::size_t(2 * d + hi)] = c;
    return *this;
  }
};

}  // namespace parafsi::boundary
