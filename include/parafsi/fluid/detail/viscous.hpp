/// \file viscous.hpp
/// Viscous and heat fluxes (laminar + eddy viscosity), in box components:
///   τ̂ = μ_eff (∇û + ∇ûᵀ − ⅔ (∇·û) I),   q̂ = −k_eff ∇T,
///   μ_eff = μ(T) + μ_t,   k_eff = c_p (μ/Pr + μ_t/Pr_t),
/// face-normal derivatives from two-point differences, tangential ones from the
/// average of the two cells' central differences; momentum fluxes rotated back to
/// inertial components. Each face is computed once per stage (per axis, into a face
/// buffer indexed by its high cell), then every cell takes the differences of its two
/// faces per axis, summed over the axes in the order x, y, z:
///   dU_c += Σ_d (F̂_v,d(c + s_d) − F̂_v,d(c)) / Δx_d.
#pragma once
#include <cmath>

#include <Eigen/Core>

#include "../fields.hpp"
#include "../gas.hpp"
#include "../grid.hpp"
#include "stage.hpp"

namespace parafsi::fluid::detail {

/// What the viscous pass does with an axis's face fluxes besides differencing them: nothing
/// (the box solver); a block of a block mesh keeps its boundary faces' for the coarse–fine
/// correction (hook(d, Fv): Fv[q][c] the flux of the face below cell c, q = momentum x, y, z, energy).
struct no_face_hook {
  void operator()(int, double* const*) const noexcept {}
};

/// Everything the viscous pass reads and writes.
template <class Viscosity, class Turbulence, class ViscStorage, class TurbStorage>
struct viscous_pass {
  static constexpr bool has_eddy_viscosity = Turbulence::active;
  static constexpr bool needs_wall_distance = [] {
    if constexpr (Turbulence::active) return Turbulence::needs_wall_distance;
    else return false;
  }();

  const Viscosity& visc;
  const Turbulence& turb;
  const gas::ideal& gas;
  const rectilinear_grid& grid;
  ViscStorage& vs;
  TurbStorage& ts;
  bool threaded;

