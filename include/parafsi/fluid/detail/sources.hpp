/// \file sources.hpp
/// Volume sources and the far-field sponge:
///   dU += S − σ (U − U_∞),
/// S the per-cell sources (the coupling's impulses, per unit volume and time; mass,
/// momentum, energy), σ the sponge rate, ramping as σ = s c_∞/L_s ((L − dist)/L)³ into
/// the last L cells before every far-field face (L_s the layer's thickness, c_∞ and U_∞
/// the first far-field face's sound speed and state). Which terms are present is chosen
/// once per call (template flags), not per cell.
#pragma once
#include <algorithm>
#include <variant>

#include "../../core/simd.hpp"
#include "../boundary/condition.hpp"
#include "../gas.hpp"
#include "../grid.hpp"
#include "stage.hpp"

namespace parafsi::fluid::detail {

/// Sound speed of the first far-field face (the sponge's rate scale); 340 m/s if none.
inline double sponge_sound_speed(const boundary::set& bcs, const gas::ideal& gas) {
  for (const auto& f : bcs.face)
    if (auto* ff = std::get_if<boundary::far_field>(&f)) return gas.sound_speed(ff->rho, ff->p);
  return 340.0;
}
/// The sponge's target state: the first far-field face's state (else `fallback`).
inline cons<double> sponge_target(const boundary::set& bcs, const gas::ideal& gas, const cons<double>& fallback) {
  for (const auto& f : bcs.face)
    if (auto* ff = std::get_if<boundary::far_field>(&f)) return to_cons(ff->state(), gas);
  return fallback;
}
/// σ at a cell `dist` cells in from a far-field face, for a layer of L cells of total
/// thickness `thick`: s c_∞/thick ((L − dist)/L)³ (0 outside the layer).
inline double sponge_rate(const boundary::sponge& layer, double c_inf, double thick, double dist) {
  if (!(dist < double(layer.cells))) return 0.0;
  const double xi = (double(layer.cells) - dist) / double(layer.cells);
  return layer.strength * c_inf / thick * xi * xi * xi;
}

/// Fill the sponge rate σ on interior cells; returns the sponge's target state.
inline cons<double> setup_sponge(const rectilinear_grid& grid, const boundary::set& bcs, const gas::ideal& gas,
                                 double* sig, const cons<double>& fallback) {
  const index_t L = bcs.layer.cells;
  const double cinf = sponge_sound_speed(bcs, gas);
  for (index_t k = 0; k < grid.n(2); ++k)
    for (index_t j = 0; j < grid.n(1); ++j)
      for (index_t i = 0; i < grid.n(0); ++i) {
        const index_t ijk[3] = {i, j, k};
        double s = 0.0;
        for (int d = 0; d < 3; ++d)
          for (int hi = 0; hi < 2; ++hi) {
            if (!std::holds_alternative<boundary::far_field>(bcs.face[std::size_t(2 * d + hi)])) continue;
            const index_t dist = hi ? grid.n(d) - 1 - ijk[d] : ijk[d];  // cells from the face
            if (dist >= L) continue;
            double thick = 0.0;
            for (index_t q = 0; q < L && q < grid.n(d); ++q) thick += grid.width(d, hi ? grid.n(d) - 1 - q : q);
            s = std::max(s, sponge_rate(bcs.layer, cinf, thick, double(dist)));
          }
        sig[grid.index(i, j, k)] = s;
      }
  return sponge_target(bcs, gas, fallback);
}

/// dU += S (Sources), then dU −= σ (U − U_∞) where σ > 0 (Sponge), on interior cells,
/// packed along x rows. `src` in the order (ρ, mx, my, mz, E).
template <bool Sources, bool Sponge>
void add_sources(const rectilinear_grid& grid, const fields5<double>& dU, const fields5<const double>& U,
                 const fields5<const double>& src, const double* sig, const cons<double>& target, bool threaded) {
  const index_t nx = grid.n(0), ny = grid.n(1), nz = grid.n(2);
  const double tgt[5] = {target.rho, target.m.x, target.m.y, target.m.z, target.E};
  par_for(threaded, 0, ny * nz, [&](index_t r) {
    const index_t base = grid.index(0, r % ny, r / ny);
    simd::for_each_pack(0, nx, [&](auto tag, index_t i) {
      using V = typename decltype(tag)::type;
      const index_t c = base + i;
      V q[5];
      for (int f = 0; f < 5; ++f) q[f] = simd::load<V>(dU[f] + c);
      if constexpr (Sources)
        for (int f = 0; f < 5; ++f) q[f] = q[f] + simd::load<V>(src[f] + c);
      if constexpr (Sponge) {
        const V s = simd::load<V>(sig + c);
        const auto on = s > V(0.0);
        if (simd::any(on))
          for (int f = 0; f < 5; ++f) q[f] = simd::select(on, q[f] - s * (simd::load<V>(U[f] + c) - V(tgt[f])), q[f]);
      }
      for (int f = 0; f < 5; ++f) simd::store(dU[f] + c, q[f]);
    });
  });
}

}  // namespace parafsi::fluid::detail
