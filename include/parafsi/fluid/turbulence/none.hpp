/// \file none.hpp
/// No turbulence closure (implicit LES through the scheme's dissipation). The
/// solver allocates no eddy-viscosity field for it.
#pragma once
#include "../../core/policy.hpp"

namespace parafsi::turbulence {

struct none {
  static constexpr bool active = false;
  using policy_kind = kind::turbulence;
  static constexpr const char* name() noexcept { return "none"; }
  double prandtl_t = 0.9;
};

}  // namespace parafsi::turbulence
