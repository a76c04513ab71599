/// \file tree.hpp
/// The octree of a block-structured fluid mesh: the box is split into a root grid of
/// nb_x × nb_y × nb_z blocks (level 0); a block of level L at logical position
/// l = (l_x, l_y, l_z) splits into the 8 children (2 l + o, L + 1), o ∈ {0, 1}³. Only the
/// leaves carry cells. The tree is kept fully 2:1 balanced: two leaves that touch across
/// a face, an edge or a corner differ by at most one level, so every ghost layer and every
/// coarse–fine face spans exactly one level (faces alone would do for the inviscid fluxes;
/// edges and corners keep the prolongation stencils and the viscous cross terms on one
/// level too).
///
/// Leaves are ordered along the Morton (Z-order) curve of their lower corner at the
/// finest level, so the order is independent of how the tree was built (the same set of
/// leaves always gives the same block ids) and neighbouring blocks are close in memory.
///
/// References: Stout Q.F. et al. (1997) "Adaptive blocks", Proc. ACM/IEEE SC97;
///   Burstedde C., Wilcox L.C., Ghattas O. (2011) SIAM J. Sci. Comput. 33:1103 (p4est:
///   2:1 balance, Morton order); Stone J.M. et al. (2020) ApJS 249:4 (Athena++ MeshBlocks).
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <unordered_map>
#include <vector>

#include "../../core/config.hpp"
#include "../../core/error.hpp"

namespace parafsi::fluid::blocks {

/// Logical location of a block: its level and its block coordinates at that level.
struct location {
  int level = 0;
  std::array<std::int64_t, 3> l{};

  friend bool operator==(const location&, const location&) = default;
  location parent() const noexcept { return {level - 1, {l[0] >> 1, l[1] >> 1, l[2] >> 1}}; }
  /// Child c ∈ [0, 8): offset (c & 1, (c >> 1) & 1, (c >> 2) & 1).
  location child(int c) const noexcept {
    return {level + 1, {2 * l[0] + (c & 1), 2 * l[1] + ((c >> 1) & 1), 2 * l[2] + ((c >> 2) & 1)}};
  }
};

/// What covers a block-sized region at a given level (tree::find).
struct cover {
  enum kind_t { outside, leaf, finer } kind = outside;
  index_t id = -1;  ///< the leaf (kind == leaf), whose level is ≤ the asked level
  int level = 0;    ///< that leaf's level
};

class tree {
 public:
  static constexpr int max_depth = 12;      ///< levels above the root grid
  static constexpr index_t max_root = 128;  ///< root blocks per axis (keys: 19 bits per coordinate)

  tree() = default;
  /// A root grid of nb blocks (one level, every block a leaf); `periodic` wraps an axis.
  tree(std::array<index_t, 3> nb, std::array<bool, 3> periodic = {false, false, false}) : nb_(nb), periodic_(periodic) {
    for (int d = 0; d < 3; ++d)
      require(nb[std::size_t(d)] >= 1 && nb[std::size_t(d)] <= max_root,
              "blocks::tree: root blocks per axis must be in [1, 128], got ", nb[std::size_t(d)], " on axis ", d);
    for (index_t k = 0; k < nb[2]; ++k)
      for (index_t j = 0; j < nb[1]; ++j)
        for (index_t i = 0; i < nb[0]; ++i) leaves_.emplace(key({0, {i, j, k}}), location{0, {i, j, k}});
    order();
  }

