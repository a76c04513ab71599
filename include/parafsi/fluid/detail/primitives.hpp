/// \file primitives.hpp
/// Primitive variables on every cell (ghosts and padding included), packed along the
/// flat index:  ρ,  u = m·(1/ρ),  p = (γ − 1)(E − ½ ρ |u|²).
#pragma once
#include <algorithm>

#include "../../core/simd.hpp"
#include "../gas.hpp"
#include "stage.hpp"

namespace parafsi::fluid::detail {

inline void compute_primitives(index_t N, const gas::ideal& gas, const fields5<const double>& U,
                               const fields5<double>& W, bool threaded) {
  const double* r = U[0];
  const double* mx = U[1];
  const double* my = U[2];
  const double* mz = U[3];
  const double* E = U[4];
  double* wr = W[0];
  double* wu = W[1];
  double* wv = W[2];
  double* ww = W[3];
  double* wp = W[4];
  const index_t chunk = 4096;
  const index_t nchunks = (N + chunk - 1) / chunk;
  const gas::ideal g = gas;
  par_for(threaded, 0, nchunks, [&](index_t ch) {
    const index_t b = ch * chunk, e = std::min(N, b + chunk);
    simd::for_each_pack(b, e, [&](auto tag, index_t c) {
      using V = typename decltype(tag)::type;
      const V rho = simd::load<V>(r + c);
      const V inv = V(1.0) / rho;
      const V u = simd::load<V>(mx + c) * inv, v = simd::load<V>(my + c) * inv, w = simd::load<V>(mz + c) * inv;
      simd::store(wr + c, rho);
      simd::store(wu + c, u);
      simd::store(wv + c, v);
      simd::store(ww + c, w);
      simd::store(wp + c, V(g.gamma - 1.0) * (simd::load<V>(E + c) - V(0.5) * rho * (u * u + v * v + w * w)));
    });
  });
}

}  // namespace parafsi::fluid::detail
