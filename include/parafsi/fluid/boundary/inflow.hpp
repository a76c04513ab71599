/// \file inflow.hpp
/// Prescribed inflow: the ghost cells hold a fixed primitive state (inertial
/// velocity), e.g. a uniform stream entering a duct.
#pragma once
#include "../state.hpp"

namespace parafsi::boundary {
struct inflow {
  double rho = 1.18;
  vec3<double> u{0.0, 0.0, 0.0};
  double p = 101325.0;
  static constexpr const char* name() noexcept { return "inflow"; }
  static constexpr bool layer_invariant = true;  ///< the ghost reads the adjacent cell only
  fluid::prim<double> ghost(const fluid::prim<double>&, const fluid::prim<double>&, const vec3<double>&, double,
                            const gas::ideal&, double) const {
    return {rho, u, p};
  }
};
}  // namespace parafsi::boundary
