/// \file exchange.hpp
/// Ghost cells of the blocks of a block mesh from their neighbours, as a plan built once
/// per mesh (tree) and executed every stage. The plan fills the ghost slabs of the six
/// faces (ghost along one axis, interior along the other two), which is all that the flux
/// sweeps and the regrid's prolongation slopes read (one axis at a time); the edge and
/// corner ghosts (outside along two or three axes) are left as they are. A face ghost
/// cell of a block of level L whose centre lies in the box is covered by exactly one of
///   - a leaf of level L: copied;
///   - leaves of level L + 1: the volume mean of the 8 fine cells it holds (restriction);
///   - a leaf of level L − 1: the coarse cell's conserved state plus limited slopes
///       U = U_c + Σ_d δ_d s_d,  s_d = minmod(U_c − U_{c−e_d}, U_{c+e_d} − U_c),  δ_d = ±¼
///     (prolongation; δ_d the fine centre's offset in coarse widths). A slope stencil cell
///     outside the box or on a coarser level counts as a zero one-sided difference; a
///     stencil cell covered by finer cells is their mean. If the result is not a gas
///     (ρ ≤ 0 or p ≤ 0) the ghost takes U_c.
/// The ghost cells one coarse cell covers share its slopes, computed once per group.
/// Copies run as boxes of cells (block_plan::copy_box): the per-cell items merged where
/// destination and source are both contiguous, along x, then y, then z (a face slab of
/// n × n × 2 cells is one box), so the exchange is a few contiguous loops per field.
/// Every item reads interior cells only, so the blocks can be filled in any order and in
/// parallel; ghost cells outside the box are left to the boundary conditions, applied
/// afterwards (detail/ghosts.hpp with the block's boundary faces). On periodic axes the
/// neighbour search wraps. The 2:1 balance of the tree (tree.hpp) guarantees one level of
/// difference across every ghost layer; the plan checks it across faces.
///
/// The children's mean of a prolonged coarse cell equals it (the offsets cancel), so the
/// same operator is conservative when a regrid splits a block.
///
/// References: Berger M.J., Colella P. (1989) J. Comput. Phys. 82:64;
///   Stone J.M. et al. (2020) ApJS 249:4 (Athena++: restriction, limited prolongation).
#pragma once
#include <array>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "../../core/error.hpp"
#include "../detail/stage.hpp"
#include "../gas.hpp"
#include "../grid.hpp"
#include "tree.hpp"

