/// \file layout.hpp
/// Where the blocks of a block mesh lie: the box [lo, hi] (box coordinates), the root grid
/// of blocks and the cells per block edge n; the width of a level's blocks and cells, and
/// the leaf cell holding a point (the search the solver's locate() and the couplings'
/// stencils share).
#pragma once
#include <array>
#include <cmath>
#include <cstdint>

#include <Eigen/Core>

#include "../../core/error.hpp"
#include "exchange.hpp"
#include "tree.hpp"

namespace parafsi::fluid {

/// The box and its blocks: [lo, hi] in box coordinates, the root grid of blocks, n cells
/// per block edge.
struct block_layout {
  std::array<double, 3> lo{0, 0, 0}, hi{1, 1, 1};
  std::array<index_t, 3> root_blocks{1, 1, 1};
  index_t block_cells = 16;

  void validate() const {
    for (int d = 0; d < 3; ++d)
      require(hi[std::size_t(d)] > lo[std::size_t(d)] && std::isfinite(lo[std::size_t(d)]) &&
                  std::isfinite(hi[std::size_t(d)]),
              "block_layout: need finite lo < hi on axis ", d);
    blocks::check_block_size(block_cells);
  }
  /// Width of a block of level L along axis d.
  double block_width(int d, int level) const noexcept {
    return (hi[std::size_t(d)] - lo[std::size_t(d)]) / double(root_blocks[std::size_t(d)] << level);
  }
  /// Width of a cell of level L along axis d.
  double cell_width(int d, int level) const noexcept { return block_width(d, level) / double(block_cells); }
};

namespace blocks {

/// A leaf cell: its block (tree id, −1 if none), level and cell (i, j, k) in the block.
struct cell_address {
  index_t block = -1;
  int level = 0;
  std::array<index_t, 3> ijk{};
};

/// The leaf cell holding ξ (box coordinates); block −1 outside the box.
inline cell_address find_cell(const tree& t, const block_layout& lay, const Eigen::Vector3d& xi) {
  const int top = t.finest_level();
  std::array<std::int64_t, 3> l{};
  for (int d = 0; d < 3; ++d) {
    const double u = (xi[d] - lay.lo[std::size_t(d)]) / lay.block_width(d, top);
    if (!(u >= 0.0 && u < double(t.extent(d, top)))) return {};
    l[std::size_t(d)] = std::int64_t(std::floor(u));
  }
  const cover c = t.find({top, l});
  if (c.kind != cover::leaf) return {};
  const location& q = t.leaf(c.id);
  cell_address a{c.id, q.level, {}};
  const index_t n = lay.block_cells;
  for (int d = 0; d < 3; ++d) {
    const double lo = lay.lo[std::size_t(d)] + lay.block_width(d, q.level) * double(q.l[std::size_t(d)]);
    a.ijk[std::size_t(d)] = std::clamp<index_t>(index_t(std::floor((xi[d] - lo) / lay.cell_width(d, q.level))), 0,
                                                n - 1);
  }
  return a;
}

}  // namespace blocks
}  // namespace parafsi::fluid
