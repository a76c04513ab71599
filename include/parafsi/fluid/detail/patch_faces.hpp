/// \file patch_faces.hpp
/// Patched faces (fluid/patch.hpp): per face of the patcher's list, in list order
/// (serial, deterministic), recompute the face's regular flux F from the stage's face
/// values, ask the patcher for the one-sided fluxes F_lo, F_hi and correct the rates
///   dU_low += (F − F_lo)/Δx_low,   dU_high −= (F − F_hi)/Δx_high   (interior cells only).
///
/// One-sided reconstruction (patchers with `one_sided_reconstruction = true`, a membrane
/// in the face): the sweeps' MUSCL slopes of the two cells beside a patched face read
/// across it. For such a patcher the cells with a patched face along the axis are
/// reconstructed from their own side only: a cell blocked on its high face takes
///   Δ = limiter((W_i − W_{i−1})/δ_{i−½}, (W_{i−1} − W_{i−2})/δ_{i−3/2}) Δx_i/2
/// (the second difference replaced by the first where face i − 3/2 is also blocked),
/// mirrored for a low face; a cell blocked on both faces is first order; the positivity
/// fallback is the sweeps'. The patcher sees these values as the face states L, R (second
/// order up to the membrane), and the fluxes of the unblocked neighbouring faces
/// (i − ½ of the low cell, i + 3/2 of the high one) are recomputed with them, the
/// difference to the sweeps' flux moved between the two cells (conservative). Each such
/// neighbouring face is corrected once: by the patch on its high cell's high face if there
/// is one, else by the patch on its low cell's low face.
#pragma once
#include <cstdint>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "../../core/error.hpp"
#include "../patch.hpp"
#include "../view.hpp"
#include "sweep.hpp"

