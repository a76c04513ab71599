/// \file hllc_lm.hpp
/// HLLC-LM: HLLC with a low-Mach limiter on the acoustic dissipation
/// (Fleischmann, Adami & Adams 2020). Outer upwind switches keep the unlimited
/// S_L, S_R; inside the fan
///   F* = ½(F_L + F_R) + ½[φ S_L (U*_L − U_L) + |S*| (U*_L − U*_R) + φ S_R (U*_R − U_R)],
///   φ = sin(min(1, M_loc / M_lim) π/2),  M_loc = max(|u_nL|/c_L, |u_nR|/c_R),  M_lim = 0.1.
/// With φ = 1 the central form equals HLLC algebraically (a unit test checks it).
/// φ is floored at φ_min = 0.1 (our choice, not the paper's): with φ → 0 the acoustic
/// part of the flux becomes central, and with a limited MUSCL reconstruction acoustic
/// waves in still air then grow grid-scale noise (a 10 Pa pulse leaves ±1 Pa noise,
/// with SSP-RK2 or SSP-RK3 alike). The floor only acts below M_loc ≈ 0.006, far under
/// the parachute's M ≈ 0.02; set phi_min = 0 for the paper's original form.
/// References: Fleischmann N., Adami S., Adams N.A. (2020) J. Comput. Phys. 423:109762,
///   doi:10.1016/j.jcp.2020.109762.
#pragma once
#include "../../core/policy.hpp"
#include <numbers>

#include "hllc_common.hpp"

namespace parafsi::flux {

struct hllc_lm {
  double mach_limit = 0.1;  ///< M_lim: below it the acoustic dissipation is scaled down
  double phi_min = 0.1;      ///< floor on φ: acoustic damping kept below M ≈ 0.006 (see above)

  using policy_kind = kind::flux;
  static constexpr const char* name() noexcept { return "hllc_lm"; }

  /// sin(π x / 2) on [0, 1] by its Taylor series to x⁹ (|error| ≤ 3.6e-6, exact 1 at x = 1):
  /// a few FMAs instead of a full SIMD sine with range reduction.
  template <class V>
  static PARAFSI_INLINE V sin_half_pi(const V& x) noexcept {
    constexpr double a = 0.5 * std::numbers::pi;
    constexpr double c1 = a, c3 = -a * a * a / 6, c5 = a * a * a * a * a / 120,
                     c7 = -a * a * a * a * a * a * a / 5040, c9 = a * a * a * a * a * a * a * a * a / 362880;
    const V x2 = x * x;
    const V s = x * (V(c1) + x2 * (V(c3) + x2 * (V(c5) + x2 * (V(c7) + x2 * V(c9)))));
    return simd::select(x >= V(1.0), V(1.0), s);
  }

  template <class V>
  PARAFSI_INLINE fluid::cons<V> operator()(const fluid::prim<V>& L, const fluid::prim<V>& R,
                                           const vec3<double>& n, const gas::ideal& g) const noexcept {
    using fluid::select;
    const auto h = detail::hllc_prepare(L, R, n, g);
    // M_loc = max(|u_nL|/c_L, |u_nR|/c_R) with one division.
    const V mloc = simd::max(simd::abs(h.unL) * h.cR, simd::abs(h.unR) * h.cL) / (h.cL * h.cR);
    const V phi0 = sin_half_pi(simd::min(V(1.0), mloc * V(1.0 / mach_limit)));
    const V phi = simd::max(phi0, V(phi_min));
    const auto central = (h.FL + h.FR) * V(0.5) +
                         ((h.UsL - h.UL) * (phi * h.SL) + (h.UsL - h.UsR) * simd::abs(h.Sstar) +
                          (h.UsR - h.UR) * (phi * h.SR)) * V(0.5);
    return select<V>(h.SL >= V(0.0), h.FL, select<V>(h.SR <= V(0.0), h.FR, central));
  }
};

}  // namespace parafsi::flux
