/// \file stress_elimination.hpp
/// No-compression fabric by compressive stress elimination (methods §5.3, W1; the
/// analogue of LS-DYNA MAT_FABRIC's compressive stress elimination).
///
/// With principal values s1 ≥ s2 of the elastic second Piola–Kirchhoff stress S:
///   s1 ≤ 0            (slack):    S ← r_c S
///   s1 > 0 > s2       (wrinkled): S ← S − (1 − r_c) s2 p2⊗p2   (= s1 p1⊗p1 + r_c s2 p2⊗p2)
///   s2 ≥ 0            (taut):     S unchanged.
/// p2⊗p2 = (S − s1 I)/(s2 − s1) needs no eigenvector. The viscous (damping) stress D
/// is filtered alike: scaled by r_c when slack, its p2p2 component scaled by r_c when
/// wrinkled, so a wrinkle neither carries nor damps compression.
/// r_c ∈ [1e-3, 1e-2] keeps a small stiffness against zero-energy mechanisms.
///
/// References: Altair Radioss fabric law (RE 0.001–0.01);
///   LS-DYNA Keyword Manual, *MAT_FABRIC (CSE); Roddeman D.G. et al. (1987) J. Appl.
///   Mech. 54:884 (wrinkling of membranes).
#pragma once
#include "../../../core/simd.hpp"
#include "moduli.hpp"

namespace parafsi::structure::wrinkling {

struct stress_elimination {
  double residual = 1e-3;  ///< r_c: fraction of compressive stress kept
  static constexpr const char* name() { return "stress_elimination"; }
  void validate() const {
    require(residual >= 0.0 && residual <= 1.0,
            "wrinkling::stress_elimination: residual factor must be in [0, 1], got ", residual);
  }
  /// Filter the elastic stress S and viscous stress D in place (strain E unused).
  template <class V>
  PARAFSI_INLINE void apply(V& S11, V& S22, V& S12, V& D11, V& D22, V& D12, const V&, const V&, const V&,
                            const fabric_moduli&) const noexcept {
    const V h = V(0.5) * (S11 + S22);
    const V d = V(0.5) * (S11 - S22);
    const V r = simd::sqrt(d * d + S12 * S12);
    const V s1 = h + r, s2 = h - r;
    const auto slack = s1 <= V(0.0);
    const auto wr = (s2 < V(0.0)) & (s1 > V(0.0));
    const V inv = V(1.0) / simd::select(wr, s2 - s1, V(-1.0));
    const V P11 = (S11 - s1) * inv, P22 = (S22 - s1) * inv, P12 = S12 * inv;
    const V k = simd::select(wr, V(1.0 - residual) * s2, V(0.0));
    const V Dp = P11 * D11 + P22 * D22 + V(2.0) * P12 * D12;
    const V kd = simd::select(wr, V(1.0 - residual) * Dp, V(0.0));
    const V f = simd::select(slack, V(residual), V(1.0));
    S11 = (S11 - k * P11) * f;
    S22 = (S22 - k * P22) * f;
    S12 = (S12 - k * P12) * f;
    D11 = (D11 - kd * P11) * f;
    D22 = (D22 - kd * P22) * f;
    D12 = (D12 - kd * P12) * f;
  }
};

}  // namespace parafsi::structure::wrinkling