namespace parafsi::fluid::detail {

/// Whether a patcher asks for one-sided reconstruction beside its faces.
template <class P>
constexpr bool wants_one_sided() {
  if constexpr (requires { P::one_sided_reconstruction; }) return P::one_sided_reconstruction;
  else return false;
}

/// Two-sided face values of `cell` along D (what the sweeps used).
template <int D, class Flux, class Recon>
void sweep_cell_faces(const face_kernel<Flux, Recon>& fk, index_t cell, index_t ia, double* lo, double* hi) {
  double* pl[5] = {&lo[0], &lo[1], &lo[2], &lo[3], &lo[4]};
  double* ph[5] = {&hi[0], &hi[1], &hi[2], &hi[3], &hi[4]};
  fk.template cell_faces<D, double>(cell, fk.grid.stride(D), ia, pl, ph, 0);
}

/// Centre (box coordinates) of the face between cells high − stride(d) and high.
inline Eigen::Vector3d face_centre(const rectilinear_grid& grid, int d, index_t high) {
  const auto ijk = grid.ijk(high);
  Eigen::Vector3d x(grid.centre(0, ijk[0]), grid.centre(1, ijk[1]), grid.centre(2, ijk[2]));
  x[d] = grid.face(d, ijk[std::size_t(d)]);
  return x;
}
/// The grid's speed along axis d at box point x (the face's normal speed w_n).
inline double face_speed(const stage_geometry& geo, int d, const Eigen::Vector3d& x) {
  return geo.vh[d] + geo.oh.cross(x)[d];
}

/// The blocked faces of a cell along one axis as the one-sided reconstruction reads them:
/// its low and high face, and the far face of the neighbour on its open side (face i − 3/2
/// of a cell blocked on its high face, i + 3/2 of one blocked on its low face).
struct blocked_faces {
  bool lo = false, hi = false, far = false;
};

/// Face values of `cell` along D (flat index of fk's grid, index ia along D): the
/// two-sided MUSCL values where neither face along D is blocked, else the one-sided values
/// of the file comment.
template <int D, class Flux, class Recon>
void one_sided_cell_faces(const face_kernel<Flux, Recon>& fk, blocked_faces bf, index_t cell, index_t ia, double* lo,
                          double* hi) {
  if (!bf.lo && !bf.hi) {
    sweep_cell_faces<D>(fk, cell, ia, lo, hi);
    return;
  }
  double q[5];
  for (int f = 0; f < 5; ++f) q[f] = fk.W[f][cell];
  if constexpr (Recon::second_order) {
    if (!(bf.lo && bf.hi)) {
      const index_t s = fk.grid.stride(D);
      const double* idc = fk.grid.inv_centre_gaps(D);
      const double h = fk.grid.half_widths(D)[ia];
      // Towards the open side: the near difference a and the next one b (or a again).
      const index_t o = bf.hi ? -s : s;  // step into the open side
      const double ia_near = bf.hi ? idc[ia] : idc[ia + 1], ia_far = bf.hi ? idc[ia - 1] : idc[ia + 2];
      const double sg = bf.hi ? 1.0 : -1.0;  // differences taken low → high
      double l[5], r[5];
      for (int f = 0; f < 5; ++f) {
        const double* w = fk.W[f];
        const double a = sg * (w[cell] - w[cell + o]) * ia_near;
        const double b = bf.far ? a : sg * (w[cell + o] - w[cell + 2 * o]) * ia_far;
        const double d = fk.recon.slope(a, b) * h;
        l[f] = q[f] - d;
        r[f] = q[f] + d;
      }
      const bool bad = l[0] <= 0.0 || r[0] <= 0.0 || l[4] <= 0.0 || r[4] <= 0.0;
      if (!bad) {
        for (int f = 0; f < 5; ++f) {
          lo[f] = l[f];
          hi[f] = r[f];
        }
        return;
      }
    }
  }
  for (int f = 0; f < 5; ++f) lo[f] = hi[f] = q[f];
}

/// The blocked faces of `cell` along D from the box's marks (bit 2D: low face, 2D + 1:
/// high face of `blocked`).
template <int D>
blocked_faces blocked_along(const std::vector<std::uint8_t>& blocked, index_t cell, index_t s) {
  const std::uint8_t lo_bit = std::uint8_t(1u << (2 * D)), hi_bit = std::uint8_t(1u << (2 * D + 1));
  blocked_faces bf;
  bf.lo = blocked[std::size_t(cell)] & lo_bit;
  bf.hi = blocked[std::size_t(cell)] & hi_bit;
  if (bf.lo != bf.hi) bf.far = blocked[std::size_t(cell + (bf.hi ? -s : s))] & (bf.hi ? lo_bit : hi_bit);
  return bf;
}

/// Face values of `cell` along D on the box (one_sided_cell_faces with the box's marks).
template <int D, class Flux, class Recon>
void blocked_cell_faces(const face_kernel<Flux, Recon>& fk, const std::vector<std::uint8_t>& blocked, index_t cell,
                        index_t ia, double* lo, double* hi) {
  one_sided_cell_faces<D>(fk, blocked_along<D>(blocked, cell, fk.grid.stride(D)), cell, ia, lo, hi);
}

inline prim<double> prim_of(const double* v) { return {v[0], {v[1], v[2], v[3]}, v[4]}; }

/// One cell beside a recomputed face: the face kernel of the grid that holds it (the
/// box's, or a block's), its flat index there and index along the axis, its blocked faces,
/// and whether its rate is updated (false for a ghost outside the box).
template <class Flux, class Recon>
struct face_side {
  const face_kernel<Flux, Recon>* fk;
  index_t cell, ia;
  blocked_faces bf;
  bool in;
};

/// The change F1 − F0 of the unblocked face between a (low) and b (high) along D when
/// its face states are the one-sided values instead of the sweeps' (F0); the face's
/// centre is b's low face on b's grid.
template <int D, class Flux, class Recon>
cons<double> neighbour_face_change(const stage_geometry& geo, const face_side<Flux, Recon>& a,
                                   const face_side<Flux, Recon>& b) {
  double la[5], ha[5], lb[5], hb[5], la1[5], ha1[5], lb1[5], hb1[5];
  sweep_cell_faces<D>(*a.fk, a.cell, a.ia, la, ha);
  sweep_cell_faces<D>(*b.fk, b.cell, b.ia, lb, hb);
  one_sided_cell_faces<D>(*a.fk, a.bf, a.cell, a.ia, la1, ha1);
  one_sided_cell_faces<D>(*b.fk, b.bf, b.cell, b.ia, lb1, hb1);
  const auto& fk = *b.fk;
  const vec3<double> n = geo.n[std::size_t(D)];
  const double wn = face_speed(geo, D, face_centre(fk.grid, D, b.cell));
  const cons<double> F0 = flux::ale_flux(fk.flux, prim_of(ha), prim_of(lb), n, wn, fk.gas);
  const cons<double> F1 = flux::ale_flux(fk.flux, prim_of(ha1), prim_of(lb1), n, wn, fk.gas);
  return {F1.rho - F0.rho, {F1.m.x - F0.m.x, F1.m.y - F0.m.y, F1.m.z - F0.m.z}, F1.E - F0.E};
}

/// A face's flux change between two cells' rates: dU_a −= d/Δx_a (if a_in), dU_b += d/Δx_b
/// (if b_in); a recorded change (block_solver's face records) is replayed by the same code.
inline void shift_face_change(const double* d, index_t ga, double ixa, bool a_in, index_t gb, double ixb, bool b_in,
                              const fields5<double>& dU) {
  for (int q = 0; q < 5; ++q) {
    if (a_in) dU[q][ga] -= d[q] * ixa;
    if (b_in) dU[q][gb] += d[q] * ixb;
  }
}

/// The inverse widths of a face change's two cells along D (0 for a side that is not `in`).
template <int D, class Flux, class Recon>
std::pair<double, double> face_change_widths(const face_side<Flux, Recon>& a, const face_side<Flux, Recon>& b) {
  return {a.in ? a.fk->grid.inv_widths(D)[a.ia] : 0.0, b.in ? b.fk->grid.inv_widths(D)[b.ia] : 0.0};
}

/// Move a face's flux change dF between its cells' rates (global indices of dU; a side
/// that is not `in` is left alone): dU_a −= dF/Δx_a, dU_b += dF/Δx_b.
template <int D, class Flux, class Recon>
void move_face_change(const cons<double>& dF, const face_side<Flux, Recon>& a, index_t ga,
                      const face_side<Flux, Recon>& b, index_t gb, const fields5<double>& dU) {
  const double d[5] = {dF.rho, dF.m.x, dF.m.y, dF.m.z, dF.E};
  const auto [ixa, ixb] = face_change_widths<D>(a, b);
  shift_face_change(d, ga, ixa, a.in, gb, ixb, b.in, dU);
}

/// Recompute the unblocked face between cells a (low, index ia along D) and a + s of the
/// box with the one-sided values and move the difference to the sweeps' flux between the
/// cells.
template <int D, class Flux, class Recon>
void correct_neighbour_face(const face_kernel<Flux, Recon>& fk, const stage_geometry& geo,
                            const std::vector<std::uint8_t>& blocked, index_t a, index_t ia,
                            const fields5<double>& dU) {
  const index_t s = fk.grid.stride(D), b = a + s;
  const face_side<Flux, Recon> A{&fk, a, ia, blocked_along<D>(blocked, a, s), ia >= 0};
  const face_side<Flux, Recon> B{&fk, b, ia + 1, blocked_along<D>(blocked, b, s), ia + 1 < fk.grid.n(D)};
  move_face_change<D>(neighbour_face_change<D>(geo, A, B), A, a, B, b, dU);
}

/// fn(std::integral_constant<int, d>{}) for the run-time axis d.
template <class Fn>
void with_axis(int d, Fn&& fn) {
  if (d == 0) fn(std::integral_constant<int, 0>{});
  else if (d == 1) fn(std::integral_constant<int, 1>{});
  else fn(std::integral_constant<int, 2>{});
}

/// The face between cells c − stride(d) and c of fk's grid (c's index along d: ic): its
/// geometry and two-sided face states into fc (normal, centre, grid speed, area, L, R), and
/// its regular (sweep) flux returned. The caller names the cells (fc.low, fc.high), the
/// stage and the patch.
template <class Flux, class Recon>
cons<double> regular_face(const face_kernel<Flux, Recon>& fk, const stage_geometry& geo, int d, index_t c,
                          face_context& fc) {
  const rectilinear_grid& grid = fk.grid;
  const auto ijk = grid.ijk(c);
  const index_t ic = ijk[std::size_t(d)], m = c - grid.stride(d);
  double lo_m[5], hi_m[5], lo_c[5], hi_c[5];
  with_axis(d, [&](auto D) {
    sweep_cell_faces<decltype(D)::value>(fk, m, ic - 1, lo_m, hi_m);
    sweep_cell_faces<decltype(D)::value>(fk, c, ic, lo_c, hi_c);
  });
  fc.axis = d;
  fc.L = prim_of(hi_m);
  fc.R = prim_of(lo_c);
  fc.n = geo.n[std::size_t(d)];
  fc.centre = face_centre(grid, d, c);
  fc.wn = face_speed(geo, d, fc.centre);
  const int a = (d + 1) % 3, b = (d + 2) % 3;
  fc.area = grid.width(a, ijk[std::size_t(a)]) * grid.width(b, ijk[std::size_t(b)]);
  return flux::ale_flux(fk.flux, fc.L, fc.R, fc.n, fc.wn, fk.gas);
}

/// The patcher's fluxes into the rates of the face's cells (flat indices of dU):
/// dU_low += (F − F_lo)/Δx_low, dU_high −= (F − F_hi)/Δx_high; a cell flagged out (a ghost)
/// is left alone.
inline void apply_face_patch(const cons<double>& F, const cons<double>& Flo, const cons<double>& Fhi, index_t low,
                             double inv_dx_low, bool low_in, index_t high, double inv_dx_high, bool high_in,
                             const fields5<double>& dU) {
  const double dlo[5] = {F.rho - Flo.rho, F.m.x - Flo.m.x, F.m.y - Flo.m.y, F.m.z - Flo.m.z, F.E - Flo.E};
  const double dhi[5] = {F.rho - Fhi.rho, F.m.x - Fhi.m.x, F.m.y - Fhi.m.y, F.m.z - Fhi.m.z, F.E - Fhi.E};
  for (int q = 0; q < 5; ++q) {
    if (low_in) dU[q][low] += dlo[q] * inv_dx_low;
    if (high_in) dU[q][high] -= dhi[q] * inv_dx_high;
  }
}

template <class Flux, class Recon, class Patcher>
void patch_faces(const face_kernel<Flux, Recon>& fk, const stage_geometry& geo, const view& state, int stage,
                 const fields5<double>& dU, Patcher& patcher, std::vector<std::uint8_t>& blocked) {
  constexpr bool one_sided = wants_one_sided<Patcher>() && Recon::second_order;
  const rectilinear_grid& grid = fk.grid;
  const std::span<const patch_face> faces = patcher.patch_faces();
  for (std::size_t pi = 0; pi < faces.size(); ++pi) {
    const index_t c = faces[pi].high;
    const int d = faces[pi].axis;
    require(d >= 0 && d < 3 && c >= grid.stride(d) && c < grid.total_cells(), "fluid::solver: bad patched face ", pi,
            " (cell ", c, ", axis ", d, ")");
  }
  // Faces with a ghost cell on either side keep the sweeps' values.
  auto interior = [&](const patch_face& f) {
    const index_t i = grid.ijk(f.high)[std::size_t(f.axis)];
    return i >= 1 && i < grid.n(f.axis);
  };
  if constexpr (one_sided) {
    if (blocked.size() != std::size_t(grid.total_cells())) blocked.assign(std::size_t(grid.total_cells()), 0);
    for (const patch_face& f : faces) {
      if (!interior(f)) continue;
      blocked[std::size_t(f.high)] |= std::uint8_t(1u << (2 * f.axis));
      blocked[std::size_t(f.high - grid.stride(f.axis))] |= std::uint8_t(1u << (2 * f.axis + 1));
    }
  }
  for (std::size_t pi = 0; pi < faces.size(); ++pi) {
    const index_t c = faces[pi].high;
    const int d = faces[pi].axis;
    const index_t s = grid.stride(d), m = c - s;
    const index_t ic = grid.ijk(c)[std::size_t(d)];  // the high cell's index along d
    face_context fc;
    fc.low = m;
    fc.high = c;
    fc.stage = stage;
    fc.patch = pi;
    const cons<double> F = regular_face(fk, geo, d, c, fc);
    if constexpr (one_sided) {
      // The membrane sees the one-sided face states; the unblocked neighbouring faces are
      // recomputed with them (each once, see the file comment).
      if (interior(faces[pi]))
        with_axis(d, [&](auto D) {
          double l1[5], h1[5];
          blocked_cell_faces<decltype(D)::value>(fk, blocked, m, ic - 1, l1, h1);
          fc.L = prim_of(h1);
          blocked_cell_faces<decltype(D)::value>(fk, blocked, c, ic, l1, h1);
          fc.R = prim_of(l1);
          const std::uint8_t lo_bit = std::uint8_t(1u << (2 * d)), hi_bit = std::uint8_t(1u << (2 * d + 1));
          if (!(blocked[std::size_t(m)] & lo_bit))
            correct_neighbour_face<decltype(D)::value>(fk, geo, blocked, m - s, ic - 2, dU);
          if (!(blocked[std::size_t(c)] & hi_bit) && !(blocked[std::size_t(c + s)] & hi_bit))
            correct_neighbour_face<decltype(D)::value>(fk, geo, blocked, c, ic, dU);
        });
    }
    cons<double> Flo = F, Fhi = F;
    patcher.patch(fc, state, Flo, Fhi);
    apply_face_patch(F, Flo, Fhi, m, grid.inv_widths(d)[ic - 1], ic - 1 >= 0, c, grid.inv_widths(d)[ic], ic < grid.n(d),
                     dU);
  }
  if constexpr (one_sided)
    for (const patch_face& f : faces) {
      if (!interior(f)) continue;
      blocked[std::size_t(f.high)] = 0;
      blocked[std::size_t(f.high - grid.stride(f.axis))] = 0;
    }
}

}  // namespace parafsi::fluid::detail