namespace parafsi::fluid::blocks {

/// One value on a level: a leaf's cell, or the mean of the 2×2×2 cells of a finer leaf
/// starting at `cell` (restricted); block −1: none (zero slope).
struct value_ref {
  index_t block = -1;
  index_t cell = 0;
  bool restricted = false;
};

/// The exchange items of one destination block.
struct block_plan {
  struct copy_item {
    index_t dst, src_block, src;
  };
  /// The ghost cells of this block that one coarse cell covers (up to its 8 children):
  /// the coarse cell's slopes are computed once for all of them.
  struct prolong_group {
    value_ref centre;
    std::array<value_ref, 6> side;  ///< −x, +x, −y, +y, −z, +z neighbours of the coarse cell
    int count = 0;                  ///< children filled from it
    std::array<index_t, 8> dst{};
    std::array<std::array<double, 3>, 8> offset{};  ///< δ_d = ±¼ of each child
  };
  /// Cells dst + a + b s_y + c s_z ← src + a + b s_y + c s_z (a < extent[0], b < extent[1],
  /// c < extent[2]; s_y, s_z the strides of a block) from a leaf of the same level.
  struct copy_box {
    index_t dst, src_block, src;
    std::array<index_t, 3> extent;
  };
  std::vector<copy_box> copies;
  std::vector<copy_item> restrictions;  ///< src: the lowest fine cell of the 2×2×2 group
  std::vector<prolong_group> prolongations;
};

/// Cells per block edge n (even, ≥ 4: two ghost layers of a fine block lie in one coarse
/// cell layer of its neighbour, and the 8 children of a coarse cell lie in one block).
inline void check_block_size(index_t n) {
  require(n >= 4 && n % 2 == 0 && n <= 256, "blocks: cells per block edge must be even and in [4, 256], got ", n);
}

/// Local flat index of cell (i, j, k) of a block of n³ cells with 2 ghost layers.
struct block_index {
  index_t n;
  index_t operator()(index_t i, index_t j, index_t k) const noexcept {
    constexpr index_t g = rectilinear_grid::ghosts;
    const index_t s = n + 2 * g;
    return (i + g) + s * ((j + g) + s * (k + g));
  }
};

/// Merge per-cell copy items (in increasing dst order) into boxes: runs of consecutive
/// cells first, then runs of equal length stacked along y (stride sy) into planes, then
/// planes stacked along z (stride sz). Each box copies exactly the cells of its items.
inline std::vector<block_plan::copy_box> merge_copies(const std::vector<block_plan::copy_item>& items, index_t sy,
                                                      index_t sz) {
  using box = block_plan::copy_box;
  std::vector<box> runs;
  for (const auto& it : items) {
    if (!runs.empty()) {
      box& r = runs.back();
      if (r.src_block == it.src_block && r.dst + r.extent[0] == it.dst && r.src + r.extent[0] == it.src) {
        ++r.extent[0];
        continue;
      }
    }
    runs.push_back({it.dst, it.src_block, it.src, {1, 1, 1}});
  }
  // Stack boxes along axis d (stride st): a box extends the first earlier box it continues.
  auto stack = [](const std::vector<box>& in, int d, index_t st) {
    std::vector<box> out;
    for (const auto& b : in) {
      bool merged = false;
      for (auto& o : out) {
        const index_t step = o.extent[std::size_t(d)] * st;
        bool same = o.src_block == b.src_block && o.dst + step == b.dst && o.src + step == b.src;
        for (int e = 0; e < 3; ++e)
          if (e != d) same = same && o.extent[std::size_t(e)] == b.extent[std::size_t(e)];
        if (same) {
          o.extent[std::size_t(d)] += b.extent[std::size_t(d)];
          merged = true;
          break;
        }
      }
      if (!merged) out.push_back(b);
    }
    return out;
  };
  return stack(stack(runs, 1, sy), 2, sz);
}

/// Build every block's plan for the leaves of `t` with n cells per block edge.
/// With `edges`, also the edge ghosts one cell deep on both axes they lie outside along
/// (i, j ∈ {−1, n} for an x-parallel edge): the tangential central differences of the
/// first face-ghost layer read them, which a viscous pass needs for the fluxes of a
/// block's boundary faces and for μ_t on that layer. Nothing that enters a face flux
/// reads a corner ghost or the outer edge cells (depth 2 on an axis), so they are not
/// filled (a plan for them would grow the exchange from 864 to 1216 cells per 8³ block).
/// The tree's balance across edges covers the edge ghosts.
inline std::vector<block_plan> build_plan(const tree& t, index_t n, bool edges = false) {
  check_block_size(n);
  constexpr index_t g = rectilinear_grid::ghosts;
  const block_index at{n};
  auto floor_div = [](std::int64_t a, std::int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); };
  // Wrap a global cell index G at level L; false if outside the box.
  auto wrap_cell = [&](std::array<std::int64_t, 3>& G, int L) {
    for (int d = 0; d < 3; ++d) {
      const std::int64_t N = t.extent(d, L) * n;
      auto& c = G[std::size_t(d)];
      if (c >= 0 && c < N) continue;
      if (!t.periodic(d)) return false;
      c = ((c % N) + N) % N;
    }
    return true;
  };
  auto block_of = [&](const std::array<std::int64_t, 3>& G, int L) {
    return location{L, {floor_div(G[0], n), floor_div(G[1], n), floor_div(G[2], n)}};
  };
  auto local = [&](const std::array<std::int64_t, 3>& G, const location& b) {
    return at(G[0] - b.l[0] * n, G[1] - b.l[1] * n, G[2] - b.l[2] * n);
  };
  // The value of cell G at level L for a prolongation stencil.
  auto value_at = [&](std::array<std::int64_t, 3> G, int L) -> value_ref {
    if (!wrap_cell(G, L)) return {};
    const cover c = t.find(block_of(G, L));
    if (c.kind == cover::leaf && c.level == L) return {c.id, local(G, t.leaf(c.id)), false};
    if (c.kind == cover::finer) {
      const std::array<std::int64_t, 3> F{2 * G[0], 2 * G[1], 2 * G[2]};
      const cover f = t.find(block_of(F, L + 1));
      if (f.kind == cover::leaf && f.level == L + 1) return {f.id, local(F, t.leaf(f.id)), true};
    }
    return {};  // coarser (or deeper than one level): zero slope on that side
  };

