/// \file tension_field.hpp
/// Tension-field wrinkling model with the mixed stress–strain criterion
/// (methods §5.3, W2; Kang & Im 1997):
///   taut      if the elastic minor principal stress s2 ≥ 0   → S unchanged;
///   slack     if the major principal strain e1 ≤ 0            → S ← r_c S;
///   wrinkled  otherwise → uniaxial tension along the major principal strain
///             direction n1: S ← E(θ) e1 n1⊗n1 + r_c S,
/// with the directional (uniaxial) modulus of the orthotropic law
///   1/E(θ) = c⁴/E1 + (1/G12 − 2ν12/E1) c² s² + s⁴/E2,  c = cos θ, s = sin θ.
/// For an isotropic sheet this is Roddeman's exact tension-field solution (the wrinkling
/// strain absorbs the lateral contraction, tension and major strain are coaxial). For
/// orthotropic fabric the tension direction in general differs from n1 and needs a
/// scalar Newton solve (Miyazaki 2006); this policy keeps n1, an approximation whose
/// error grows with the anisotropy E1/E2 and the angle between n1 and the fibres.
/// The viscous stress D keeps only its n1n1 component (+ r_c D) when wrinkled.
///
/// References: Roddeman D.G. et al. (1987) J. Appl. Mech. 54:884;
///   Kang S., Im S. (1997) J. Appl. Mech. 64:263; Miyazaki Y. (2006) IJNME 66:1179.
#pragma once
#include "../../../core/simd.hpp"
#include "moduli.hpp"

namespace parafsi::structure::wrinkling {

struct tension_field {
  double residual = 1e-3;  ///< r_c: fraction of the elastic stress kept when slack or wrinkled
  static constexpr const char* name() { return "tension_field"; }
  void validate() const {
    require(residual >= 0.0 && residual <= 1.0, "wrinkling::tension_field: residual factor must be in [0, 1], got ",
            residual);
  }
  template <class V>
  PARAFSI_INLINE void apply(V& S11, V& S22, V& S12, V& D11, V& D22, V& D12, const V& E11, const V& E22, const V& E12,
                            const fabric_moduli& q) const noexcept {
    // Elastic principal stresses (criterion only).
    const V hs = V(0.5) * (S11 + S22), ds = V(0.5) * (S11 - S22);
    const V s2 = hs - simd::sqrt(ds * ds + S12 * S12);
    // Principal strains and the major direction n1 = (c, s).
    const V he = V(0.5) * (E11 + E22), de = V(0.5) * (E11 - E22);
    const V re = simd::sqrt(de * de + E12 * E12);
    const V e1 = he + re;
    const auto iso = re <= V(1e-300);
    const V rinv = V(1.0) / simd::select(iso, V(1.0), re);
    const V cos2 = simd::select(iso, V(1.0), de * rinv), sin2 = simd::select(iso, V(0.0), E12 * rinv);
    const V cc = V(0.5) * (V(1.0) + cos2), ss = V(0.5) * (V(1.0) - cos2), cs = V(0.5) * sin2;
    const V compliance = cc * cc / V(q.E1) + V(1.0 / q.G12 - 2.0 * q.nu12 / q.E1) * cc * ss + ss * ss / V(q.E2);
    const V sig = e1 / compliance;
    const auto taut = s2 >= V(0.0);
    const auto slack = e1 <= V(0.0);
    const V rc(residual);
    // Wrinkled values.
    const V Dn = cc * D11 + ss * D22 + V(2.0) * cs * D12;
    const V w11 = sig * cc + rc * S11, w22 = sig * ss + rc * S22, w12 = sig * cs + rc * S12;
    const V v11 = Dn * cc + rc * D11, v22 = Dn * ss + rc * D22, v12 = Dn * cs + rc * D12;
    S11 = simd::select(taut, S11, simd::select(slack, rc * S11, w11));
    S22 = simd::select(taut, S22, simd::select(slack, rc * S22, w22));
    S12 = simd::select(taut, S12, simd::select(slack, rc * S12, w12));
    D11 = simd::select(taut, D11, simd::select(slack, rc * D11, v11));
    D22 = simd::select(taut, D22, simd::select(slack, rc * D22, v22));
    D12 = simd::select(taut, D12, simd::select(slack, rc * D12, v12));
  }
};

}  // namespace parafsi::structure::wrinkling
