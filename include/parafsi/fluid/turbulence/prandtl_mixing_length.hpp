/// \file prandtl_mixing_length.hpp
/// Prandtl mixing-length eddy viscosity, generalised to 3-D:
///   μ_t = ρ l_m² |S|,  |S| = √(2 S_ij S_ij),
///   l_m = min(κ d_w, C_l L_ref, C_Δ Δ),  Δ = (h_x h_y h_z)^{1/3},
/// with d_w the distance to the nearest body (a per-cell field the user or the
/// coupling fills; +∞ where unknown), κ = 0.41, C_l ≈ 0.07 for wakes and shear layers
/// and L_ref the body size (the canopy's nominal diameter). μ_t is capped at
/// `mu_cap` (Pa s; 1000 × air's viscosity by default) for robustness.
/// References: Prandtl L. (1925) ZAMM 5:136; Wilcox D.C., Turbulence Modeling for CFD,
///   3rd ed., ch. 3; Pope S.B. (2000) Turbulent Flows, §10.3.
#pragma once
#include <algorithm>

#include "../../core/error.hpp"
#include "../../core/policy.hpp"
#include "../../core/simd.hpp"

namespace parafsi::turbulence {

struct prandtl_mixing_length {
  static constexpr bool active = true;
  static constexpr bool needs_wall_distance = true;
  using policy_kind = kind::turbulence;
  static constexpr const char* name() noexcept { return "prandtl_mixing_length"; }
  double kappa = 0.41;      ///< von Kármán constant
  double c_l = 0.07;        ///< mixing length / reference length in free shear flows
  double ref_length = 1.0;  ///< L_ref (m), e.g. the canopy's nominal diameter D0
  double c_delta = 1.0;     ///< cap: l_m ≤ C_Δ Δ (grid scale)
  double prandtl_t = 0.9;   ///< turbulent Prandtl number
  double mu_cap = 1.79e-2;  ///< upper bound on μ_t (Pa s), 1000 × air's μ by default

  void validate() const {
    require(kappa > 0 && c_l > 0 && ref_length > 0 && c_delta > 0,
            "turbulence::prandtl_mixing_length: constants must be positive");
  }
  /// The wall distance beyond which d_w no longer sets l_m in cells whose grid scale Δ is
  /// at most `delta`: min(C_l L_ref, C_Δ delta)/κ (1e-9 over it where the grid cap binds,
  /// for rounding), so a distance field may stop there (1e30 beyond) and give the same μ_t
  /// bit for bit; C_l L_ref/κ for delta = ∞.
  double wall_reach(double delta) const noexcept {
    const double reach = c_l * ref_length / kappa;
    return std::min(reach, std::min(c_l * ref_length, c_delta * delta) / kappa * (1.0 + 1e-9));
  }
  template <class V>
  PARAFSI_INLINE V eddy_viscosity(const V& rho, const V& S_norm, const V& delta,
                                  const V& wall_distance) const noexcept {
    const V lm = simd::min(simd::min(V(kappa) * wall_distance, V(c_l * ref_length)), V(c_delta) * delta);
    return simd::min(rho * lm * lm * S_norm, V(mu_cap));
  }
};

}  // namespace parafsi::turbulence
