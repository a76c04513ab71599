/// \file wall_distance.hpp
/// The distance field d_w of a mixing-length closure (turbulence/prandtl_mixing_length.hpp:
/// l_m = min(κ d_w, C_l L_ref, C_Δ Δ)) from a moving structure given as points (its nodes,
/// box coordinates): d_w(cell) = min over the points p within `reach` of the cell centre of
/// |x_c − p|, and +∞ (1e30) beyond. With reach ≥ C_l L_ref / κ the closure sees the exact
/// point distance wherever κ d_w is its smallest length; beyond it d_w does not matter.
/// Points stand for the surface between them: on a triangulated sheet the distance to the
/// nearest node exceeds the distance to the surface by at most the element's circumradius
/// (≤ the longest edge / √3), which bounds the error of d_w near the cloth.
///
/// Cost: O(cells) to reset, then per point within reach of the grid the cells of a cube
/// 2·reach wide (index ranges by binary search on the axes' centres), in squared distances
/// with one √ per cell at the end (the same values: √ is monotone and correctly rounded).
#pragma once
#include <algorithm>
#include <cmath>
#include <span>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "grid.hpp"

namespace parafsi::fluid {

/// d_w on every interior cell of `grid` (flat index; with `ghosts`, on the ghost layers too,
/// else they are left untouched) from `points` (box coordinates) within `reach` (m); `out`
/// has grid.total_cells() entries. The viscous pass computes μ_t on the first ghost layer,
/// so fill the ghosts (a block of a block mesh: its neighbour's eddy viscosity; a box: a
/// boundary ghost within reach of a point then takes its own distance, not the full mixing
/// length, and a box and a one-level block mesh agree to round-off there).
inline void distance_to_points(const rectilinear_grid& grid, std::span<const Eigen::Vector3d> points, double reach,
                               std::span<double> out, bool ghosts = false) {
  require(std::isfinite(reach) && reach > 0, "fluid::distance_to_points: reach must be finite and > 0, got ", reach);
  require(out.size() == std::size_t(grid.total_cells()), "fluid::distance_to_points: ", out.size(),
          " values for a grid of ", grid.total_cells(), " cells (ghosts included)");
  constexpr double far = 1e30, far2 = 1e60;
  const index_t g = ghosts ? rectilinear_grid::ghosts : 0;  // cells −g … n − 1 + g
  // Squared distances first (min and √ commute exactly), √ once per cell at the end.
  auto rows = [&](auto&& fn) {
    for (index_t k = -g; k < grid.n(2) + g; ++k)
      for (index_t j = -g; j < grid.n(1) + g; ++j) fn(out.data() + grid.index(-g, j, k), grid.n(0) + 2 * g);
  };
  rows([&](double* row, index_t len) { std::fill(row, row + len, far2); });
  // The cells' centres span [c_lo, c_hi] per axis; a point farther than `reach` outside
  // that span touches no cell (the blocks of a block mesh skip most points so).
  double c_lo[3], c_hi[3];
  for (int d = 0; d < 3; ++d) {
    c_lo[d] = grid.centre(d, -g);
    c_hi[d] = grid.centre(d, grid.n(d) - 1 + g);
  }
  const double r2 = reach * reach;
  for (const Eigen::Vector3d& p : points) {
    require(p.allFinite(), "fluid::distance_to_points: a point is not finite");
    if (p[0] < c_lo[0] - reach || p[0] > c_hi[0] + reach || p[1] < c_lo[1] - reach || p[1] > c_hi[1] + reach ||
        p[2] < c_lo[2] - reach || p[2] > c_hi[2] + reach)
      continue;
    index_t lo[3], hi[3];
    for (int d = 0; d < 3; ++d) {
      const double* c = grid.centres(d) - g;
      const index_t n = grid.n(d) + 2 * g;
      lo[d] = index_t(std::lower_bound(c, c + n, p[d] - reach) - c) - g;
      hi[d] = index_t(std::upper_bound(c, c + n, p[d] + reach) - c) - g;
    }
    for (index_t k = lo[2]; k < hi[2]; ++k) {
      const double dz = grid.centre(2, k) - p[2];
      for (index_t j = lo[1]; j < hi[1]; ++j) {
        const double dy = grid.centre(1, j) - p[1];
        const double dyz = dy * dy + dz * dz;
        if (dyz > r2) continue;
        double* row = out.data() + grid.index(0, j, k);
        const double* cx = grid.centres(0);
        for (index_t i = lo[0]; i < hi[0]; ++i) {
          const double dx = cx[i] - p[0];
          const double q = dx * dx + dyz;
          row[i] = std::min(row[i], q <= r2 ? q : far2);
        }
      }
    }
  }
  rows([&](double* row, index_t len) {
    for (index_t i = 0; i < len; ++i) row[i] = row[i] < far2 ? std::sqrt(row[i]) : far;
  });
}

}  // namespace parafsi::fluid
