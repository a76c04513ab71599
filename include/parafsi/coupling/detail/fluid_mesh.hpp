/// \file fluid_mesh.hpp
/// What a coupling needs of the fluid's mesh, for the box solver (fluid::solver, one
/// rectilinear grid) and the block mesh (fluid::block_solver) alike: cells as flat indices
/// of the fluid's arrays (the box's grid index, or the block mesh's global_index), their
/// count and volumes, a loop over interior cells, and point location as an eight-cell
/// trilinear stencil (coupling_points.hpp).
///
/// Block mesh stencils: the point's leaf sets the level L; the stencil is the trilinear one
/// of the level-L cell centres around the point, clamped at the box faces like the grid's
/// (so every weight lands on an interior cell), and each of its 8 cells is the leaf cell
/// holding that centre: a cell of a same-level neighbour block, or, where the stencil
/// reaches across a level boundary, the coarser or finer leaf cell there (the weights stay,
/// so interpolation and spreading remain each other's adjoint and conservative). A
/// refinement criterion that keeps the structure on the finest level with a buffer
/// (fluid/blocks/refine.hpp) makes every stencil one level.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <variant>

#include <Eigen/Core>

#include "../../core/parallel.hpp"
#include "../../fluid/blocks/layout.hpp"
#include "../../fluid/grid.hpp"
#include "../coupling_points.hpp"

namespace parafsi::coupling {

/// A fluid on the block mesh (fluid::block_solver).
template <class F>
concept block_fluid = requires(const F& f) {
  f.block_count();
  f.stride();
  f.tree();
  f.layout();
};

/// Stencils on a block mesh (see the file comment).
class block_locator {
 public:
  block_locator() = default;
  template <block_fluid F>
  explicit block_locator(const F& f) : tree_(&f.tree()), lay_(f.layout()), stride_(f.stride()) {}

  double min_width() const noexcept {
    const int top = tree_->finest_level();
    return std::min({lay_.cell_width(0, top), lay_.cell_width(1, top), lay_.cell_width(2, top)});
  }

  stencil locate(const Eigen::Vector3d& xi) const {
    stencil s;
    s.inside = true;
    for (int d = 0; d < 3; ++d)
      if (!(xi[d] >= lay_.lo[std::size_t(d)] && xi[d] <= lay_.hi[std::size_t(d)])) s.inside = false;
    Eigen::Vector3d q = xi;  // the point's leaf (clamped into the box)
    for (int d = 0; d < 3; ++d) {
      const double eps = 1e-12 * (lay_.hi[std::size_t(d)] - lay_.lo[std::size_t(d)]);
      q[d] = std::clamp(q[d], lay_.lo[std::size_t(d)] + eps, lay_.hi[std::size_t(d)] - eps);
    }
    const fluid::blocks::cell_address home = fluid::blocks::find_cell(*tree_, lay_, q);
    const int L = home.level;
    const index_t n = lay_.block_cells;
    std::array<index_t, 3> i0{};
    double vol = 1.0, hmin = 1e300;
    for (int d = 0; d < 3; ++d) {
      const double h = lay_.cell_width(d, L);
      const index_t N = tree_->extent(d, L) * n;
      const double u = (xi[d] - lay_.lo[std::size_t(d)]) / h - 0.5;  // in cell-centre units
      const double fl = std::floor(u);
      index_t i = fl < -1.0 ? -1 : (fl > double(N) ? N : index_t(fl));
      double t;
      if (N == 1) {
        i = 0;
        t = 0.0;
      } else if (i < 0) {
        i = 0;
        t = 0.0;
      } else if (i >= N - 1) {
        i = N - 2;
        t = 1.0;
      } else {
        t = std::clamp(u - double(i), 0.0, 1.0);
      }
      i0[std::size_t(d)] = i;
      s.t[std::size_t(d)] = t;
      vol *= h;
      hmin = std::min(hmin, h);
    }
    const fluid::blocks::location& hb = tree_->leaf(home.block);
    for (int a = 0; a < 8; ++a) {
      std::array<index_t, 3> G{};
      bool own = true;  // the corner cell lies in the point's own block: no search
      for (int d = 0; d < 3; ++d) {
        G[std::size_t(d)] = i0[std::size_t(d)] + ((a >> d) & 1);
        const index_t loc = G[std::size_t(d)] - hb.l[std::size_t(d)] * n;
        own = own && loc >= 0 && loc < n;
      }
      if (own) {
        s.cell[std::size_t(a)] = global({home.block, L, {G[0] - hb.l[0] * n, G[1] - hb.l[1] * n, G[2] - hb.l[2] * n}});
        continue;
      }
      Eigen::Vector3d c;
      for (int d = 0; d < 3; ++d)
        c[d] = lay_.lo[std::size_t(d)] + (double(G[std::size_t(d)]) + 0.5) * lay_.cell_width(d, L);
      const fluid::blocks::cell_address ca = fluid::blocks::find_cell(*tree_, lay_, c);
      s.cell[std::size_t(a)] = ca.block < 0 ? global(home) : global(ca);
    }
    s.ijk = i0;
    s.base = s.cell[0];
    s.h = std::cbrt(vol);
    s.hmin = hmin;
    return s;
  }