  std::vector<block_plan> plans(std::size_t(t.size()));
  std::vector<block_plan::copy_item> copies;
  std::map<std::pair<index_t, index_t>, std::size_t> group_of;  // coarse (block, cell) → group
  for (index_t b = 0; b < t.size(); ++b) {
    const location q = t.leaf(b);
    const int L = q.level;
    block_plan& p = plans[std::size_t(b)];
    copies.clear();
    group_of.clear();
    for (index_t k = -g; k < n + g; ++k)
      for (index_t j = -g; j < n + g; ++j)
        for (index_t i = -g; i < n + g; ++i) {
          const int outside = int(i < 0 || i >= n) + int(j < 0 || j >= n) + int(k < 0 || k >= n);
          if (outside == 0 || (outside > 1 && !edges) || outside == 3) continue;  // interior, edge, corner
          if (outside == 2 && (i < -1 || i > n || j < -1 || j > n || k < -1 || k > n)) continue;  // outer edge
          std::array<std::int64_t, 3> G{q.l[0] * n + i, q.l[1] * n + j, q.l[2] * n + k};
          if (!wrap_cell(G, L)) continue;  // outside the box: boundary condition
          const index_t dst = at(i, j, k);
          const cover c = t.find(block_of(G, L));
          if (c.kind == cover::leaf && c.level == L) {
            copies.push_back({dst, c.id, local(G, t.leaf(c.id))});
          } else if (c.kind == cover::finer) {
            const std::array<std::int64_t, 3> F{2 * G[0], 2 * G[1], 2 * G[2]};
            const cover f = t.find(block_of(F, L + 1));
            require(f.kind == cover::leaf && f.level == L + 1,
                    "blocks::build_plan: the tree is not 2:1 balanced near "
                    "level ",
                    L, " block (", q.l[0], ", ", q.l[1], ", ", q.l[2], ")");
            p.restrictions.push_back({dst, f.id, local(F, t.leaf(f.id))});
          } else {
            require(c.kind == cover::leaf && c.level == L - 1,
                    "blocks::build_plan: the tree is not 2:1 balanced near "
                    "level ",
                    L, " block (", q.l[0], ", ", q.l[1], ", ", q.l[2], ")");
            const std::array<std::int64_t, 3> C{floor_div(G[0], 2), floor_div(G[1], 2), floor_div(G[2], 2)};
            const value_ref centre{c.id, local(C, t.leaf(c.id)), false};
            const auto [slot, fresh] = group_of.try_emplace({centre.block, centre.cell}, p.prolongations.size());
            if (fresh) {
              block_plan::prolong_group grp;
              grp.centre = centre;
              for (int d = 0; d < 3; ++d)
                for (int s = 0; s < 2; ++s) {
                  auto Cn = C;
                  Cn[std::size_t(d)] += s ? 1 : -1;
                  grp.side[std::size_t(2 * d + s)] = value_at(Cn, L - 1);
                }
              p.prolongations.push_back(grp);
            }
            block_plan::prolong_group& grp = p.prolongations[slot->second];
            const int k8 = grp.count++;
            grp.dst[std::size_t(k8)] = dst;
            for (int d = 0; d < 3; ++d)
              grp.offset[std::size_t(k8)][std::size_t(d)] = (G[std::size_t(d)] - 2 * C[std::size_t(d)]) == 0 ? -0.25
                                                                                                             : 0.25;
          }
        }
    p.copies = merge_copies(copies, n + 2 * g, (n + 2 * g) * (n + 2 * g));
  }
  return plans;
}

