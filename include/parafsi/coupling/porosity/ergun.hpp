/// \file ergun.hpp
/// Ergun law of a porous fabric (the paper's Eq. 7, Ergun 1952):
///   Δp / t = α V + β V |V|,
/// Δp the pressure jump across the fabric (Pa), t its thickness (m), V the normal
/// through-velocity relative to the fabric (m/s), α (kg m⁻³ s⁻¹) the viscous and
/// β (kg m⁻⁴) the inertial coefficient. The law is odd in V.
/// Inverse, exact and free of cancellation (the root of β t V² + α t V − |Δp| = 0):
///   V = sign(Δp) · 2|Δp| / (α t + √((α t)² + 4 β t |Δp|)).
/// With β = 0 this is Darcy's law; with α = 0 a pure quadratic (orifice) law.
/// Reference: Ergun S. (1952) Chem. Eng. Prog. 48:89; parachute use: Aquelet & Tutt,
///   Int. J. Multiphysics 1 (2007) 1, doi:10.1260/175095407780130517.
#pragma once
#include <cmath>

#include "../../core/error.hpp"
#include "../../core/simd.hpp"
#include "../kinds.hpp"

namespace parafsi::porosity {

struct ergun {
  double alpha = 0;      ///< α, viscous coefficient (kg m⁻³ s⁻¹)
  double beta = 0;       ///< β, inertial coefficient (kg m⁻⁴)
  double thickness = 0;  ///< t, fabric thickness (m)

  using policy_kind = kind::porosity;
  static constexpr bool permeable = true;
  static constexpr const char* name() noexcept { return "ergun"; }

  void validate() const {
    require(std::isfinite(alpha) && alpha >= 0, "porosity::ergun: alpha must be >= 0, got ", alpha);
    require(std::isfinite(beta) && beta >= 0, "porosity::ergun: beta must be >= 0, got ", beta);
    require(alpha > 0 || beta > 0, "porosity::ergun: alpha and beta are both 0 (a fully open fabric: use no coupling)");
    require(std::isfinite(thickness) && thickness > 0, "porosity::ergun: thickness must be > 0, got ", thickness);
  }

  /// Δp(V) = t (α V + β V |V|) (Pa).
  template <class V>
  PARAFSI_INLINE V pressure_jump(const V& u) const noexcept {
    return V(thickness) * (V(alpha) * u + V(beta) * u * simd::abs(u));
  }
  /// dΔp/dV = t (α + 2 β |V|) (Pa s/m).
  template <class V>
  PARAFSI_INLINE V resistance(const V& u) const noexcept {
    return V(thickness) * (V(alpha) + V(2.0 * beta) * simd::abs(u));
  }
  /// V(Δp), the exact inverse of pressure_jump.
  template <class V>
  PARAFSI_INLINE V through_velocity(const V& dp) const noexcept {
    const V a = V(alpha * thickness), b = V(beta * thickness);
    const V m = simd::abs(dp);
    const V den = a + simd::sqrt(a * a + V(4.0) * b * m);
    return simd::copysign(V(2.0) * m / den, dp);
  }
  /// dV/dΔp at Δp = 1 / resistance(V(Δp)).
  template <class V>
  PARAFSI_INLINE V compliance(const V& dp) const noexcept {
    return V(1.0) / resistance(through_velocity(dp));
  }
};

}  // namespace parafsi::porosity
