/// \file hllc_lm.hpp
/// HLLC-LM: HLLC with a low-Mach limiter on the acoustic dissipation
/// (Fleischmann, Adami & Adams 2020). Outer upwind switches keep the unlimited
/// S_L, S_R; inside the fan
///   F* = ½(F_L + F_R) + ½[φ S_L (U*_L − U_L) + |S*| (U*_L − U*_R) + φ S_R (U*_R − U_R)],
///   φ = sin(min(1, M_loc / M_lim) π/2),  M_loc = max(|u_nL|/c_L, |u_nR|/c_R),  M_lim = 0.1.
/// With φ = 1 the central form equals HLLC algebraically (a unit test checks it).
/// Acoustic floor (our addition, not the paper's): φ ≥ φ_min · r with the sensor
///   r = min(1, a/b) · min(1, K b/a),  a = |p_R − p_L|,  b = ρ̄ c̄ |u_nR − u_nL|,  K = 2,
/// which is 1 across acoustic waves (Δp ≈ ρ c Δu), ≈ M across vortical low-Mach flow
/// (Δp ~ ρ u Δu) and ≈ 0 across a pressure jump held by a wall or an immersed membrane
/// (Δp ≫ ρ c Δu). Without it (φ_min = 0, the paper's form) the acoustic part of the flux
/// becomes central as M → 0 and, with a limited MUSCL reconstruction, acoustic waves in
/// still air grow grid-scale noise (a 10 Pa pulse left ±1 Pa of noise, with SSP-RK2 or
/// SSP-RK3 alike) and the Gresho vortex at M = 0.001 went unstable. With φ_min = 1
/// (default) acoustic waves get HLLC's dissipation and vortical flow keeps the low-Mach
/// reduction: Gresho KE retention at t = 0.1, 32² cells: 0.980 / 0.960 / 0.892 at
/// M = 0.1 / 0.01 / 0.001 (HLLC: 0.966 / 0.803 / 0.522), acoustic noise 0.003 Pa. The
/// upper cut K keeps the low-Mach reduction at membrane pressure jumps, where it limits
/// the numerical leak of penalty coupling (methods.md §4.8): piston pressure rise
/// −6.7 % of ρcv at PFAC 1 (−13.7 % with K = ∞, −4.6 % with φ_min = 0).
/// References: Fleischmann N., Adami S., Adams N.A. (2020) J. Comput. Phys. 423:109762,
///   doi:10.1016/j.jcp.2020.109762.
#pragma once
#include <numbers>
#include "../../core/policy.hpp"

#include "hllc_common.hpp"

namespace parafsi::flux {

struct hllc_lm {
  double mach_limit = 0.1;     ///< M_lim: below it the acoustic dissipation is scaled down
  double phi_min = 1.0;        ///< acoustic floor: φ ≥ φ_min · r, r the acoustic sensor (see above)
  double acoustic_band = 2.0;  ///< K: jumps with |Δp| > K ρc|Δu_n| are not acoustic (walls, membranes)

  using policy_kind = kind::flux;
  static constexpr const char* name() noexcept { return "hllc_lm"; }

  /// sin(π x / 2) on [0, 1] by its Taylor series to x⁹ (|error| ≤ 3.6e-6, exact 1 at x = 1):
  /// a few FMAs instead of a full SIMD sine with range reduction.
  template <class V>
  static PARAFSI_INLINE V sin_half_pi(const V& x) noexcept {
    constexpr double a = 0.5 * std::numbers::pi;
    constexpr double c1 = a, c3 = -a * a * a / 6, c5 = a * a * a * a * a / 120, c7 = -a * a * a * a * a * a * a / 5040,
                     c9 = a * a * a * a * a * a * a * a * a / 362880;
    const V x2 = x * x;
    const V s = x * (V(c1) + x2 * (V(c3) + x2 * (V(c5) + x2 * (V(c7) + x2 * V(c9)))));
    return simd::select(x >= V(1.0), V(1.0), s);
  }

  template <class V>
  PARAFSI_INLINE fluid::cons<V> operator()(const fluid::prim<V>& L, const fluid::prim<V>& R, const vec3<double>& n,
                                           const gas::ideal& g) const noexcept {
    using fluid::select;
    const auto h = detail::hllc_prepare(L, R, n, g);
    // M_loc = max(|u_nL|/c_L, |u_nR|/c_R) with one division.
    const V mloc = simd::max(simd::abs(h.unL) * h.cR, simd::abs(h.unR) * h.cL) / (h.cL * h.cR);
    const V phi0 = sin_half_pi(simd::min(V(1.0), mloc * V(1.0 / mach_limit)));
    // Acoustic sensor (a = |Δp|, b = ρ̄ c̄ |Δu_n|): r = min(1, a/b) · min(1, K b/a) is 1
    // across acoustic waves (a ≈ b), ≈ M across vortical low-Mach flow (a ≪ b) and ≈ 0
    // across a pressure jump held by a wall or membrane (a > K b); the floor acts on
    // acoustic jumps only.
    const V a = simd::abs(R.p - L.p);
    const V b = V(0.5) * (L.rho * h.cL + R.rho * h.cR) * simd::abs(h.unR - h.unL);
    const V r = simd::min(V(1.0), a / (b + V(1e-300))) * simd::min(V(1.0), V(acoustic_band) * b / (a + V(1e-300)));
    const V phi = simd::max(phi0, V(phi_min) * r);
    const auto central = (h.FL + h.FR) * V(0.5) +
                         ((h.UsL - h.UL) * (phi * h.SL) + (h.UsL - h.UsR) * simd::abs(h.Sstar) +
                          (h.UsR - h.UR) * (phi * h.SR)) *
                             V(0.5);
    return select<V>(h.SL >= V(0.0), h.FL, select<V>(h.SR <= V(0.0), h.FR, central));
  }
};

}  // namespace parafsi::flux
