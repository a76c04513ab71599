/// \file refine.hpp
/// Refinement criteria for the block mesh: `target(location) → level` functions for
/// tree::refine_where and block_solver::regrid.
///
///   near_points{layout, points, buffer, level, graded}: `level` for every block whose box
///     comes within `buffer` (m, box coordinates) of one of the points; elsewhere 0, or with
///     `graded` the level ℓ < level within buffer · 2^(level − ℓ) (each coarser level twice
///     as far out), so a feature near the points (a canopy's near wake) keeps cells that
///     coarsen gradually; the 2:1 balance grades whatever remains. With the structure's nodes as points and a
///     buffer of at least the longest element edge plus the distance the structure can
///     travel between regrids plus two finest cells (the prolongation and MUSCL
///     stencils), every cell a membrane cuts, and its stencil, is on the finest level
///     until the next regrid.
///
/// Points are binned on a uniform grid of bins one buffer-plus-block wide, so a query
/// looks at the few bins the block's box (grown by the buffer) overlaps. A query first
/// tests the points' bounding box and each bin's, so a block far from every point (most
/// of a drop's box) is answered without a distance, and a bin beyond the radius without
/// its points (the answers are those of testing every point).
///
///   leaf_indicator{tree, values, refine_above, coarsen_below, max_level}: a flow criterion
///     from one value per leaf of the current tree (e.g. block_solver::vorticity_indicator,
///     max |ω| h over the leaf, in m/s): a block whose leaf's value exceeds `refine_above`
///     wants one level finer (up to max_level), one below `coarsen_below` one level coarser,
///     else its level; a regrid thus moves a level at a time and the gap between the two
///     thresholds keeps a refined block from coarsening at once (|ω| h halves when h does).
///   in_box{layout, lo, hi, level}: `level` on every block whose box overlaps the open box
///     (lo, hi) (box coordinates), 0 elsewhere; the 2:1 balance grades the rest. A fixed
///     region held fine: a bluff body's core and near wake, the tensor box's refined column.
///     Leaves come from splitting, so the fine region is the union of whole blocks of the
///     level above that meet the box (up to one such block wider than (lo, hi) on a side).
///   max_of{a, b}: the finer of two criteria's targets.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "../../core/error.hpp"
#include "tree.hpp"

namespace parafsi::fluid::blocks {

/// Axis-aligned box of a block in box coordinates.
struct block_box {
  std::array<double, 3> lo, hi;
};

template <class Layout>
block_box box_of(const Layout& lay, const location& q) {
  block_box b{};
  for (int d = 0; d < 3; ++d) {
    const double w = lay.block_width(d, q.level);
    b.lo[std::size_t(d)] = lay.lo[std::size_t(d)] + w * double(q.l[std::size_t(d)]);
    b.hi[std::size_t(d)] = b.lo[std::size_t(d)] + w;
  }
  return b;
}

/// Distance from a point to a box (0 inside).
inline double distance(const block_box& b, const Eigen::Vector3d& p) {
  double d2 = 0;
  for (int d = 0; d < 3; ++d) {
    const double e = std::max({b.lo[std::size_t(d)] - p[d], 0.0, p[d] - b.hi[std::size_t(d)]});
    d2 += e * e;
  }
  return std::sqrt(d2);
}

/// `level` near a set of points (box coordinates), 0 elsewhere.
template <class Layout>
class near_points {
 public:
  near_points(const Layout& lay, std::vector<Eigen::Vector3d> points, double buffer, int level, bool graded = false)
      : lay_(lay), pts_(std::move(points)), buffer_(buffer), level_(level), graded_(graded) {
    require(std::isfinite(buffer) && buffer >= 0, "blocks::near_points: buffer must be finite and >= 0, got ", buffer);
    require(level >= 0 && level <= tree::max_depth, "blocks::near_points: level must be in [0, ", tree::max_depth,
            "], got ", level);
    for (const auto& p : pts_) require(p.allFinite(), "blocks::near_points: a point is not finite");
    // Bins as wide as the buffer plus a root block's width / 2^level (≥ one finest block).
    for (int d = 0; d < 3; ++d) bin_ = std::max(bin_, lay.block_width(d, level));
    bin_ = std::max(bin_ + buffer_, 1e-12);
    for (std::size_t i = 0; i < pts_.size(); ++i) {
      bin& bn = bins_[key(bin_of(pts_[i]))];
      bn.points.push_back(i);
      grow(bn.bounds, pts_[i]);
      grow(all_, pts_[i]);
    }
  }

  int operator()(const location& q) const {
    const block_box b = box_of(lay_, q);
    if (near(b, buffer_)) return level_;
    if (graded_)
      for (int l = level_ - 1; l >= 1; --l)
        if (near(b, std::ldexp(buffer_, level_ - l))) return l;
    return 0;
  }

