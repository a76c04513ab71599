/// \file patch_faces.hpp
/// Patched faces (fluid/patch.hpp): per face of the patcher's list, in list order
/// (serial, deterministic), recompute the face's regular flux F from the stage's face
/// values, ask the patcher for the one-sided fluxes F_lo, F_hi and correct the rates
///   dU_low += (F − F_lo)/Δx_low,   dU_high −= (F − F_hi)/Δx_high   (interior cells only).
#pragma once
#include <span>

#include "../../core/error.hpp"
#include "../patch.hpp"
#include "../view.hpp"
#include "sweep.hpp"

namespace parafsi::fluid::detail {

template <class Flux, class Recon, class Patcher>
void patch_faces(const face_kernel<Flux, Recon>& fk, const stage_geometry& geo, const view& state, int stage,
                 const fields5<double>& dU, Patcher& patcher) {
  const rectilinear_grid& grid = fk.grid;
  const std::span<const patch_face> faces = patcher.patch_faces();
  for (std::size_t pi = 0; pi < faces.size(); ++pi) {
    const index_t c = faces[pi].high;
    const int d = faces[pi].axis;
    require(d >= 0 && d < 3 && c >= grid.stride(d) && c < grid.total_cells(), "fluid::solver: bad patched face ", pi,
            " (cell ", c, ", axis ", d, ")");
    const index_t s = grid.stride(d), m = c - s;
    const auto ijk = grid.ijk(c);  // axis indices of the high cell
    double lo_m[5], hi_m[5], lo_c[5], hi_c[5];
    double* pl[5] = {&lo_m[0], &lo_m[1], &lo_m[2], &lo_m[3], &lo_m[4]};
    double* ph[5] = {&hi_m[0], &hi_m[1], &hi_m[2], &hi_m[3], &hi_m[4]};
    double* ql[5] = {&lo_c[0], &lo_c[1], &lo_c[2], &lo_c[3], &lo_c[4]};
    double* qh[5] = {&hi_c[0], &hi_c[1], &hi_c[2], &hi_c[3], &hi_c[4]};
    auto faces_of = [&](index_t cell, index_t ia, double** lo, double** hi) {
      if (d == 0) fk.template cell_faces<0, double>(cell, s, ia, lo, hi, 0);
      else if (d == 1) fk.template cell_faces<1, double>(cell, s, ia, lo, hi, 0);
      else fk.template cell_faces<2, double>(cell, s, ia, lo, hi, 0);
    };
    faces_of(m, ijk[std::size_t(d)] - 1, pl, ph);
    faces_of(c, ijk[std::size_t(d)], ql, qh);
    face_context fc;
    fc.low = m;
    fc.high = c;
    fc.axis = d;
    fc.stage = stage;
    fc.patch = pi;
    fc.L = {hi_m[0], {hi_m[1], hi_m[2], hi_m[3]}, hi_m[4]};
    fc.R = {lo_c[0], {lo_c[1], lo_c[2], lo_c[3]}, lo_c[4]};
    fc.n = geo.n[std::size_t(d)];
    fc.centre = {grid.centre(0, ijk[0]), grid.centre(1, ijk[1]), grid.centre(2, ijk[2])};
    fc.centre[d] = grid.face(d, ijk[std::size_t(d)]);
    fc.wn = geo.vh[d] + geo.oh.cross(fc.centre)[d];
    const int a = (d + 1) % 3, b = (d + 2) % 3;
    fc.area = grid.width(a, ijk[std::size_t(a)]) * grid.width(b, ijk[std::size_t(b)]);
    const cons<double> F = flux::ale_flux(fk.flux, fc.L, fc.R, fc.n, fc.wn, fk.gas);
    cons<double> Flo = F, Fhi = F;
    patcher.patch(fc, state, Flo, Fhi);
    const double idm = grid.inv_widths(d)[ijk[std::size_t(d)] - 1], idc = grid.inv_widths(d)[ijk[std::size_t(d)]];
    const double dlo[5] = {F.rho - Flo.rho, F.m.x - Flo.m.x, F.m.y - Flo.m.y, F.m.z - Flo.m.z, F.E - Flo.E};
    const double dhi[5] = {F.rho - Fhi.rho, F.m.x - Fhi.m.x, F.m.y - Fhi.m.y, F.m.z - Fhi.m.z, F.E - Fhi.E};
    const bool m_interior = ijk[std::size_t(d)] - 1 >= 0, c_interior = ijk[std::size_t(d)] < grid.n(d);
    for (int q = 0; q < 5; ++q) {
      if (m_interior) dU[q][m] += dlo[q] * idm;
      if (c_interior) dU[q][c] -= dhi[q] * idc;
    }
  }
}

}  // namespace parafsi::fluid::detail
