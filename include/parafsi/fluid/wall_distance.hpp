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
/// Cost: O(cells) to reset, then per point the cells of a cube 2·reach wide (index ranges by
/// binary search on the axes' centres).
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
/// has grid.total_cells() entries. A block of a block mesh fills its ghosts as well, so the
/// eddy viscosity of a ghost cell is its neighbour's.
inline void distance_to_points(const rectilinear_grid& grid, std::span<const Eigen::Vector3d> points, double reach,
                               std::span<double> out, bool ghosts = false) {
  require(std::isfinite(reach) && reach > 0, "fluid::distance_to_points: reach must be finite and > 0, got ", reach);
  require(out.size() == std::size_t(grid.total_cells()), "fluid::distance_to_points: ", out.size(),
          " values for a grid of ", grid.total_cells(), " cells (ghosts included)");
  constexpr double far = 1e30;
  const index_t g = ghosts ? rectilinear_grid::ghosts : 0;  // cells −g … n − 1 + g
  for (index_t k = -g; k < grid.n(2) + g; ++k)
    for (index_t j = -g; j < grid.n(1) + g; ++j) {
      double* row = out.data() + grid.index(-g, j, k);
      std::fill(row, row + grid.n(0) + 2 * g, far);
    }
  for (const Eigen::Vector3d& p : points) {
    require(p.allFinite(), "fluid::distance_to_points: a point is not finite");
    index_t lo[3], hi[3];
    for (int d = 0; d < 3; ++d) {
      const double* c = grid.centres(d) - g;
      const index_t n = grid.n(d) + 2 * g;
      lo[d] = index_t(std::lower_bound(c, c + n, p[d] - reach) - c) - g;
      hi[d] = index_t(std::upper_bound(c, c + n, p[d] + reach) - c) - g;
    }
    const double r2 = reach * reach;
    for (index_t k = lo[2]; k < hi[2]; ++k) {
      const double dz = grid.centre(2, k) - p[2];
      for (index_t j = lo[1]; j < hi[1]; ++j) {
        const double dy = grid.centre(1, j) - p[1];
        const double dyz = dy * dy + dz * dz;
        if (dyz > r2) continue;
        double* row = out.data() + grid.index(0, j, k);
        for (index_t i = lo[0]; i < hi[0]; ++i) {
          const double dx = grid.centre(0, i) - p[0];
          const double q = dx * dx + dyz;
          if (q <= r2) row[i] = std::min(row[i], std::sqrt(q));
        }
      }
    }
  }
}

}  // namespace parafsi::fluid
