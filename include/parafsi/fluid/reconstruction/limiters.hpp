/// \file limiters.hpp
/// Slope limiters on one-sided gradients a = (W_i − W_{i−1})/Δx_{i−½} and
/// b = (W_{i+1} − W_i)/Δx_{i+½} (per unit length, so non-uniform grids are handled):
///   minmod:   ½(sgn a + sgn b) min(|a|, |b|)
///   van Leer: (a b + |a b|)/(a + b)            (harmonic mean; 0 if a b ≤ 0)
///   MC:       minmod(2a, 2b, (a + b)/2)        (monotonised central)
/// All three are TVD: the face values W_i ± ½Δx_i·slope stay within the neighbours'
/// range, which also keeps reconstructed density and pressure positive.
/// References: van Leer B. (1974) J. Comput. Phys. 14:361; van Leer B. (1977)
///   J. Comput. Phys. 23:276; Roe P.L. (1986) Annu. Rev. Fluid Mech. 18:337.
#pragma once
#include "../../core/simd.hpp"

namespace parafsi::limiter {

struct minmod {
  static constexpr const char* name() noexcept { return "minmod"; }
  template <class V>
  PARAFSI_INLINE V operator()(const V& a, const V& b) const noexcept {
    const V m = simd::min(simd::abs(a), simd::abs(b));
    return simd::select(a * b > V(0.0), simd::copysign(m, a), V(0.0));
  }
};

struct van_leer {
  static constexpr const char* name() noexcept { return "van_leer"; }
  template <class V>
  PARAFSI_INLINE V operator()(const V& a, const V& b) const noexcept {
    const V ab = a * b;
    return simd::select(ab > V(0.0), V(2.0) * ab / (a + b), V(0.0));
  }
};

struct mc {
  static constexpr const char* name() noexcept { return "mc"; }
  template <class V>
  PARAFSI_INLINE V operator()(const V& a, const V& b) const noexcept {
    const V m = simd::min(simd::min(V(2.0) * simd::abs(a), V(2.0) * simd::abs(b)), V(0.5) * simd::abs(a + b));
    return simd::select(a * b > V(0.0), simd::copysign(m, a), V(0.0));
  }
};

}  // namespace parafsi::limiter