/// Conserved-variable arrays of every block (the exchange reads and writes through them).
using block_fields = std::vector<detail::fields5<double>>;

PARAFSI_INLINE double restrict8(const double* u, index_t c, index_t sy, index_t sz) noexcept {
  return 0.125 * (((u[c] + u[c + 1]) + (u[c + sy] + u[c + sy + 1])) +
                  ((u[c + sz] + u[c + sz + 1]) + (u[c + sz + sy] + u[c + sz + sy + 1])));
}

/// Fill the ghosts of block b from its plan (reads other blocks' interior cells only).
inline void execute_plan(const block_plan& p, index_t b, const block_fields& U, index_t n, const gas::ideal& gas) {
  constexpr index_t g = rectilinear_grid::ghosts;
  const index_t sy = n + 2 * g, sz = sy * sy;
  const auto& dst = U[std::size_t(b)];
  for (const auto& bx : p.copies) {
    const auto& src = U[std::size_t(bx.src_block)];
    const index_t ex = bx.extent[0], ey = bx.extent[1], ez = bx.extent[2];
    for (int f = 0; f < 5; ++f) {
      double* __restrict d = dst[f] + bx.dst;
      const double* __restrict s = src[f] + bx.src;
      if (ex == 2) {  // an x face's slab: rows of two cells (no loop over the row)
        for (index_t c = 0; c < ez; ++c)
          for (index_t r = 0; r < ey; ++r) {
            const index_t o = r * sy + c * sz;
            d[o] = s[o];
            d[o + 1] = s[o + 1];
          }
        continue;
      }
      for (index_t c = 0; c < ez; ++c)
        for (index_t r = 0; r < ey; ++r) {
          const index_t o = r * sy + c * sz;
          for (index_t a = 0; a < ex; ++a) d[o + a] = s[o + a];
        }
    }
  }
  for (const auto& it : p.restrictions) {
    const auto& src = U[std::size_t(it.src_block)];
    for (int f = 0; f < 5; ++f) dst[f][it.dst] = restrict8(src[f], it.src, sy, sz);
  }
  auto value = [&](const value_ref& r, int f) {
    const double* u = U[std::size_t(r.block)][f];
    return r.restricted ? restrict8(u, r.cell, sy, sz) : u[r.cell];
  };
  for (const auto& grp : p.prolongations) {
    // The coarse cell and its limited slopes, once for the group's children.
    double c[5], sl[5][3];
    for (int f = 0; f < 5; ++f) {
      c[f] = value(grp.centre, f);
      for (int d = 0; d < 3; ++d) {
        const value_ref& lo = grp.side[std::size_t(2 * d)];
        const value_ref& hi = grp.side[std::size_t(2 * d + 1)];
        const double a = lo.block >= 0 ? c[f] - value(lo, f) : 0.0;
        const double bb = hi.block >= 0 ? value(hi, f) - c[f] : 0.0;
        sl[f][d] = a * bb > 0.0 ? (std::fabs(a) < std::fabs(bb) ? a : bb) : 0.0;  // minmod
      }
    }
    for (int k8 = 0; k8 < grp.count; ++k8) {
      const auto& off = grp.offset[std::size_t(k8)];
      double q[5];
      for (int f = 0; f < 5; ++f) {
        q[f] = c[f];
        for (int d = 0; d < 3; ++d) q[f] += off[std::size_t(d)] * sl[f][d];
      }
      const bool gas_ok = q[0] > 0.0 && gas.pressure(q[0], q[1], q[2], q[3], q[4]) > 0.0;
      for (int f = 0; f < 5; ++f) dst[f][grp.dst[std::size_t(k8)]] = gas_ok ? q[f] : c[f];
    }
  }
}

}  // namespace parafsi::fluid::blocks