  /// Whether some point lies within distance r of the box.
  bool near(const block_box& b, double r) const {
    if (pts_.empty() || gap(b, all_) > r) return false;
    std::array<std::int64_t, 3> a{}, z{};
    for (int d = 0; d < 3; ++d) {
      a[std::size_t(d)] = std::int64_t(std::floor((b.lo[std::size_t(d)] - r) / bin_));
      z[std::size_t(d)] = std::int64_t(std::floor((b.hi[std::size_t(d)] + r) / bin_));
    }
    for (std::int64_t k = a[2]; k <= z[2]; ++k)
      for (std::int64_t j = a[1]; j <= z[1]; ++j)
        for (std::int64_t i = a[0]; i <= z[0]; ++i) {
          const auto it = bins_.find(key({i, j, k}));
          if (it == bins_.end() || gap(b, it->second.bounds) > r) continue;
          for (std::size_t p : it->second.points)
            if (distance(b, pts_[p]) <= r) return true;
        }
    return false;
  }

 private:
  std::array<std::int64_t, 3> bin_of(const Eigen::Vector3d& p) const {
    return {std::int64_t(std::floor(p[0] / bin_)), std::int64_t(std::floor(p[1] / bin_)),
            std::int64_t(std::floor(p[2] / bin_))};
  }
  /// Bin key (a hash: bins that collide share a list, which only costs distance checks).
  static std::uint64_t key(const std::array<std::int64_t, 3>& c) noexcept {
    return std::uint64_t(c[0]) * 0x9E3779B97F4A7C15ull ^ std::uint64_t(c[1]) * 0xC2B2AE3D27D4EB4Full ^
           std::uint64_t(c[2]) * 0x165667B19E3779F9ull;
  }

  /// The points of a bin and their bounding box.
  struct bin {
    std::vector<std::size_t> points;
    block_box bounds{{HUGE_VAL, HUGE_VAL, HUGE_VAL}, {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}};
  };
  static void grow(block_box& bb, const Eigen::Vector3d& p) {
    for (int d = 0; d < 3; ++d) {
      bb.lo[std::size_t(d)] = std::min(bb.lo[std::size_t(d)], p[d]);
      bb.hi[std::size_t(d)] = std::max(bb.hi[std::size_t(d)], p[d]);
    }
  }
  /// A lower bound of the distance from box b to any point inside box o: the gap between
  /// the two boxes (0 where they overlap), never more than a point's distance(b, p).
  static double gap(const block_box& b, const block_box& o) {
    double d2 = 0;
    for (int d = 0; d < 3; ++d) {
      const std::size_t u = std::size_t(d);
      const double e = std::max({o.lo[u] - b.hi[u], 0.0, b.lo[u] - o.hi[u]});
      d2 += e * e;
    }
    return std::sqrt(d2);
  }

  Layout lay_;
  std::vector<Eigen::Vector3d> pts_;
  double buffer_;
  int level_;
  bool graded_;
  double bin_ = 0;
  std::unordered_map<std::uint64_t, bin> bins_;
  block_box all_{{HUGE_VAL, HUGE_VAL, HUGE_VAL}, {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}};
};

/// `level` on the blocks that overlap the open box (lo, hi), 0 elsewhere (see the file comment).
template <class Layout>
struct in_box {
  Layout lay;
  std::array<double, 3> lo, hi;
  int level;

  int operator()(const location& q) const {
    const block_box b = box_of(lay, q);
    // A block that only touches the box (a shared face, to round-off) is outside it.
    for (std::size_t d = 0; d < 3; ++d) {
      const double tol = 1e-12 * (std::fabs(lo[d]) + std::fabs(hi[d]) + (hi[d] - lo[d]));
      if (b.hi[d] <= lo[d] + tol || b.lo[d] >= hi[d] - tol) return 0;
    }
    return level;
  }
};
template <class Layout>
in_box(Layout, std::array<double, 3>, std::array<double, 3>, int) -> in_box<Layout>;

/// A flow criterion from one value per leaf of the current tree (see the file comment).
class leaf_indicator {
 public:
  leaf_indicator(const tree& t, std::vector<double> values, double refine_above, double coarsen_below, int max_level)
      : tree_(&t), values_(std::move(values)), hi_(refine_above), lo_(coarsen_below), max_level_(max_level) {
    require(values_.size() == std::size_t(t.size()), "blocks::leaf_indicator: ", values_.size(), " values for ",
            t.size(), " leaves");
    require(std::isfinite(refine_above) && std::isfinite(coarsen_below) && coarsen_below >= 0 &&
                coarsen_below < refine_above,
            "blocks::leaf_indicator: need finite thresholds 0 <= coarsen_below < refine_above, got ", coarsen_below,
            " and ", refine_above);
    require(max_level >= 0 && max_level <= tree::max_depth, "blocks::leaf_indicator: max_level must be in [0, ",
            tree::max_depth, "], got ", max_level);
  }

  int operator()(const location& q) const {
    const cover c = tree_->find(q);
    if (c.kind != cover::leaf) return q.level;  // outside, or coarser than today's leaves: keep
    const double v = values_[std::size_t(c.id)];
    if (v > hi_) return std::min(c.level + 1, max_level_);
    if (v < lo_) return std::max(c.level - 1, 0);
    return c.level;
  }

 private:
  const tree* tree_;
  std::vector<double> values_;
  double hi_, lo_;
  int max_level_;
};

/// The finer of two criteria's targets.
template <class A, class B>
struct max_of {
  A a;
  B b;
  int operator()(const location& q) const { return std::max(int(a(q)), int(b(q))); }
};
template <class A, class B>
max_of(A, B) -> max_of<A, B>;

}  // namespace parafsi::fluid::blocks
