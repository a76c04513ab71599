/// \file hllc_common.hpp
/// Shared pieces of the HLLC family: Einfeldt wave-speed estimates, the contact
/// speed S* and the star states (Toro 2009, §10.4; Batten et al. 1997).
///   S* = [p_R − p_L + ρ_L u_nL (S_L − u_nL) − ρ_R u_nR (S_R − u_nR)]
///        / [ρ_L (S_L − u_nL) − ρ_R (S_R − u_nR)]
///   U*_K = ρ_K (S_K − u_nK)/(S_K − S*) · [1, u_K + (S* − u_nK) n,
///          E_K/ρ_K + (S* − u_nK)(S* + p_K / (ρ_K (S_K − u_nK)))]
/// References: Toro E.F., Spruce M., Speares W. (1994) Shock Waves 4:25;
///   Batten P., Clarke N., Lambert C., Causon D.M. (1997) SIAM J. Sci. Comput. 18:1553;
///   Einfeldt B. (1988) SIAM J. Numer. Anal. 25:294.
#pragma once
#include "../state.hpp"

namespace parafsi::flux::detail {

template <class V>
struct hllc_waves {
  V unL, unR, cL, cR, EL, ER, SL, SR, Sstar;
  fluid::cons<V> UL, UR, FL, FR, UsL, UsR;
};

/// Wave speeds, star states and the two side fluxes, with one reciprocal per density
/// and per star denominator (divisions dominate the cost of this kernel).
template <class V>
PARAFSI_INLINE hllc_waves<V> hllc_prepare(const fluid::prim<V>& L, const fluid::prim<V>& R, const vec3<double>& n,
                                          const gas::ideal& g) noexcept {
  using namespace fluid;
  hllc_waves<V> h;
  h.unL = dot(L.u, n);
  h.unR = dot(R.u, n);
  const V irL = V(1.0) / L.rho, irR = V(1.0) / R.rho;
  h.cL = simd::sqrt(V(g.gamma) * L.p * irL);
  h.cR = simd::sqrt(V(g.gamma) * R.p * irR);
  h.EL = g.total_energy(L.rho, L.u.x, L.u.y, L.u.z, L.p);
  h.ER = g.total_energy(R.rho, R.u.x, R.u.y, R.u.z, R.p);
  // Einfeldt (Roe-averaged) speeds bounded by the Davis estimates.
  const V sL = simd::sqrt(L.rho), sR = simd::sqrt(R.rho);
  const V inv = V(1.0) / (sL + sR);
  const V wL = sL * inv, wR = sR * inv;
  const V un_roe = wL * h.unL + wR * h.unR;
  const V HL = (h.EL + L.p) * irL, HR = (h.ER + R.p) * irR;
  const V H_roe = wL * HL + wR * HR;
  const vec3<V> u_roe = L.u * wL + R.u * wR;
  const V q2 = dot(u_roe, u_roe);
  const V c_roe = simd::sqrt(simd::max(V(g.gamma - 1.0) * (H_roe - V(0.5) * q2), V(1e-300)));
  h.SL = simd::min(h.unL - h.cL, un_roe - c_roe);
  h.SR = simd::max(h.unR + h.cR, un_roe + c_roe);
  const V dL = L.rho * (h.SL - h.unL), dR = R.rho * (h.SR - h.unR);
  h.Sstar = (R.p - L.p + dL * h.unL - dR * h.unR) / (dL - dR);
  h.UL = {L.rho, L.u * L.rho, h.EL};
  h.UR = {R.rho, R.u * R.rho, h.ER};
  h.FL = physical_flux(L, h.EL, h.unL, n);
  h.FR = physical_flux(R, h.ER, h.unR, n);
  auto star = [&](const prim<V>& W, const V& E, const V& ir, const V& un, const V& S, const V& d) {
    // f (S* − u_n) p/d = (S* − u_n) p/(S − S*): one reciprocal r = 1/(S − S*) serves both.
    const V r = V(1.0) / (S - h.Sstar);
    const V f = d * r;
    const V ds = h.Sstar - un;
    return cons<V>{f, axpy_n(W.u, ds, n) * f, f * (E * ir + ds * h.Sstar) + ds * W.p * r};
  };
  h.UsL = star(L, h.EL, irL, h.unL, h.SL, dL);
  h.UsR = star(R, h.ER, irR, h.unR, h.SR, dR);
  return h;
}

}  // namespace parafsi::flux::detail