 private:
  index_t global(const fluid::blocks::cell_address& a) const noexcept {
    return a.block * stride_ + fluid::blocks::block_index{lay_.block_cells}(a.ijk[0], a.ijk[1], a.ijk[2]);
  }
  const fluid::blocks::tree* tree_ = nullptr;
  fluid::block_layout lay_{};
  index_t stride_ = 0;
};

/// The locator of either mesh, chosen when a coupling attaches.
class mesh_locator {
 public:
  mesh_locator() = default;
  explicit mesh_locator(grid_locator g) : loc_(std::move(g)) {}
  explicit mesh_locator(block_locator b) : loc_(std::move(b)) {}
  template <class F>
  static mesh_locator of(const F& f) {
    if constexpr (block_fluid<F>) return mesh_locator(block_locator(f));
    else return mesh_locator(grid_locator(f.grid()));
  }
  stencil locate(const Eigen::Vector3d& xi) const {
    return std::visit([&](const auto& l) { return l.locate(xi); }, loc_);
  }
  double min_width() const {
    return std::visit([](const auto& l) { return l.min_width(); }, loc_);
  }

 private:
  std::variant<grid_locator, block_locator> loc_;
};

namespace detail {

/// Width of the smallest side of the fluid cell holding ξ (box coordinates; the nearest
/// cell of the box grid, the leaf cell of a block mesh, the finest cell outside the box).
template <class F>
double local_width(const F& f, const Eigen::Vector3d& xi) {
  if constexpr (block_fluid<F>) {
    const auto& lay = f.layout();
    const fluid::blocks::cell_address a = fluid::blocks::find_cell(f.tree(), lay, xi);
    const int L = a.block < 0 ? f.tree().finest_level() : a.level;
    return std::min({lay.cell_width(0, L), lay.cell_width(1, L), lay.cell_width(2, L)});
  } else {
    const fluid::rectilinear_grid& g = f.grid();
    double h = std::numeric_limits<double>::infinity();
    for (int d = 0; d < 3; ++d) {
      if (g.n(d) <= 1) continue;
      index_t lo = 0, hi = g.n(d) - 1;  // last cell whose low face is <= xi_d
      while (lo < hi) {
        const index_t mid = (lo + hi + 1) / 2;
        if (g.face(d, mid) <= xi[d]) lo = mid;
        else hi = mid - 1;
      }
      h = std::min(h, g.width(d, lo));
    }
    return std::isfinite(h) ? h : g.min_width();
  }
}

}  // namespace detail

/// Where a coupling finds the faces a membrane crosses (coupling::embedded): an index grid
/// whose cells and faces it tests, and the fluid cell of each index-grid cell. On the box
/// solver the index grid is the box's grid and a cell is its own flat index; on a block
/// mesh it is the uniform grid of the finest level over the whole box (axes only, no
/// storage), whose cell (I, J, K) is cell I mod n of the finest-level block ⌊I/n⌋ if that
/// block is a leaf, else none (−1): a membrane must lie on the finest level.
class face_space {
 public:
  face_space() = default;
  /// Follow the fluid's mesh (every step: a regrid may have changed it); the index grid is
  /// rebuilt only when the finest level's extent changed, so a step allocates nothing.
  template <class F>
  void refresh(const F& f) {
    if constexpr (block_fluid<F>) {
      const auto& lay = f.layout();
      const int L = f.tree().finest_level();
      std::array<index_t, 3> N{};
      for (int d = 0; d < 3; ++d) N[std::size_t(d)] = f.tree().extent(d, L) * lay.block_cells;
      if (grid_ != &own_ || N != N_ || lay.lo != lo_ || lay.hi != hi_) {
        own_ = fluid::rectilinear_grid::uniform(N, lay.lo, lay.hi);
        N_ = N;
        lo_ = lay.lo;
        hi_ = lay.hi;
      }
      grid_ = &own_;
      tree_ = &f.tree();
      n_ = lay.block_cells;
      stride_ = f.stride();
      level_ = L;
    } else {
      grid_ = &f.grid();
      tree_ = nullptr;
    }
  }
  face_space(const face_space& o) { *this = o; }
  face_space& operator=(const face_space& o) {
    if (this == &o) return *this;
    own_ = o.own_;
    grid_ = o.grid_ == &o.own_ ? &own_ : o.grid_;
    tree_ = o.tree_;
    n_ = o.n_;
    stride_ = o.stride_;
    level_ = o.level_;
    N_ = o.N_;
    lo_ = o.lo_;
    hi_ = o.hi_;
    return *this;
  }

