/// \file primitives.hpp
/// Primitive variables from the conserved ones, packed along the flat index:
///   ρ,  u = m·(1/ρ),  p = (γ − 1)(E − ½ ρ |u|²),
/// on every cell (ghosts and padding included: the box solver), or only where the flux
/// sweeps read them (a block of a block mesh, whose ghosts are two-fifths or more of its cells).
#pragma once
#include <algorithm>

#include "../../core/simd.hpp"
#include "../gas.hpp"
#include "../grid.hpp"
#include "stage.hpp"

namespace parafsi::fluid::detail {

/// W at the cells c … c + lanes(V) − 1.
template <class V>
PARAFSI_INLINE void primitives_at(index_t c, const gas::ideal& g, const fields5<const double>& U,
                                  const fields5<double>& W) noexcept {
  const V rho = simd::load<V>(U[0] + c);
  const V inv = V(1.0) / rho;
  const V u = simd::load<V>(U[1] + c) * inv, v = simd::load<V>(U[2] + c) * inv, w = simd::load<V>(U[3] + c) * inv;
  simd::store(W[0] + c, rho);
  simd::store(W[1] + c, u);
  simd::store(W[2] + c, v);
  simd::store(W[3] + c, w);
  simd::store(W[4] + c, V(g.gamma - 1.0) * (simd::load<V>(U[4] + c) - V(0.5) * rho * (u * u + v * v + w * w)));
}

/// W on the flat cells [0, N).
inline void compute_primitives(index_t N, const gas::ideal& gas, const fields5<const double>& U,
                               const fields5<double>& W, bool threaded) {
  const index_t chunk = 4096;
  const index_t nchunks = (N + chunk - 1) / chunk;
  const gas::ideal g = gas;
  par_for(threaded, 0, nchunks, [&](index_t ch) {
    const index_t b = ch * chunk, e = std::min(N, b + chunk);
    simd::for_each_pack(b, e, [&](auto tag, index_t c) {
      using V = typename decltype(tag)::type;
      primitives_at<V>(c, g, U, W);
    });
  });
}

/// W where the three flux sweeps (sweep.hpp) read it: the interior cells and, along each
/// axis, its two ghost layers on either side over the interior of the other two axes;
/// not the edge and corner ghosts. Every span is done in whole packs, rounded up past its
/// end (onto other cells of the grid: the last span ends two ghost rows before the grid
/// does), so each cell gets the arithmetic of compute_primitives.
inline void compute_primitives_sweeps(const rectilinear_grid& grid, const gas::ideal& gas,
                                      const fields5<const double>& U, const fields5<double>& W) {
  constexpr index_t ng = rectilinear_grid::ghosts;
  constexpr index_t lanes = index_t(simd::width);
  const index_t nx = grid.n(0), ny = grid.n(1), nz = grid.n(2);
  const gas::ideal g = gas;
  auto span = [&](index_t b, index_t len) {
    for (index_t c = b; c < b + len; c += lanes) primitives_at<simd::pack<double>>(c, g, U, W);
  };
  for (index_t k = -ng; k < nz + ng; ++k) {
    const bool k_in = k >= 0 && k < nz;
    // Rows j of plane k: interior rows with their x ghosts are one contiguous span.
    if (k_in) span(grid.index(-ng, 0, k), grid.index(-ng, ny, k) - grid.index(-ng, 0, k));
    for (index_t j = -ng; j < ny + ng; ++j) {
      const bool j_in = j >= 0 && j < ny;
      if (j_in != k_in) span(grid.index(0, j, k), nx);  // y ghost rows (k inside), z ghost rows (j inside)
    }
  }
}

}  // namespace parafsi::fluid::detail
