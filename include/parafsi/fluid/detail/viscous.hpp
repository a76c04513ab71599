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
/// Phases: box-frame velocity and temperature on every cell (with μ(T) and k_eff when there
/// is no eddy viscosity); with eddy viscosity the cell gradients (central differences), |S|,
/// μ_t and the transport coefficients on cells [−1, n]; per axis the face fluxes row by row,
/// each row's differences as soon as its faces are there (after z straight into dU); the
/// hook sees each axis's complete face buffer. No gradient is stored: a face recomputes the two
/// cells' central differences it needs (the same values). Every phase runs on SIMD lanes
/// along x (pointwise physics on V, scalar tail), each value with the operations of the
/// scalar pass (Lanes = 1, kept as the reference) in the same order: the rotations reproduce
/// Eigen's 3×3 product (rotate below), and the filter width Δ = (h_x h_y h_z)^{1/3} is
/// std::cbrt lane by lane, memoised by the width product. Without contraction of
/// a b + c (-ffp-contract=off) packs, scalars and the stored-gradient form agree bit for bit;
/// with it (the default where the hardware has FMA) the compiler fuses some sums differently
/// in each: round-off.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include <Eigen/Core>

#include "../../core/simd.hpp"
#include "../fields.hpp"
#include "../gas.hpp"
#include "../grid.hpp"
#include "stage.hpp"

namespace parafsi::fluid::detail {

/// What the viscous pass does with an axis's face fluxes besides differencing them: nothing
/// (the box solver); a block of a block mesh keeps its boundary faces' for the coarse–fine
/// correction (hook(d, Fv): Fv[q][c] the flux of the face below cell c, q = momentum x, y, z, energy).
/// It is called once every face of axis d is in Fv, and reads them (the differences may
/// have been taken already).
struct no_face_hook {
  void operator()(int, double* const*) const noexcept {}
};

/// y = M x on V with the arithmetic of Eigen 3.4's Matrix3d × Vector3d, so that the pass
/// gives the Eigen product's values. Where Eigen vectorizes, rows 0 and 1 are one packet:
/// M(·,0) x_0, then multiply-adds with columns 1 and 2 (fused when it vectorizes with FMA);
/// row 2 (every row without vectorization) is the sum M(r,0) x_0 + (M(r,2) x_2 + M(r,1) x_1).
/// Where the compiler contracts a b + c (the default -ffp-contract=fast with FMA hardware) it
/// may fuse that sum differently on packs than on scalars (a difference at round-off).
template <class V>
PARAFSI_INLINE void rotate(const Eigen::Matrix3d& M, const V (&x)[3], V (&y)[3]) noexcept {
  auto row_sum = [&](int r) { return V(M(r, 0)) * x[0] + (V(M(r, 2)) * x[2] + V(M(r, 1)) * x[1]); };
#if defined(EIGEN_VECTORIZE) && !defined(EIGEN_DONT_VECTORIZE)
  for (int r = 0; r < 2; ++r) {
    const V y0 = V(M(r, 0)) * x[0];
#if defined(EIGEN_VECTORIZE_FMA)
    y[r] = simd::fma(V(M(r, 2)), x[2], simd::fma(V(M(r, 1)), x[1], y0));
#else
    y[r] = V(M(r, 1)) * x[1] + y0;
    y[r] = V(M(r, 2)) * x[2] + y[r];
#endif
  }
#else
  y[0] = row_sum(0);
  y[1] = row_sum(1);
#endif
  y[2] = row_sum(2);
}

/// Everything the viscous pass reads and writes. Lanes: cells per SIMD pack along x
/// (simd::width), or 1 for the scalar pass.
template <class Viscosity, class Turbulence, class ViscStorage, class TurbStorage, std::size_t Lanes = simd::width>
struct viscous_pass {
  static_assert(Lanes == 1 || Lanes == simd::width, "viscous_pass: Lanes must be 1 or simd::width");
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

