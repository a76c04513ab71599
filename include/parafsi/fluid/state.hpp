/// \file state.hpp
/// Point states on a value type V: primitive W = (ρ, u, p) and conserved
/// U = (ρ, ρu, ρE), conversions, and the inviscid normal flux
///   F(U)·n = (ρ u_n, ρ u u_n + p n, (ρE + p) u_n),  u_n = u·n.
#pragma once
#include "../core/vec3.hpp"
#include "gas.hpp"

namespace parafsi::fluid {

template <class V>
struct prim {
  V rho;
  vec3<V> u;
  V p;
};

template <class V>
struct cons {
  V rho;
  vec3<V> m;
  V E;
  PARAFSI_INLINE cons operator+(const cons& o) const noexcept { return {rho + o.rho, m + o.m, E + o.E}; }
  PARAFSI_INLINE cons operator-(const cons& o) const noexcept { return {rho - o.rho, m - o.m, E - o.E}; }
  PARAFSI_INLINE cons operator*(const V& s) const noexcept { return {rho * s, m * s, E * s}; }
};

template <class V>
PARAFSI_INLINE cons<V> select(const simd::mask_t<V>& c, const cons<V>& a, const cons<V>& b) noexcept {
  using simd::select;
  return {select(c, a.rho, b.rho),
          {select(c, a.m.x, b.m.x), select(c, a.m.y, b.m.y), select(c, a.m.z, b.m.z)},
          select(c, a.E, b.E)};
}

template <class V>
PARAFSI_INLINE cons<V> to_cons(const prim<V>& w, const gas::ideal& g) noexcept {
  return {w.rho, w.u * w.rho, g.total_energy(w.rho, w.u.x, w.u.y, w.u.z, w.p)};
}

template <class V>
PARAFSI_INLINE prim<V> to_prim(const cons<V>& q, const gas::ideal& g) noexcept {
  const V inv = V(1.0) / q.rho;
  return {q.rho, q.m * inv, g.pressure(q.rho, q.m.x, q.m.y, q.m.z, q.E)};
}

/// Inviscid flux through a unit normal n of a fixed face, given u_n = u·n.
template <class V>
PARAFSI_INLINE cons<V> physical_flux(const prim<V>& w, const V& E, const V& un, const vec3<double>& n) noexcept {
  const V mflux = w.rho * un;
  return {mflux,
          {mflux * w.u.x + w.p * V(n.x), mflux * w.u.y + w.p * V(n.y), mflux * w.u.z + w.p * V(n.z)},
          (E + w.p) * un};
}

}  // namespace parafsi::fluid