  template <class FaceHook = no_face_hook>
  void operator()(const stage_geometry& geo, const fields5<const double>& W, const fields5<double>& dU,
                  const FaceHook& hook = {}) {
    const index_t nx = grid.n(0), ny = grid.n(1), nz = grid.n(2);
    double* ub[3] = {vs.template get<field::ub0>(), vs.template get<field::ub1>(), vs.template get<field::ub2>()};
    double* Tc = vs.template get<field::T>();
    double* mu = vs.template get<field::mu_eff>();
    double* kk = vs.template get<field::k_eff>();
    double* G[3][3] = {{vs.template get<field::g00>(), vs.template get<field::g01>(), vs.template get<field::g02>()},
                       {vs.template get<field::g10>(), vs.template get<field::g11>(), vs.template get<field::g12>()},
                       {vs.template get<field::g20>(), vs.template get<field::g21>(), vs.template get<field::g22>()}};
    double* GT[3] = {vs.template get<field::gT0>(), vs.template get<field::gT1>(), vs.template get<field::gT2>()};
    double* Fv[4] = {vs.template get<field::fv0>(), vs.template get<field::fv1>(), vs.template get<field::fv2>(),
                     vs.template get<field::fv3>()};
    double* acc[4] = {vs.template get<field::av0>(), vs.template get<field::av1>(), vs.template get<field::av2>(),
                      vs.template get<field::av3>()};
    const double* Wr = W[0];
    const double* Wu[3] = {W[1], W[2], W[3]};
    const double* Wp = W[4];
    const Eigen::Matrix3d Rt = geo.R.transpose();
    const double cp = gas.cp();
    // 1. Box-frame velocity and temperature on every cell (ghosts included).
    const index_t N = grid.total_cells();
    par_for(threaded, 0, N, [&](index_t c) {
      const Eigen::Vector3d u = Rt * Eigen::Vector3d(Wu[0][c], Wu[1][c], Wu[2][c]);
      ub[0][c] = u[0];
      ub[1][c] = u[1];
      ub[2][c] = u[2];
      Tc[c] = gas.temperature(Wr[c], Wp[c]);
    });
    // 2. Cell gradients (central differences) and transport coefficients on cells
    //    [−1, n] in every direction.
    const double* xcs[3] = {grid.centres(0), grid.centres(1), grid.centres(2)};
    par_for(threaded, -1, nz + 1, [&](index_t k) {
      for (index_t j = -1; j < ny + 1; ++j)
        for (index_t i = -1; i < nx + 1; ++i) {
          const index_t c = grid.index(i, j, k);
          const index_t ijk[3] = {i, j, k};
          for (int d = 0; d < 3; ++d) {
            const index_t s = grid.stride(d);
            const double inv = 1.0 / (xcs[d][ijk[d] + 1] - xcs[d][ijk[d] - 1]);
            for (int a = 0; a < 3; ++a) G[a][d][c] = (ub[a][c + s] - ub[a][c - s]) * inv;
            GT[d][c] = (Tc[c + s] - Tc[c - s]) * inv;
          }
          double mu_l = visc.mu(Tc[c]);
          double mut = 0.0;
          if constexpr (has_eddy_viscosity) {
            double S2 = 0.0;
            for (int a = 0; a < 3; ++a)
              for (int b = 0; b < 3; ++b) {
                const double sab = 0.5 * (G[a][b][c] + G[b][a][c]);
                S2 += sab * sab;
              }
            const double delta = std::cbrt(grid.width(0, i) * grid.width(1, j) * grid.width(2, k));
            double dw = 1e30;
            if constexpr (needs_wall_distance) dw = ts.template get<field::wall_distance>()[c];
            mut = turb.eddy_viscosity(Wr[c], std::sqrt(2.0 * S2), delta, dw);
            ts.template get<field::mu_t>()[c] = mut;
          }
          mu[c] = mu_l + mut;
          kk[c] = cp * (mu_l / visc.prandtl + mut / turb.prandtl_t);
        }
    });
    // 3. Face fluxes of one axis into Fv (at the face's high cell), then every cell's
    //    difference across the axis into acc (race-free, thread-count independent).
    auto face = [&](int d, index_t cm, index_t cc, double idc, index_t out) {
      // Gradient at the face: normal from the two cells, tangential averaged.
      double g[3][3], gT[3];
      for (int e = 0; e < 3; ++e) {
        if (e == d) {
          for (int a = 0; a < 3; ++a) g[a][e] = (ub[a][cc] - ub[a][cm]) * idc;
          gT[e] = (Tc[cc] - Tc[cm]) * idc;
        } else {
          for (int a = 0; a < 3; ++a) g[a][e] = 0.5 * (G[a][e][cm] + G[a][e][cc]);
          gT[e] = 0.5 * (GT[e][cm] + GT[e][cc]);
        }
      }
      const double muf = 0.5 * (mu[cm] + mu[cc]), kf = 0.5 * (kk[cm] + kk[cc]);
      const double div = g[0][0] + g[1][1] + g[2][2];
      double tau[3];
      for (int a = 0; a < 3; ++a) tau[a] = muf * (g[a][d] + g[d][a] - (a == d ? 2.0 / 3.0 * div : 0.0));
      double work = 0.0;
      for (int a = 0; a < 3; ++a) work += tau[a] * 0.5 * (ub[a][cm] + ub[a][cc]);
      const Eigen::Vector3d ti = geo.R * Eigen::Vector3d(tau[0], tau[1], tau[2]);
      Fv[0][out] = ti[0];
      Fv[1][out] = ti[1];
      Fv[2][out] = ti[2];
      Fv[3][out] = work + kf * gT[d];
    };
    auto axis_pass = [&]<int d>() {
      const index_t s = grid.stride(d);
      const double* idc = grid.inv_centre_gaps(d);
      const double* inv_h = grid.inv_widths(d);
      const index_t top[3] = {nx + (d == 0), ny + (d == 1), nz + (d == 2)};  // faces: high cells 0 … n_d
      par_for(threaded, 0, top[2], [&](index_t k) {
        for (index_t j = 0; j < top[1]; ++j)
          for (index_t i = 0; i < top[0]; ++i) {
            const index_t c = grid.index(i, j, k);
            const index_t ijk[3] = {i, j, k};
            face(d, c - s, c, idc[ijk[d]], c);
          }
      });
      hook(d, Fv);
      par_for(threaded, 0, nz, [&](index_t k) {
        for (index_t j = 0; j < ny; ++j)
          for (index_t i = 0; i < nx; ++i) {
            const index_t c = grid.index(i, j, k);
            const index_t ijk[3] = {i, j, k};
            const double ih = inv_h[ijk[d]];
            for (int q = 0; q < 4; ++q) {
              if constexpr (d == 0) acc[q][c] = 0.0;
              acc[q][c] += (Fv[q][c + s] - Fv[q][c]) * ih;
            }
          }
      });
    };
    axis_pass.template operator()<0>();
    axis_pass.template operator()<1>();
    axis_pass.template operator()<2>();
    par_for(threaded, 0, nz, [&](index_t k) {
      for (index_t j = 0; j < ny; ++j)
        for (index_t i = 0; i < nx; ++i) {
          const index_t c = grid.index(i, j, k);
          dU[1][c] += acc[0][c];
          dU[2][c] += acc[1][c];
          dU[3][c] += acc[2][c];
          dU[4][c] += acc[3][c];
        }
    });
  }
};

}  // namespace parafsi::fluid::detail
