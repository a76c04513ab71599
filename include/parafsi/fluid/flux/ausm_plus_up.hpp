/// \file ausm_plus_up.hpp
/// AUSM+-up (Liou 2006), all-speed advection upstream splitting:
///   a½ = ½(â_L + â_R),  â_K from the critical speed a*² = 2(γ−1)H/(γ+1) (Liou's
///        min(â_L, â_R) collapses to the cold side's speed at pressure ratios ≳ 10⁴, e.g.
///        Toro's test 3, and drives a huge pressure-diffusion mass flux; the mean is robust);
///   M½ = M⁺₍₄₎(M_L) + M⁻₍₄₎(M_R) − (K_p/f_a) max(1 − σ M̄², 0)(p_R − p_L)/(ρ½ a½²),
///   p½ = P⁺₍₅₎ p_L + P⁻₍₅₎ p_R − K_u P⁺₍₅₎ P⁻₍₅₎ (ρ_L + ρ_R) f_a a½ (u_nR − u_nL),
///   F  = a½ M½ ρ_up (1, u, H)_up + p½ (0, n, 0),
/// with β = 1/8, α = 3/16 (−4 + 5 f_a²), K_p = 0.25, K_u = 0.75, σ = 1,
/// f_a = M_o (2 − M_o), M_o² = min(1, max(M̄², M_co²)); M_co = 1 (f_a = 1) by default,
/// the safe choice for explicit time stepping.
/// References: Liou M.-S. (2006) J. Comput. Phys. 214:137, doi:10.1016/j.jcp.2005.09.020.
#pragma once
#include "../../core/policy.hpp"
#include "../state.hpp"

namespace parafsi::flux {

struct ausm_plus_up {
  double Kp = 0.25, Ku = 0.75, sigma = 1.0;
  double mach_cutoff = 1.0;  ///< M_co: 1 disables the low-Mach scaling (f_a = 1)

  using policy_kind = kind::flux;
  static constexpr const char* name() noexcept { return "ausm_plus_up"; }

  template <class V>
  PARAFSI_INLINE fluid::cons<V> operator()(const fluid::prim<V>& L, const fluid::prim<V>& R, const vec3<double>& n,
                                           const gas::ideal& g) const noexcept {
    using namespace fluid;
    using simd::select;
    const V unL = dot(L.u, n), unR = dot(R.u, n);
    const V EL = g.total_energy(L.rho, L.u.x, L.u.y, L.u.z, L.p);
    const V ER = g.total_energy(R.rho, R.u.x, R.u.y, R.u.z, R.p);
    const V HL = (EL + L.p) / L.rho, HR = (ER + R.p) / R.rho;
    const double gk = 2.0 * (g.gamma - 1.0) / (g.gamma + 1.0);
    const V asL = simd::sqrt(V(gk) * HL), asR = simd::sqrt(V(gk) * HR);
    const V ahL = asL * asL / simd::max(asL, unL);
    const V ahR = asR * asR / simd::max(asR, -unR);
    const V a = V(0.5) * (ahL + ahR);
    const V ML = unL / a, MR = unR / a;
    const V Mbar2 = (unL * unL + unR * unR) / (V(2.0) * a * a);
    const V Mo2 = simd::min(V(1.0), simd::max(Mbar2, V(mach_cutoff * mach_cutoff)));
    const V Mo = simd::sqrt(Mo2);
    const V fa = Mo * (V(2.0) - Mo);
    const V alpha = V(3.0 / 16.0) * (V(-4.0) + V(5.0) * fa * fa);
    const V beta = V(1.0 / 8.0);
    // Split Mach polynomials of degree 4 and pressure polynomials of degree 5.
    auto M1p = [](const V& M) { return V(0.5) * (M + simd::abs(M)); };
    auto M1m = [](const V& M) { return V(0.5) * (M - simd::abs(M)); };
    auto M2p = [](const V& M) { return V(0.25) * (M + V(1.0)) * (M + V(1.0)); };
    auto M2m = [](const V& M) { return V(-0.25) * (M - V(1.0)) * (M - V(1.0)); };
    const auto subL = simd::abs(ML) < V(1.0);
    const auto subR = simd::abs(MR) < V(1.0);
    const V M4p = select(subL, M2p(ML) * (V(1.0) - V(16.0) * beta * M2m(ML)), M1p(ML));
    const V M4m = select(subR, M2m(MR) * (V(1.0) + V(16.0) * beta * M2p(MR)), M1m(MR));
    const V P5p = select(subL, M2p(ML) * ((V(2.0) - ML) - V(16.0) * alpha * ML * M2m(ML)), M1p(ML) / ML);
    const V P5m = select(subR, M2m(MR) * ((V(-2.0) - MR) + V(16.0) * alpha * MR * M2p(MR)), M1m(MR) / MR);
    const V rho_half = V(0.5) * (L.rho + R.rho);
    const V Mhalf = M4p + M4m -
                    V(Kp) / fa * simd::max(V(1.0) - V(sigma) * Mbar2, V(0.0)) * (R.p - L.p) / (rho_half * a * a);
    const V phalf = P5p * L.p + P5m * R.p - V(Ku) * P5p * P5m * (L.rho + R.rho) * fa * a * (unR - unL);
    const auto up = Mhalf > V(0.0);
    const V mdot = a * Mhalf * select(up, L.rho, R.rho);
    const vec3<V> u_up{select(up, L.u.x, R.u.x), select(up, L.u.y, R.u.y), select(up, L.u.z, R.u.z)};
    const V H_up = select(up, HL, HR);
    return {mdot,
            {mdot * u_up.x + phalf * V(n.x), mdot * u_up.y + phalf * V(n.y), mdot * u_up.z + phalf * V(n.z)},
            mdot * H_up};
  }
};

}  // namespace parafsi::flux
