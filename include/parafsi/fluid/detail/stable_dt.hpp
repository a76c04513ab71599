/// \file stable_dt.hpp
/// Largest stable step: Δt = CFL / max_cells λ with
///   λ = Σ_d (|û_d − ŵ_d| + c)/h_d                                     (convective)
///   λ ← max(λ, lv CFL/0.5),  lv = 2 ν_eff Σ_d 1/h_d²,                   (viscous: Δt_v = 0.5/lv)
///   ν_eff = max(μ_eff/ρ, γ (μ/Pr + μ_t/Pr_t)/ρ),
/// ŵ the grid velocity at the cell centre (box components). The maximum is reduced per
/// row in a fixed order (thread-count independent) into caller-owned slots. A cell whose
/// rate is not finite (a state that is not a gas: NaN, infinite) makes its row's rate +∞,
/// so the caller's check stops the run there instead of a maximum that skips the NaN.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "../../core/simd.hpp"
#include "../frame/pose.hpp"
#include "../gas.hpp"
#include "../grid.hpp"
#include "../state.hpp"
#include "stage.hpp"

namespace parafsi::fluid::detail {

/// `mu_t`: eddy viscosity per cell (when Turbulence::active), else unused.
template <bool Viscous, class Viscosity, class Turbulence>
double max_wave_rate(const rectilinear_grid& grid, const gas::ideal& gas, const frame::pose& pose,
                     const fields5<const double>& U, const Viscosity& visc, const Turbulence& turb, const double* mu_t,
                     double cfl, std::vector<double>& slots, bool threaded) {
  const Eigen::Matrix3d Rt = pose.R.transpose();
  const Eigen::Vector3d vh = Rt * pose.V, oh = Rt * pose.Omega;
  const index_t nx = grid.n(0), ny = grid.n(1), nz = grid.n(2);
  const double* h0 = grid.widths(0);
  const double* h1 = grid.widths(1);
  const double* h2 = grid.widths(2);
  const double* x0 = grid.centres(0);
  const double* x1 = grid.centres(1);
  const double* x2 = grid.centres(2);
  // Packed along x (simd::for_each_pack: whole packs, then single cells; each cell's
  // arithmetic depends on its place in the row only, not on the thread count).
  auto row_max = [&](index_t r) {
    const index_t j = r % ny, k = r / ny;
    const double x1j = x1[j], x2k = x2[k], i1 = 1.0 / h1[j], i2 = 1.0 / h2[k];
    double lam = 0.0;
    simd::for_each_pack(0, nx, [&](auto tag, index_t i) {
      using V = typename decltype(tag)::type;
      const index_t c = grid.index(i, j, k);
      const cons<V> q{simd::load<V>(U[0] + c),
                      {simd::load<V>(U[1] + c), simd::load<V>(U[2] + c), simd::load<V>(U[3] + c)},
                      simd::load<V>(U[4] + c)};
      const prim<V> w = to_prim(q, gas);
      const V c_s = gas.sound_speed(w.rho, w.p);
      const V x0i = simd::load<V>(x0 + i);
      // Box-frame velocity of the air (Rᵀu) and of the grid (V̂ + Ω̂ × ξ) at the centre.
      V rel[3];
      for (int d = 0; d < 3; ++d) {
        const V ub = V(Rt(d, 0)) * w.u.x + V(Rt(d, 1)) * w.u.y + V(Rt(d, 2)) * w.u.z;
        const int e = (d + 1) % 3, f = (d + 2) % 3;  // (Ω̂ × ξ)_d = Ω̂_e ξ_f − Ω̂_f ξ_e
        const V xe = e == 0 ? x0i : V(e == 1 ? x1j : x2k), xf = f == 0 ? x0i : V(f == 1 ? x1j : x2k);
        const V wb = V(vh[d]) + (V(oh[e]) * xf - V(oh[f]) * xe);
        rel[d] = simd::abs(ub - wb) + c_s;
      }
      const V i0 = V(1.0) / simd::load<V>(h0 + i);
      V l = rel[0] * i0 + rel[1] * V(i1) + rel[2] * V(i2);
      // Checked before the viscous limit: simd::max(NaN, x) would return x.
      if (!simd::all_finite(l)) lam = HUGE_VAL;
      if constexpr (Viscous) {
        const V mu_l = visc.mu(gas.temperature(w.rho, w.p));
        V mut(0.0);
        if constexpr (Turbulence::active) mut = simd::load<V>(mu_t + c);
        const V inv_rho = V(1.0) / w.rho;
        const V nu = simd::max((mu_l + mut) * inv_rho,
                               V(gas.gamma) * (mu_l * V(1.0 / visc.prandtl) + mut * V(1.0 / turb.prandtl_t)) * inv_rho);
        const V lv = V(2.0) * nu * (i0 * i0 + V(i1 * i1 + i2 * i2));
        // Δt_v = 0.5/lv must hold; expressed against cfl: cfl/l_eff ≤ 0.5/lv.
        l = simd::max(l, lv * V(cfl / 0.5));
      }
      lam = std::max(lam, simd::hmax(l));
    });
    return lam;
  };
  (void)visc;
  (void)turb;
  (void)mu_t;
  return parallel::reduce(
      index_t(0), ny * nz, 0.0, row_max, [](double a, double b) { return std::max(a, b); }, threaded, slots);
}

}  // namespace parafsi::fluid::detail
