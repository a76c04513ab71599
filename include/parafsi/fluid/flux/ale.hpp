/// \file ale.hpp
/// Flux through a moving face by Galilean shift (any fixed-face Riemann solver):
///   1. u' = u − w_n n on both sides (ρ, p unchanged);
///   2. F' = flux(W'_L, W'_R, n);
///   3. Ĝ_ρ = F'_ρ,  Ĝ_m = F'_m + w_n n F'_ρ,  Ĝ_E = F'_E + w_n n·F'_m + ½ w_n² F'_ρ,
/// which is the ALE flux F·n − w_n U exactly for the physical flux.
/// Mach sensors inside the flux see the relative (shifted) normal velocity.
#pragma once
#include "../state.hpp"

namespace parafsi::flux {

template <class Flux, class V>
PARAFSI_INLINE fluid::cons<V> ale_flux(const Flux& flux, fluid::prim<V> L, fluid::prim<V> R, const vec3<double>& n,
                                       const V& wn, const gas::ideal& g) noexcept {
  L.u = axpy_n(L.u, -wn, n);
  R.u = axpy_n(R.u, -wn, n);
  fluid::cons<V> F = flux(L, R, n, g);
  F.E = F.E + wn * dot(F.m, n) + V(0.5) * wn * wn * F.rho;
  F.m = axpy_n(F.m, wn * F.rho, n);
  return F;
}

}  // namespace parafsi::flux
