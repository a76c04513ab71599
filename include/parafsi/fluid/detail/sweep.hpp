/// \file sweep.hpp
/// Inviscid face fluxes along one axis, accumulated into the cell rates:
///   dU_i −= (Ĝ_{i+½} − Ĝ_{i−½}) / Δx_i,
/// Ĝ the Galilean-shifted Riemann flux (flux/ale.hpp) of the reconstructed face states.
/// Reconstruction: MUSCL face values W_c ∓ (Δx_c/2)·limiter(a, b) with per-unit-length
/// gradients a, b (each cell's slope once per sweep); where a face value would have
/// ρ ≤ 0 or p ≤ 0 the cell falls back to first order. Lanes run along x in every
/// direction: x rows are reconstructed whole, then their n + 1 face fluxes; y and z
/// rows are walked along the axis keeping the previous row's high-face values and face
/// fluxes, so every slope is computed once and every cell is written once per axis.
#pragma once
#include <array>
#include <type_traits>
#include <vector>

#include "../../core/parallel.hpp"
#include "../../core/simd.hpp"
#include "../flux/ale.hpp"
#include "../gas.hpp"
#include "../grid.hpp"
#include "stage.hpp"

namespace parafsi::fluid::detail {

/// Thread-local row buffers for the flux sweeps: face values of a row of cells
/// (lo: at the cell's low face, hi: at its high face; hi of the previous row for
/// the y/z sweeps) and two rolling rows of face fluxes.
struct row_buffers {
  std::array<simd::aligned_vector<double>, 5> lo, hi, hi_prev, fa, fb;
};
/// One set per thread, rows of n_x cells; allocates only when too small.
inline void ensure_row_buffers(std::vector<row_buffers>& bufs, index_t nx) {
  const std::size_t nt = std::size_t(parallel::max_threads());
  const std::size_t len = std::size_t(nx) + 2 * simd::width + 4;
  if (bufs.size() < nt || (bufs.size() && bufs[0].lo[0].size() < len)) {
    bufs.assign(nt, {});
    for (auto& rb : bufs)
      for (auto* arr : {&rb.lo, &rb.hi, &rb.hi_prev, &rb.fa, &rb.fb})
        for (auto& v : *arr) v.assign(len, 0.0);
  }
}

/// Reconstruction and Riemann flux on the primitive arrays W of a stage.
template <class Flux, class Recon>
struct face_kernel {
  const Flux& flux;
  const Recon& recon;
  const gas::ideal& gas;
  const rectilinear_grid& grid;
  fields5<const double> W;

  /// Face values of the cells starting at c (lanes along x) along axis D, stored at
  /// lane offset o of lo (low face) and hi (high face); ia: the cells' index along D.
  template <int D, class V>
  PARAFSI_INLINE void cell_faces(index_t c, index_t s, index_t ia, double* const* lo, double* const* hi,
                                 index_t o) const noexcept {
    if constexpr (Recon::second_order) {
      const double* idc = grid.inv_centre_gaps(D);
      const double* hdx = grid.half_widths(D);
      V idc_c, idc_p, h_c;
      if constexpr (D == 0) {
        idc_c = simd::load<V>(idc + ia);
        idc_p = simd::load<V>(idc + ia + 1);
        h_c = simd::load<V>(hdx + ia);
      } else {
        idc_c = V(idc[ia]);
        idc_p = V(idc[ia + 1]);
        h_c = V(hdx[ia]);
      }
      V q[5], l[5], r[5];
      for (int f = 0; f < 5; ++f) {
        const V qm = simd::load<V>(W[f] + c - s);
        q[f] = simd::load<V>(W[f] + c);
        const V qp = simd::load<V>(W[f] + c + s);
        const V d = recon.slope((q[f] - qm) * idc_c, (qp - q[f]) * idc_p) * h_c;
        l[f] = q[f] - d;
        r[f] = q[f] + d;
      }
      const auto bad = (l[0] <= V(0.0)) || (r[0] <= V(0.0)) || (l[4] <= V(0.0)) || (r[4] <= V(0.0));
      if (simd::any(bad))
        for (int f = 0; f < 5; ++f) {
          l[f] = simd::select(bad, q[f], l[f]);
          r[f] = simd::select(bad, q[f], r[f]);
        }
      for (int f = 0; f < 5; ++f) {
        simd::store(lo[f] + o, l[f]);
        simd::store(hi[f] + o, r[f]);
      }
    } else {
      (void)s;
      (void)ia;
      for (int f = 0; f < 5; ++f) {
        const V q = simd::load<V>(W[f] + c);
        simd::store(lo[f] + o, q);
        simd::store(hi[f] + o, q);
      }
    }
  }

