/// \file outflow.hpp
/// Zero-gradient outflow: ghosts copy the adjacent interior cell. Optionally the
/// ghost pressure is held at `p_exit` (subsonic pressure outlet) when `fix_pressure`.
#pragma once
#include "../state.hpp"

namespace parafsi::boundary {
struct outflow {
  bool fix_pressure = false;
  double p_exit = 101325.0;
  static constexpr const char* name() noexcept { return "outflow"; }
  static constexpr bool layer_invariant = true;  ///< the ghost reads the adjacent cell only
  fluid::prim<double> ghost(const fluid::prim<double>&, const fluid::prim<double>& in, const vec3<double>&, double,
                            const gas::ideal&, double) const {
    fluid::prim<double> g = in;
    if (fix_pressure) g.p = p_exit;
    return g;
  }
};
}  // namespace parafsi::boundary
