/// \file rusanov.hpp
/// Rusanov (local Lax–Friedrichs) flux on a fixed face with unit normal n:
///   F = ½ (F_L + F_R) − ½ S_max (U_R − U_L),  S_max = max(|u_nL| + c_L, |u_nR| + c_R).
/// Robust and very dissipative at low Mach; a reference and fallback.
/// References: Rusanov V.V. (1961) J. Comput. Math. Phys. USSR 1:267;
///             Toro E.F. (2009) Riemann Solvers and Numerical Methods, 3rd ed., §10.5.
#pragma once
#include "../../core/policy.hpp"
#include "../state.hpp"

namespace parafsi::flux {

struct rusanov {
  using policy_kind = kind::flux;
  static constexpr const char* name() noexcept { return "rusanov"; }

  template <class V>
  PARAFSI_INLINE fluid::cons<V> operator()(const fluid::prim<V>& L, const fluid::prim<V>& R, const vec3<double>& n,
                                           const gas::ideal& g) const noexcept {
    using namespace fluid;
    const V unL = dot(L.u, n), unR = dot(R.u, n);
    const V cL = g.sound_speed(L.rho, L.p), cR = g.sound_speed(R.rho, R.p);
    const V EL = g.total_energy(L.rho, L.u.x, L.u.y, L.u.z, L.p);
    const V ER = g.total_energy(R.rho, R.u.x, R.u.y, R.u.z, R.p);
    const V smax = simd::max(simd::abs(unL) + cL, simd::abs(unR) + cR);
    const cons<V> UL{L.rho, L.u * L.rho, EL}, UR{R.rho, R.u * R.rho, ER};
    const cons<V> FL = physical_flux(L, EL, unL, n), FR = physical_flux(R, ER, unR, n);
    return (FL + FR) * V(0.5) - (UR - UL) * (V(0.5) * smax);
  }
};

}  // namespace parafsi::flux