  /// f(tag, i) over [b, e): packs and a scalar tail, or scalars only.
  template <class F>
  static PARAFSI_INLINE void lanes(index_t b, index_t e, F&& f) {
    if constexpr (Lanes == 1) simd::for_each_scalar(b, e, f);
    else simd::for_each_pack(b, e, f);
  }

  template <class FaceHook = no_face_hook>
  void operator()(const stage_geometry& geo, const fields5<const double>& W, const fields5<double>& dU,
                  const FaceHook& hook = {}) {
    const index_t nx = grid.n(0), ny = grid.n(1), nz = grid.n(2);
    double* ub[3] = {vs.template get<field::ub0>(), vs.template get<field::ub1>(), vs.template get<field::ub2>()};
    double* Tc = vs.template get<field::T>();
    double* mu = vs.template get<field::mu_eff>();
    double* kk = vs.template get<field::k_eff>();
    double* Fv[4] = {vs.template get<field::fv0>(), vs.template get<field::fv1>(), vs.template get<field::fv2>(),
                     vs.template get<field::fv3>()};
    double* acc[4] = {vs.template get<field::av0>(), vs.template get<field::av1>(), vs.template get<field::av2>(),
                      vs.template get<field::av3>()};
    const double* Wr = W[0];
    const double* Wu[3] = {W[1], W[2], W[3]};
    const double* Wp = W[4];
    const Eigen::Matrix3d Rt = geo.R.transpose();
    const double cp = gas.cp();
    const gas::ideal g = gas;
    // 1. Box-frame velocity and temperature on every cell (ghosts included); without eddy
    //    viscosity also the transport coefficients.
    const index_t N = grid.total_cells();
    const index_t chunk = 4096;
    par_for(threaded, 0, (N + chunk - 1) / chunk, [&](index_t ch) {
      lanes(ch * chunk, std::min(N, ch * chunk + chunk), [&](auto tag, index_t c) {
        using V = typename decltype(tag)::type;
        const V w[3] = {simd::load<V>(Wu[0] + c), simd::load<V>(Wu[1] + c), simd::load<V>(Wu[2] + c)};
        V u[3];
        rotate(Rt, w, u);
        for (int a = 0; a < 3; ++a) simd::store(ub[a] + c, u[a]);
        const V T = g.temperature(simd::load<V>(Wr + c), simd::load<V>(Wp + c));
        simd::store(Tc + c, T);
        if constexpr (!has_eddy_viscosity) {
          const V mu_l = visc.mu(T), mut = V(0.0);
          simd::store(mu + c, mu_l + mut);
          simd::store(kk + c, V(cp) * (mu_l / V(visc.prandtl) + mut / V(turb.prandtl_t)));
        }
      });
    });
    // Central differences of the cell at c along axis e (inv: 1 / the distance between its
    // two neighbours' centres), of the box velocity (a = 0, 1, 2) and of T (a = 3).
    const index_t sd[3] = {grid.stride(0), grid.stride(1), grid.stride(2)};
    const double* const q4[4] = {ub[0], ub[1], ub[2], Tc};
    auto central = [&]<class V>(int a, int e, index_t c, const V& inv) {
      return (simd::load<V>(q4[a] + c + sd[e]) - simd::load<V>(q4[a] + c - sd[e])) * inv;
    };
    const double* xcs[3] = {grid.centres(0), grid.centres(1), grid.centres(2)};
    auto inv_gap = [&](int e, index_t i) { return 1.0 / (xcs[e][i + 1] - xcs[e][i - 1]); };
    auto inv_gap_x = [&]<class V>(index_t i) {
      return V(1.0) / (simd::load<V>(xcs[0] + i + 1) - simd::load<V>(xcs[0] + i - 1));
    };
    // 2. With eddy viscosity: the cell gradients (central differences), |S|, μ_t and the
    //    transport coefficients on cells [−1, n] in every direction.
    const double* hx = grid.widths(0);
    if constexpr (has_eddy_viscosity)
      par_for(threaded, -1, nz + 1, [&](index_t k) {
        // Δ from a memo of the last four width products met (an exact match gives the same
        // cube root): the widths of a block or a uniform core, x_I = lo + (hi − lo) I/N, take
        // a few values that differ in their last bits, which a last-value memo kept missing
        // (the cube root was 3 % of a block drop's step).
        constexpr int memo_size = 4;
        double memo_p[memo_size], memo_d[memo_size];
        std::fill(memo_p, memo_p + memo_size, std::numeric_limits<double>::quiet_NaN());
        std::fill(memo_d, memo_d + memo_size, 0.0);
        int memo_next = 0;
        for (index_t j = -1; j < ny + 1; ++j) {
          const index_t base = grid.index(0, j, k);
          const double inv_y = inv_gap(1, j), inv_z = inv_gap(2, k);
          const double hy = grid.width(1, j), hz = grid.width(2, k);
          auto delta_at = [&](index_t i) {
            const double p = hx[i] * hy * hz;
            for (int q = 0; q < memo_size; ++q)
              if (memo_p[q] == p) return memo_d[q];
            const double d = std::cbrt(p);
            memo_p[memo_next] = p;
            memo_d[memo_next] = d;
            memo_next = (memo_next + 1) % memo_size;
            return d;
          };
          lanes(-1, nx + 1, [&](auto tag, index_t i) {
            using V = typename decltype(tag)::type;
            const index_t c = base + i;
            const V inv[3] = {inv_gap_x.template operator()<V>(i), V(inv_y), V(inv_z)};
            V gr[3][3];
            for (int e = 0; e < 3; ++e)
              for (int a = 0; a < 3; ++a) gr[a][e] = central(a, e, c, inv[e]);
            const V mu_l = visc.mu(simd::load<V>(Tc + c));
            V S2 = V(0.0);
            for (int a = 0; a < 3; ++a)
              for (int b = 0; b < 3; ++b) {
                const V sab = V(0.5) * (gr[a][b] + gr[b][a]);
                S2 += sab * sab;
              }
            V delta;
            if constexpr (simd::is_pack_v<V>) {
              alignas(64) double dl[V::size];
              for (std::size_t l = 0; l < V::size; ++l) dl[l] = delta_at(i + index_t(l));
              delta = simd::load_aligned<V>(dl);
            } else {
              delta = delta_at(i);
            }
            V dw = V(1e30);
            if constexpr (needs_wall_distance) dw = simd::load<V>(ts.template get<field::wall_distance>() + c);
            const V mut = turb.eddy_viscosity(simd::load<V>(Wr + c), simd::sqrt(V(2.0) * S2), delta, dw);
            simd::store(ts.template get<field::mu_t>() + c, mut);
            simd::store(mu + c, mu_l + mut);
            simd::store(kk + c, V(cp) * (mu_l / V(visc.prandtl) + mut / V(turb.prandtl_t)));
          });
        }
      });
    // 3. Per axis, face fluxes into Fv (at the face's high cell) and every cell's difference
    //    across the axis into acc (race-free, thread-count independent).
    //    idc: 1/(distance between the two cells' centres) of the faces; inv[e]: the two
    //    cells' central-difference factors along the other axes (the same for both).
    auto face = [&]<int d, class V>(index_t cc, const V& idc, const V(&inv)[3]) {
      const index_t cm = cc - sd[d];
      // Gradient at the face: normal from the two cells, tangential the average of the two
      // cells' central differences.
      V gf[3][3], gT[3];
      for (int e = 0; e < 3; ++e) {
        if (e == d) {
          for (int a = 0; a < 3; ++a) gf[a][e] = (simd::load<V>(ub[a] + cc) - simd::load<V>(ub[a] + cm)) * idc;
          gT[e] = (simd::load<V>(Tc + cc) - simd::load<V>(Tc + cm)) * idc;
        } else {
          for (int a = 0; a < 3; ++a) gf[a][e] = V(0.5) * (central(a, e, cm, inv[e]) + central(a, e, cc, inv[e]));
          gT[e] = V(0.5) * (central(3, e, cm, inv[e]) + central(3, e, cc, inv[e]));
        }
      }
      const V muf = V(0.5) * (simd::load<V>(mu + cm) + simd::load<V>(mu + cc));
      const V kf = V(0.5) * (simd::load<V>(kk + cm) + simd::load<V>(kk + cc));
      const V div = gf[0][0] + gf[1][1] + gf[2][2];
      V tau[3];
      for (int a = 0; a < 3; ++a) tau[a] = muf * (gf[a][d] + gf[d][a] - (a == d ? V(2.0 / 3.0) * div : V(0.0)));
      V work = V(0.0);
      for (int a = 0; a < 3; ++a) work += tau[a] * V(0.5) * (simd::load<V>(ub[a] + cm) + simd::load<V>(ub[a] + cc));
      V ti[3];
      rotate(geo.R, tau, ti);
      for (int a = 0; a < 3; ++a) simd::store(Fv[a] + cc, ti[a]);
      simd::store(Fv[3] + cc, work + kf * gT[d]);
    };
    // Faces of row (j, k) along axis d (high cells i = 0 … n_x − 1, and n_x for x faces).
    auto faces_row = [&]<int d>(index_t j, index_t k) {
      const double* idc = grid.inv_centre_gaps(d);
      const index_t base = grid.index(0, j, k);
      const double inv_y = d == 1 ? 0.0 : inv_gap(1, j), inv_z = d == 2 ? 0.0 : inv_gap(2, k);
      lanes(0, nx + (d == 0), [&](auto tag, index_t i) {
        using V = typename decltype(tag)::type;
        const V id = d == 0 ? simd::load<V>(idc + i) : V(idc[d == 1 ? j : k]);
        const V inv[3] = {d == 0 ? V(0.0) : inv_gap_x.template operator()<V>(i), V(inv_y), V(inv_z)};
        face.template operator()<d, V>(base + i, id, inv);
      });
    };
    // Differences across axis d of the cells of row (j, k) into acc; after z, into dU.
    auto differences_row = [&]<int d>(index_t j, index_t k) {
      const index_t s = sd[d];
      const double* inv_h = grid.inv_widths(d);
      const index_t base = grid.index(0, j, k);
      lanes(0, nx, [&](auto tag, index_t i) {
        using V = typename decltype(tag)::type;
        const index_t c = base + i;
        const V ih = d == 0 ? simd::load<V>(inv_h + i) : V(inv_h[d == 1 ? j : k]);
        for (int q = 0; q < 4; ++q) {
          const V a0 = d == 0 ? V(0.0) : simd::load<V>(acc[q] + c);
          const V a = a0 + (simd::load<V>(Fv[q] + c + s) - simd::load<V>(Fv[q] + c)) * ih;
          // 4. After the last axis, the sum into the rates.
          if constexpr (d == 2) simd::store(dU[q + 1] + c, simd::load<V>(dU[q + 1] + c) + a);
          else simd::store(acc[q] + c, a);
        }
      });
    };
    // Each row's differences right after the faces they need (still in cache): x rows
    // by themselves, y rows walking j in each plane k, z rows walking k for each j.
    par_for(threaded, 0, nz, [&](index_t k) {
      for (index_t j = 0; j < ny; ++j) {
        faces_row.template operator()<0>(j, k);
        differences_row.template operator()<0>(j, k);
      }
    });
    hook(0, Fv);
    par_for(threaded, 0, nz, [&](index_t k) {
      for (index_t j = 0; j <= ny; ++j) {
        faces_row.template operator()<1>(j, k);
        if (j > 0) differences_row.template operator()<1>(j - 1, k);
      }
    });
    hook(1, Fv);
    par_for(threaded, 0, ny, [&](index_t j) {
      for (index_t k = 0; k <= nz; ++k) {
        faces_row.template operator()<2>(j, k);
        if (k > 0) differences_row.template operator()<2>(j, k - 1);
      }
    });
    hook(2, Fv);
  }
};

}  // namespace parafsi::fluid::detail
