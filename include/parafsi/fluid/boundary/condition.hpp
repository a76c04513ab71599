/// \file condition.hpp
/// Boundary condition of one box face (a variant, chosen once per face per stage,
/// never inside a cell loop) and the set of six faces, ordered x−, x+, y−, y+, z−, z+.
/// Optional sponge layer: a source −σ(ξ)(U − U_∞) over the outer `cells` cells next
/// to far-field faces, σ rising as a cubic from 0 to σ_max = strength · c_∞ / L_sponge.
#pragma once
#include <array>
#include <cmath>
#include <string>
#include <variant>

#include "../../core/error.hpp"
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

namespace detail {
/// A prescribed state (far field, inflow) must be a gas: ρ > 0, p > 0, all finite.
template <class B>
void validate_state(const B& b, const char* face) {
  require(std::isfinite(b.rho) && b.rho > 0, "boundary::", b.name(), " on face ", face,
          ": density must be finite and > 0, got ", b.rho);
  require(std::isfinite(b.p) && b.p > 0, "boundary::", b.name(), " on face ", face,
          ": pressure must be finite and > 0, got ", b.p);
  const double u[3] = {b.u.x, b.u.y, b.u.z};
  for (int d = 0; d < 3; ++d)
    require(std::isfinite(u[d]), "boundary::", b.name(), " on face ", face, ": velocity component ", d,
            " must be finite, got ", u[d]);
}
}  // namespace detail

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
  /// Refuse states that are not a gas and a sponge that is not a damping (the solver
  /// calls this at construction), naming the face and the value.
  void validate() const {
    static constexpr const char* names[6] = {"x-", "x+", "y-", "y+", "z-", "z+"};
    for (std::size_t f = 0; f < 6; ++f)
      std::visit(
          [&](const auto& b) {
        if constexpr (requires { b.rho, b.p, b.u; }) detail::validate_state(b, names[f]);
          },
          face[f]);
    require(layer.cells >= 0, "boundary::sponge: cells must be >= 0, got ", layer.cells);
    require(std::isfinite(layer.strength) && layer.strength >= 0,
            "boundary::sponge: strength must be finite and >= 0, got ", layer.strength);
  }
};

}  // namespace parafsi::boundary
