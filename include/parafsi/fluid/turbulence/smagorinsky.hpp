/// \file smagorinsky.hpp
/// Smagorinsky subgrid eddy viscosity  μ_t = ρ (C_s Δ)² |S|,  Δ = (h_x h_y h_z)^{1/3},
/// C_s = 0.1 for shear flows (0.17 for isotropic turbulence).
/// Reference: Smagorinsky J. (1963) Mon. Weather Rev. 91:99.
#pragma once
#include "../../core/error.hpp"
#include "../../core/policy.hpp"
#include "../../core/simd.hpp"

namespace parafsi::turbulence {

struct smagorinsky {
  static constexpr bool active = true;
  static constexpr bool needs_wall_distance = false;
  using policy_kind = kind::turbulence;
  static constexpr const char* name() noexcept { return "smagorinsky"; }
  double cs = 0.1;
  double prandtl_t = 0.9;
  double mu_cap = 1.79e-2;
  void validate() const { require(cs > 0.0, "turbulence::smagorinsky: C_s must be > 0, got ", cs); }
  template <class V>
  PARAFSI_INLINE V eddy_viscosity(const V& rho, const V& S_norm, const V& delta,
                                  const V& /*wall_distance*/) const noexcept {
    const V l = V(cs) * delta;
    return simd::min(rho * l * l * S_norm, V(mu_cap));
  }
};

}  // namespace parafsi::turbulence
