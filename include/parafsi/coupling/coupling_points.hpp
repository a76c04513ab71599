/// \file coupling_points.hpp
/// Coupling points on membrane triangles and their location in the moving
/// rectilinear fluid grid (methods §4.1–4.2).
///
/// Points. A triangle with longest edge L in a cell of size h gets NQUAD² points,
///   NQUAD = clamp(ceil(points_per_cell · L / h), 1, max_nquad),  points_per_cell ≥ 2,
/// at the centroids of the NQUAD² congruent sub-triangles (upward sub-triangle (i, j):
/// parametric centroid ((i + ⅓)/n, (j + ⅓)/n), i + j ≤ n − 1; downward: ((i + ⅔)/n,
/// (j + ⅔)/n), i + j ≤ n − 2), so the point spacing is ≤ h/points_per_cell in every
/// in-plane direction. Each point stores its element, its shape weights
/// (N0, N1, N2) = (1 − a − b, a, b) and a signed penetration d; its tributary area
/// A_c = A_e/NQUAD² and unit normal n_e = (x1 − x0) × (x2 − x0)/|…| follow the current
/// geometry. Points of one element are contiguous (element e owns
/// [first(e), first(e + 1))).
///
/// Location. ξ = Rᵀ(x − X) in box coordinates; per axis the stencil index
/// i0 = the cell whose centre is the last one ≤ ξ_d — O(1) on a uniform axis
/// (i0 = floor((ξ_d − x_c,0)/h)), a binary search over the centres otherwise
/// (O(log n), n ≤ a few hundred) — and t_d = (ξ_d − x_c,i0)/(x_c,i0+1 − x_c,i0).
/// Trilinear weights over the 8 cell centres, w = Π_d (t_d or 1 − t_d). Near a box
/// face the stencil is clamped to interior cells (t = 0 below the first centre,
/// t = 1 past the last): the weights still sum to one, every weight lands on an
/// interior cell (so nothing spread to the fluid is lost in a ghost cell), and the
/// field is extrapolated as a constant over the outer half cell. Points outside the
/// box are inactive. The same weights interpolate (v_f = Σ w u_cell) and spread
/// (J_cell = w J), so Σ_cells J_cell = J to round-off and Σ w F·u_cell = F·v_f.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "../fluid/frame/pose.hpp"
#include "../fluid/grid.hpp"

namespace parafsi::coupling {

/// Eight-cell trilinear stencil of one point.
struct stencil {
  index_t base = 0;               ///< linear index of the (i0, j0, k0) corner cell
  std::array<index_t, 3> ijk{};   ///< i0, j0, k0
  std::array<double, 3> t{};      ///< fractions along each axis
  std::array<index_t, 8> cell{};  ///< the fluid cell of corner a (flat index of the fluid's arrays)
  double h = 0;                   ///< local cell size (cube root of the containing cell's volume)
  double hmin = 0;                ///< smallest width of the containing cell
  bool inside = false;            ///< the point lies inside the box
  /// Weight of corner a (bit 0: +x, bit 1: +y, bit 2: +z).
  double weight(int a) const noexcept {
    return (a & 1 ? t[0] : 1.0 - t[0]) * (a & 2 ? t[1] : 1.0 - t[1]) * (a & 4 ? t[2] : 1.0 - t[2]);
  }
};

/// O(1) (uniform axes) or O(log n) location of box points in a rectilinear grid.
class grid_locator {
 public:
  grid_locator() = default;
  explicit grid_locator(const fluid::rectilinear_grid& g) : g_(&g) {
    for (int d = 0; d < 3; ++d) {
      const index_t n = g.n(d);
      const double h0 = g.width(d, 0);
      bool uni = true;
      for (index_t i = 0; i < n; ++i) uni = uni && std::fabs(g.width(d, i) - h0) <= 1e-12 * h0;
      uniform_[std::size_t(d)] = uni;
      inv_h_[std::size_t(d)] = 1.0 / h0;
    }
    for (int a = 0; a < 8; ++a)
      corner_[std::size_t(a)] = (a & 1 ? g.stride(0) : 0) + (a & 2 ? g.stride(1) : 0) + (a & 4 ? g.stride(2) : 0);
  }

  const fluid::rectilinear_grid& grid() const noexcept { return *g_; }
  double min_width() const noexcept { return g_->min_width(); }
  /// Linear offset of corner a from the stencil base.
  index_t corner(int a) const noexcept { return corner_[std::size_t(a)]; }