  /// ALE Riemann flux from face values L (left/low side) and R at lane offsets.
  template <class V>
  PARAFSI_INLINE cons<V> face_flux(const double* const* L, index_t oL, const double* const* R, index_t oR, const V& wn,
                                   const vec3<double>& n) const noexcept {
    const prim<V> wl{simd::load<V>(L[0] + oL),
                     {simd::load<V>(L[1] + oL), simd::load<V>(L[2] + oL), simd::load<V>(L[3] + oL)},
                     simd::load<V>(L[4] + oL)};
    const prim<V> wr{simd::load<V>(R[0] + oR),
                     {simd::load<V>(R[1] + oR), simd::load<V>(R[2] + oR), simd::load<V>(R[3] + oR)},
                     simd::load<V>(R[4] + oR)};
    return flux::ale_flux(flux, wl, wr, n, wn, gas);
  }
};

PARAFSI_INLINE void store_flux(double* const* out, index_t o, const auto& F) noexcept {
  simd::store(out[0] + o, F.rho);
  simd::store(out[1] + o, F.m.x);
  simd::store(out[2] + o, F.m.y);
  simd::store(out[3] + o, F.m.z);
  simd::store(out[4] + o, F.E);
}

/// Where a sweep leaves the fluxes of the grid's two boundary faces along its axis (a
/// block of a block mesh: coarse–fine flux correction); `no_register` keeps none.
struct no_register {};
/// Five component arrays per side, indexed by the transverse cell: j + n_y k (x faces),
/// i + n_x k (y faces), i + n_x j (z faces).
struct face_register {
  fields5<double> lo{}, hi{};
};

/// Inviscid fluxes along axis D accumulated into dU (D = 0 initialises dU).
template <int D, class Flux, class Recon, class Register = no_register>
void sweep(const face_kernel<Flux, Recon>& fk, const stage_geometry& geo, const fields5<double>& dU,
           std::vector<row_buffers>& bufs, bool threaded, const Register& reg = {}) {
  constexpr bool keep = std::is_same_v<Register, face_register>;
  const rectilinear_grid& grid = fk.grid;
  const index_t nx = grid.n(0), ny = grid.n(1), nz = grid.n(2);
  const vec3<double> n = geo.n[D];
  const double* x0 = grid.centres(0);
  const double* x1 = grid.centres(1);
  const double* x2 = grid.centres(2);
  auto ptrs = [](std::array<simd::aligned_vector<double>, 5>& a) {
    return std::array<double*, 5>{a[0].data(), a[1].data(), a[2].data(), a[3].data(), a[4].data()};
  };
  if constexpr (D == 0) {
    const double* idx = grid.inv_widths(0);
    par_for(threaded, 0, ny * nz, [&](index_t r) {
      const index_t j = r % ny, k = r / ny;
      auto& rb = bufs[std::size_t(parallel::thread_id())];
      const auto lo = ptrs(rb.lo), hi = ptrs(rb.hi), fb = ptrs(rb.fa);
      const index_t base = grid.index(0, j, k);
      // Face values of cells −1 … n_x, stored at offset i + 1.
      simd::for_each_pack(-1, nx + 1, [&](auto tag, index_t i) {
        using V = typename decltype(tag)::type;
        fk.template cell_faces<0, V>(base + i, 1, i, lo.data(), hi.data(), i + 1);
      });
      // ŵ_x on x faces: v̂_x + ω̂_y z − ω̂_z y (constant along the row).
      const double wn = geo.vh[0] + geo.oh[1] * x2[k] - geo.oh[2] * x1[j];
      simd::for_each_pack(0, nx + 1, [&](auto tag, index_t i) {  // face i: cells i−1 | i
        using V = typename decltype(tag)::type;
        store_flux(fb.data(), i, fk.template face_flux<V>(hi.data(), i, lo.data(), i + 1, V(wn), n));
      });
      if constexpr (keep)
        for (int f = 0; f < 5; ++f) {
          reg.lo[f][r] = fb[f][0];
          reg.hi[f][r] = fb[f][nx];
        }
      simd::for_each_pack(0, nx, [&](auto tag, index_t i) {
        using V = typename decltype(tag)::type;
        const V id = simd::load<V>(idx + i);
        for (int f = 0; f < 5; ++f)
          simd::store(dU[f] + base + i, (simd::load<V>(fb[f] + i) - simd::load<V>(fb[f] + i + 1)) * id);
      });
    });
  } else {
    constexpr int T = (D == 1) ? 2 : 1;  // the other transverse axis (parallelised)
    const index_t nD = grid.n(D), nT = grid.n(T);
    const index_t s = grid.stride(D);
    const double* idx = grid.inv_widths(D);
    par_for(threaded, 0, nT, [&](index_t q) {
      auto& rb = bufs[std::size_t(parallel::thread_id())];
      auto lo = ptrs(rb.lo), hi = ptrs(rb.hi), hi_prev = ptrs(rb.hi_prev);
      auto cur = ptrs(rb.fa), prev = ptrs(rb.fb);
      for (index_t row = -1; row <= nD; ++row) {  // cells along D; face `row` is row−1 | row
        const index_t j = D == 1 ? row : q, k = D == 1 ? q : row;
        const index_t base = grid.index(0, j, k);
        simd::for_each_pack(0, nx, [&](auto tag, index_t i) {
          using V = typename decltype(tag)::type;
          fk.template cell_faces<D, V>(base + i, s, row, lo.data(), hi.data(), i);
        });
        if (row >= 0) {
          // ŵ on y faces: v̂_y + ω̂_z x − ω̂_x z;  on z faces: v̂_z + ω̂_x y − ω̂_y x.
          const double wconst = D == 1 ? geo.vh[1] - geo.oh[0] * x2[k] : geo.vh[2] + geo.oh[0] * x1[j];
          const double wslope = D == 1 ? geo.oh[2] : -geo.oh[1];
          simd::for_each_pack(0, nx, [&](auto tag, index_t i) {
            using V = typename decltype(tag)::type;
            const V wn = V(wconst) + V(wslope) * simd::load<V>(x0 + i);
            store_flux(cur.data(), i, fk.template face_flux<V>(hi_prev.data(), i, lo.data(), i, wn, n));
          });
          if constexpr (keep)
            if (row == 0 || row == nD) {
              const fields5<double>& side = row == 0 ? reg.lo : reg.hi;
              for (int f = 0; f < 5; ++f)
                simd::for_each_pack(0, nx, [&](auto tag, index_t i) {
                  using V = typename decltype(tag)::type;
                  simd::store(side[f] + i + nx * q, simd::load<V>(cur[f] + i));
                });
            }
          if (row >= 1) {
            const index_t cbase = base - s;  // cell row−1 receives F_{row−1/2} − F_{row+1/2}
            const double id = idx[row - 1];
            simd::for_each_pack(0, nx, [&](auto tag, index_t i) {
              using V = typename decltype(tag)::type;
              for (int c = 0; c < 5; ++c)
                simd::store(dU[c] + cbase + i, simd::load<V>(dU[c] + cbase + i) +
                                                   (simd::load<V>(prev[c] + i) - simd::load<V>(cur[c] + i)) * V(id));
            });
          }
          std::swap(cur, prev);
        }
        std::swap(hi, hi_prev);
      }
    });
  }
}

}  // namespace parafsi::fluid::detail