  const fluid::rectilinear_grid& grid() const noexcept { return *grid_; }
  bool blocks() const noexcept { return tree_ != nullptr; }
  /// Fluid cell (flat index of the fluid's arrays) of index-grid cell c; −1: none.
  index_t cell(index_t c) const {
    if (!tree_) return c;
    const auto I = grid_->ijk(c);
    fluid::blocks::location q{level_, {}};
    std::array<index_t, 3> loc{};
    for (int d = 0; d < 3; ++d) {
      q.l[std::size_t(d)] = I[std::size_t(d)] / n_;
      loc[std::size_t(d)] = I[std::size_t(d)] % n_;
    }
    const index_t id = tree_->id_of(q);
    if (id < 0) return -1;
    return id * stride_ + fluid::blocks::block_index{n_}(loc[0], loc[1], loc[2]);
  }

 private:
  fluid::rectilinear_grid own_{};
  const fluid::rectilinear_grid* grid_ = nullptr;
  const fluid::blocks::tree* tree_ = nullptr;
  index_t n_ = 0, stride_ = 0;
  int level_ = 0;
  std::array<index_t, 3> N_{};         ///< own_'s cells per axis (refresh)
  std::array<double, 3> lo_{}, hi_{};  ///< and its box
};

namespace detail {

/// Length of the fluid's flat cell arrays (ghosts and padding included).
template <class F>
index_t cell_count(const F& f) {
  if constexpr (block_fluid<F>) return f.stride() * f.block_count();
  else return f.grid().total_cells();
}

/// fn(cell, volume) for every interior cell (flat index), in parallel over rows or blocks.
template <class F, class Fn>
void for_each_interior_cell(const F& f, Fn&& fn) {
  if constexpr (block_fluid<F>) {
    parallel::for_range(0, f.block_count(), [&](index_t id) {
      const auto& b = f.block_at(id);
      const auto& g = b.grid;
      for (index_t k = 0; k < g.n(2); ++k)
        for (index_t j = 0; j < g.n(1); ++j)
          for (index_t i = 0; i < g.n(0); ++i) fn(f.global_index(id, g.index(i, j, k)), g.cell_volume(i, j, k));
    });
  } else {
    const auto& g = f.grid();
    const index_t nx = g.n(0), ny = g.n(1);
    parallel::for_range(0, ny * g.n(2), [&](index_t row) {
      const index_t j = row % ny, k = row / ny;
      const index_t base = g.index(0, j, k);
      for (index_t i = 0; i < nx; ++i) fn(base + i, g.cell_volume(i, j, k));
    });
  }
}

/// Volume of cell c (flat index).
template <class F>
double cell_volume(const F& f, index_t c) {
  if constexpr (block_fluid<F>) return f.block_at(c / f.stride()).grid.cell_volume(c % f.stride());
  else return f.grid().cell_volume(c);
}

}  // namespace detail
}  // namespace parafsi::coupling
