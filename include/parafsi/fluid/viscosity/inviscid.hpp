/// \file inviscid.hpp
/// No molecular viscosity or heat conduction (Euler equations). With
/// `turbulence::none` the solver then has no viscous pass and no gradient storage.
#pragma once
#include "../../core/policy.hpp"

namespace parafsi::viscosity {

struct inviscid {
  static constexpr bool active = false;
  using policy_kind = kind::viscosity;
  static constexpr const char* name() noexcept { return "inviscid"; }
  double prandtl = 0.72;
  template <class V>
  V mu(const V&) const noexcept {
    return V(0.0);
  }
};

}  // namespace parafsi::viscosity