  /// Stencil of the box point ξ.
  stencil locate(const Eigen::Vector3d& xi) const {
    const auto& g = *g_;
    stencil s;
    s.inside = true;
    double vol = 1.0, hmin = 1e300;
    for (int d = 0; d < 3; ++d) {
      const index_t n = g.n(d);
      const double x = xi[d];
      if (!(x >= g.face(d, 0) && x <= g.face(d, n))) s.inside = false;
      const double* xc = g.centres(d);
      index_t i0;
      if (uniform_[std::size_t(d)]) {
        const double q = std::floor((x - xc[0]) * inv_h_[std::size_t(d)]);
        i0 = q < -1.0 ? -1 : (q > double(n) ? n : index_t(q));
      } else {
        i0 = index_t(std::upper_bound(xc, xc + n, x) - xc) - 1;  // last centre <= x
      }
      double t;
      if (n == 1) {
        i0 = 0;
        t = 0.0;
      } else if (i0 < 0) {
        i0 = 0;
        t = 0.0;
      } else if (i0 >= n - 1) {
        i0 = n - 2;
        t = 1.0;
      } else {
        t = (x - xc[i0]) / (xc[i0 + 1] - xc[i0]);
        t = std::clamp(t, 0.0, 1.0);
      }
      s.ijk[std::size_t(d)] = i0;
      s.t[std::size_t(d)] = t;
      // Containing cell for the local size.
      index_t ic = std::clamp<index_t>(i0 + (t >= 0.5 ? 1 : 0), 0, n - 1);
      if (n == 1) ic = 0;
      vol *= g.width(d, ic);
      if (n > 1) hmin = std::min(hmin, g.width(d, ic));
    }
    s.base = g.index(s.ijk[0], s.ijk[1], s.ijk[2]);
    for (int a = 0; a < 8; ++a) s.cell[std::size_t(a)] = s.base + corner_[std::size_t(a)];
    s.h = std::cbrt(vol);
    s.hmin = hmin < 1e300 ? hmin : g.min_width();
    return s;
  }

 private:
  const fluid::rectilinear_grid* g_ = nullptr;
  std::array<bool, 3> uniform_{};
  std::array<double, 3> inv_h_{};
  std::array<index_t, 8> corner_{};
};

struct point_options {
  int points_per_cell = 2;  ///< ≥ 2 points per fluid cell in each in-plane direction
  int max_nquad = 32;       ///< cap on NQUAD per element
  void validate() const {
    require(points_per_cell >= 2, "coupling::point_options: points_per_cell must be >= 2 (density rule), got ",
            points_per_cell);
    require(max_nquad >= 1 && max_nquad <= 256, "coupling::point_options: max_nquad must be in [1, 256], got ",
            max_nquad);
  }
};

/// Parametric coupling points of a set of triangles (SoA: element, weights).
class coupling_points {
 public:
  coupling_points() = default;

  /// Build NQUAD² points per triangle, NQUAD from the cell size at its centroid.
  /// `position(i)` gives node i's current position (inertial).
  /// `loc`: a locator (grid_locator, block_locator) with locate(ξ) and min_width().
  template <class Pos, class Locator>
  void build(const std::vector<std::array<index_t, 3>>& tris, Pos&& position, const Locator& loc,
             const frame::pose& pose, point_options opt = {}) {
    opt.validate();
    tris_ = tris;
    elem_.clear();
    w_[0].clear();
    w_[1].clear();
    w_[2].clear();
    first_.assign(1, 0);
    nquad_.clear();
    const double hmin = loc.min_width();
    for (std::size_t e = 0; e < tris_.size(); ++e) {
      const auto& t = tris_[e];
      const Eigen::Vector3d x0 = position(t[0]), x1 = position(t[1]), x2 = position(t[2]);
      const double L = std::sqrt(std::max({(x1 - x0).squaredNorm(), (x2 - x1).squaredNorm(), (x0 - x2).squaredNorm()}));
      const stencil s = loc.locate(pose.to_box((x0 + x1 + x2) / 3.0));
      const double h = s.inside ? std::min(s.h, s.hmin) : hmin;
      const int n = std::clamp(int(std::ceil(opt.points_per_cell * L / h - 1e-9)), 1, opt.max_nquad);
      nquad_.push_back(n);
      const double inv = 1.0 / n;
      auto push = [&](double a, double b) {
        elem_.push_back(index_t(e));
        w_[0].push_back(1.0 - a - b);
        w_[1].push_back(a);
        w_[2].push_back(b);
      };
      for (int j = 0; j < n; ++j)
        for (int i = 0; i + j <= n - 1; ++i) {
          push((i + 1.0 / 3.0) * inv, (j + 1.0 / 3.0) * inv);
          if (i + j <= n - 2) push((i + 2.0 / 3.0) * inv, (j + 2.0 / 3.0) * inv);
        }
      first_.push_back(index_t(elem_.size()));
    }
  }

  index_t size() const noexcept { return index_t(elem_.size()); }
  index_t elements() const noexcept { return index_t(tris_.size()); }
  index_t element(index_t c) const noexcept { return elem_[std::size_t(c)]; }
  index_t first(index_t e) const noexcept { return first_[std::size_t(e)]; }
  int nquad(index_t e) const noexcept { return nquad_[std::size_t(e)]; }
  const std::array<index_t, 3>& nodes_of(index_t e) const noexcept { return tris_[std::size_t(e)]; }
  double weight(index_t c, int a) const noexcept { return w_[std::size_t(a)][std::size_t(c)]; }
  const std::vector<std::array<index_t, 3>>& triangles() const noexcept { return tris_; }

 private:
  std::vector<std::array<index_t, 3>> tris_;
  std::vector<index_t> elem_, first_;
  std::vector<int> nquad_;
  std::array<std::vector<double>, 3> w_;
};

}  // namespace parafsi::coupling
