/// \file stable_dt.hpp
/// Largest stable step: Δt = CFL / max_cells λ with
///   λ = Σ_d (|û_d − ŵ_d| + c)/h_d                                     (convective)
///   λ ← max(λ, lv CFL/0.5),  lv = 2 ν_eff Σ_d 1/h_d²,                   (viscous: Δt_v = 0.5/lv)
///   ν_eff = max(μ_eff/ρ, γ (μ/Pr + μ_t/Pr_t)/ρ),
/// ŵ the grid velocity at the cell centre (box components). The maximum is reduced per
/// row in a fixed order (thread-count independent) into caller-owned slots.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "../frame/pose.hpp"
#include "../gas.hpp"
#include "../grid.hpp"
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
  auto row_max = [&](index_t r) {
    const index_t j = r % ny, k = r / ny;
    double lam = 0.0;
    for (index_t i = 0; i < nx; ++i) {
      const auto w = to_prim(load_cons(U, grid.index(i, j, k)), gas);
      const double c = gas.sound_speed(w.rho, w.p);
      const Eigen::Vector3d ub = Rt * Eigen::Vector3d(w.u.x, w.u.y, w.u.z);
      const Eigen::Vector3d xi{x0[i], x1[j], x2[k]};
      const Eigen::Vector3d wb = vh + oh.cross(xi);
      double l = (std::fabs(ub[0] - wb[0]) + c) / h0[i] + (std::fabs(ub[1] - wb[1]) + c) / h1[j] +
                 (std::fabs(ub[2] - wb[2]) + c) / h2[k];
      if constexpr (Viscous) {
        double mu_l = visc.mu(gas.temperature(w.rho, w.p));
        double mut = 0.0;
        if constexpr (Turbulence::active) mut = mu_t[grid.index(i, j, k)];
        const double nu = std::max((mu_l + mut) / w.rho,
                                   gas.gamma * (mu_l / visc.prandtl + mut / turb.prandtl_t) / w.rho);
        const double lv = 2.0 * nu * (1.0 / (h0[i] * h0[i]) + 1.0 / (h1[j] * h1[j]) + 1.0 / (h2[k] * h2[k]));
        // Δt_v = 0.5/lv must hold; expressed against cfl: cfl/l_eff ≤ 0.5/lv.
        l = std::max(l, lv * cfl / 0.5);
      }
      lam = std::max(lam, l);
    }
    return lam;
  };
  (void)visc;
  (void)turb;
  (void)mu_t;
  return parallel::reduce(
      index_t(0), ny * nz, 0.0, row_max, [](double a, double b) { return std::max(a, b); }, threaded, slots);
}

}  // namespace parafsi::fluid::detail