  /// A tree from its leaves (a checkpoint): they must lie in the box, not overlap and
  /// fill it; balance is checked where the exchange plan is built.
  static tree from_leaves(std::array<index_t, 3> nb, std::array<bool, 3> periodic,
                          const std::vector<location>& leaves) {
    tree t(nb, periodic);
    t.leaves_.clear();
    double volume = 0.0;
    for (const auto& q : leaves) {
      require(q.level >= 0 && q.level <= max_depth, "blocks::tree::from_leaves: level ", q.level, " out of range");
      for (int d = 0; d < 3; ++d)
        require(q.l[std::size_t(d)] >= 0 && q.l[std::size_t(d)] < t.extent(d, q.level),
                "blocks::tree::from_leaves: "
                "level ",
                q.level, " block (", q.l[0], ", ", q.l[1], ", ", q.l[2], ") lies outside the box");
      require(t.leaves_.emplace(key(q), q).second, "blocks::tree::from_leaves: block (", q.l[0], ", ", q.l[1], ", ",
              q.l[2], ") of level ", q.level, " is listed twice");
      volume += std::ldexp(1.0, -3 * q.level);
    }
    for (const auto& q : leaves)
      for (location p = q; p.level > 0;) {
        p = p.parent();
        require(!t.leaves_.count(key(p)), "blocks::tree::from_leaves: level ", q.level, " block (", q.l[0], ", ",
                q.l[1], ", ", q.l[2], ") lies inside another leaf");
      }
    require(volume == double(nb[0] * nb[1] * nb[2]), "blocks::tree::from_leaves: the leaves fill ", volume,
            " root blocks of ", nb[0] * nb[1] * nb[2]);
    t.order();
    return t;
  }

  index_t size() const noexcept { return index_t(order_.size()); }
  const location& leaf(index_t id) const noexcept { return order_[std::size_t(id)]; }
  const std::vector<location>& leaves() const noexcept { return order_; }
  std::array<index_t, 3> root_blocks() const noexcept { return nb_; }
  bool periodic(int d) const noexcept { return periodic_[std::size_t(d)]; }
  int finest_level() const noexcept { return finest_; }
  /// Blocks per axis at level L.
  index_t extent(int d, int level) const noexcept { return nb_[std::size_t(d)] << level; }
  bool is_leaf(const location& q) const { return leaves_.count(key(q)) != 0; }
  /// Leaf id of a leaf location (−1 if it is not a leaf).
  index_t id_of(const location& q) const {
    const auto it = ids_.find(key(q));
    return it == ids_.end() ? -1 : it->second;
  }

  /// Wrap a location's coordinates on periodic axes; false if it lies outside the box.
  bool wrap(location& q) const noexcept {
    for (int d = 0; d < 3; ++d) {
      const std::int64_t n = extent(d, q.level);
      auto& c = q.l[std::size_t(d)];
      if (c >= 0 && c < n) continue;
      if (!periodic_[std::size_t(d)]) return false;
      c = ((c % n) + n) % n;
    }
    return true;
  }

  /// What covers the block-sized region q: a leaf at q's level or coarser, finer leaves,
  /// or nothing (outside a non-periodic box).
  cover find(location q) const {
    if (!wrap(q)) return {};
    for (location p = q;; p = p.parent()) {
      if (const auto it = ids_.find(key(p)); it != ids_.end()) return {cover::leaf, it->second, p.level};
      if (p.level == 0) break;
    }
    return {cover::finer, -1, q.level + 1};
  }

  /// Split leaf q into its 8 children, first splitting every coarser leaf that touches it
  /// (across a face, edge or corner) so the tree stays 2:1 balanced. Ids change: call
  /// leaves() again afterwards.
  void refine(const location& q) {
    require(is_leaf(q), "blocks::tree::refine: level ", q.level, " block (", q.l[0], ", ", q.l[1], ", ", q.l[2],
            ") is not a leaf");
    require(q.level < max_depth, "blocks::tree::refine: more than ", max_depth, " levels");
    split_balanced(q);
    order();
  }

  /// Refine every leaf below `max_level` for which `want(location)` holds, level by level,
  /// until none is left; returns the number of splits (balance splits included).
  index_t refine_where(int max_level, const std::function<bool(const location&)>& want) {
    require(max_level >= 0 && max_level <= max_depth, "blocks::tree::refine_where: max_level must be in [0, ",
            max_depth, "], got ", max_level);
    index_t splits = 0;
    for (bool changed = true; changed;) {
      changed = false;
      const std::vector<location> now = order_;
      for (const auto& q : now)
        if (q.level < max_level && is_leaf(q) && want(q)) {
          splits += split_balanced(q);
          changed = true;
        }
      order();
    }
    return splits;
  }

  /// Merge the 8 children of `parent` (all leaves) back into it, if no leaf touching the
  /// parent is finer than the children (balance would break otherwise). Returns whether
  /// it merged.
  bool coarsen(const location& parent) {
    for (int c = 0; c < 8; ++c)
      if (!is_leaf(parent.child(c))) return false;
    // Every region of the children's size touching the parent must be covered by a leaf
    // no finer than the children.
    const location c0 = parent.child(0);
    for (int dz = -1; dz <= 2; ++dz)
      for (int dy = -1; dy <= 2; ++dy)
        for (int dx = -1; dx <= 2; ++dx) {
          if (dx >= 0 && dx <= 1 && dy >= 0 && dy <= 1 && dz >= 0 && dz <= 1) continue;
          if (find({c0.level, {c0.l[0] + dx, c0.l[1] + dy, c0.l[2] + dz}}).kind == cover::finer) return false;
        }
    for (int c = 0; c < 8; ++c) leaves_.erase(key(parent.child(c)));
    leaves_.emplace(key(parent), parent);
    order();
    return true;
  }

  /// Morton key of a location's lower corner at the deepest level (the leaf order).
  static std::uint64_t morton(const location& q) noexcept {
    std::uint64_t m = 0;
    const int shift = max_depth - q.level;
    for (int b = 0; b < 21; ++b)
      for (int d = 0; d < 3; ++d) {
        const std::uint64_t c = std::uint64_t(q.l[std::size_t(d)]) << shift;
        m |= ((c >> b) & 1u) << (3 * b + d);
      }
    return m;
  }

  /// A location's key (level and coordinates; unique below max_depth and max_root).
  static std::uint64_t key(const location& q) noexcept {
    return (std::uint64_t(q.level) << 59) | (std::uint64_t(q.l[2]) << 38) | (std::uint64_t(q.l[1]) << 19) |
           std::uint64_t(q.l[0]);
  }

 private:
  /// Split q after splitting every coarser touching leaf (recursively); returns splits.
  index_t split_balanced(const location& q) {
    index_t splits = 0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          location n{q.level, {q.l[0] + dx, q.l[1] + dy, q.l[2] + dz}};
          if (!wrap(n)) continue;
          for (;;) {  // a coarser leaf covering n: split it, then look again
            location p = n;
            bool found = false;
            while (p.level > 0 && !found) {
              p = p.parent();
              found = leaves_.count(key(p)) != 0;
            }
            if (!found || p.level >= q.level) break;
            splits += split_balanced(p);
          }
        }
    leaves_.erase(key(q));
    for (int c = 0; c < 8; ++c) leaves_.emplace(key(q.child(c)), q.child(c));
    ids_.clear();  // stale until order()
    return splits + 1;
  }

  void order() {
    order_.clear();
    order_.reserve(leaves_.size());
    for (const auto& kv : leaves_) order_.push_back(kv.second);
    std::sort(order_.begin(), order_.end(), [](const location& a, const location& b) {
      const auto ma = morton(a), mb = morton(b);
      return ma != mb ? ma < mb : a.level < b.level;
    });
    ids_.clear();
    finest_ = 0;
    for (std::size_t i = 0; i < order_.size(); ++i) {
      ids_.emplace(key(order_[i]), index_t(i));
      finest_ = std::max(finest_, order_[i].level);
    }
  }

  std::array<index_t, 3> nb_{1, 1, 1};
  std::array<bool, 3> periodic_{};
  std::unordered_map<std::uint64_t, location> leaves_;
  std::unordered_map<std::uint64_t, index_t> ids_;
  std::vector<location> order_;
  int finest_ = 0;
};

}  // namespace parafsi::fluid::blocks
