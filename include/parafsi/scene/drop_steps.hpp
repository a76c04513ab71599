/// \file drop_steps.hpp
/// The steps of the parachute drop that a program building the drop itself
/// (examples/drop_guide.cpp) shares with scene::run_drop (scene/drop.hpp):
///
///   make_drop_grid(box)               the rectilinear grid of a model::drop_box
///   make_drop_blocks(box, n, across)  its block-mesh layout and finest level (--mesh blocks)
///   drop_block_target(...)            the block mesh's refinement target: the canopy
///   drop_canopy_travel(...)           how far the canopy may move until the next regrid
///   place_drop_box(fluid, box, chute) the box pose: axes, payload mass centre, velocity
///   drop_frame_target<Fluid>(g)       the stepper's frame target: the payload's mass centre
///   landing_step(dt, left)            a step shortened to land on an output instant
///
/// The box motion itself is planned by the stepper (move_frame phase) from the frame target.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "../fluid/blocks/layout.hpp"
#include "../fluid/blocks/refine.hpp"
#include "../fluid/grid.hpp"
#include "../frame_target.hpp"
#include "../model/drop_box.hpp"
#include "../structure/from_drop_scene.hpp"

namespace parafsi::scene {

/// The rectilinear grid of the box `b`: fluid::axis::refined along each axis.
inline fluid::rectilinear_grid make_drop_grid(const model::drop_box& b) {
  auto axis = [&](std::size_t d) {
    return fluid::axis::refined(b.lo[d], b.hi[d], b.fine_lo[d], b.fine_hi[d], b.cell, b.growth);
  };
  return fluid::rectilinear_grid{axis(0), axis(1), axis(2)};
}

/// The block mesh of the box `b` with n cells per block edge: the finest cell is the box's
/// refined cell h, and L levels above the root grid with L the largest that leaves at least
/// `across` root blocks (n 2^L h wide) across the narrowest side (2 by default; 1 gives blocks
/// of 16³ the levels of 8³ blocks across the same box); the root blocks tile a box grown
/// about the same centre to whole blocks (every axis keeps cubic cells). Returns the layout
/// and L.
inline std::pair<fluid::block_layout, int> make_drop_blocks(const model::drop_box& b, int n, int across = 2) {
  require(n >= 2 && across >= 1, "scene::make_drop_blocks: need n >= 2 and across >= 1, got ", n, " and ", across);
  const double h = b.cell;
  double narrow = 1e300;
  for (std::size_t d = 0; d < 3; ++d) narrow = std::min(narrow, b.hi[d] - b.lo[d]);
  const int L = std::max(0, int(std::floor(std::log2(narrow / (double(across) * n * h)))));
  require(L <= fluid::blocks::tree::max_depth, "scene::make_drop_blocks: ", L, " levels are too many");
  const double root = double(n) * h * std::ldexp(1.0, L);
  fluid::block_layout lay;
  lay.block_cells = n;
  for (std::size_t d = 0; d < 3; ++d) {
    const index_t nb = std::max<index_t>(1, index_t(std::ceil((b.hi[d] - b.lo[d]) / root - 1e-9)));
    require(nb <= fluid::blocks::tree::max_root, "scene::make_drop_blocks: ", nb, " root blocks on an axis, more than ",
            fluid::blocks::tree::max_root);
    const double mid = 0.5 * (b.lo[d] + b.hi[d]);
    lay.root_blocks[d] = nb;
    lay.lo[d] = mid - 0.5 * double(nb) * root;
    lay.hi[d] = mid + 0.5 * double(nb) * root;
  }
  return {lay, L};
}

/// The narrowest cell width of level `level` of a block layout (the canopy's buffer and travel
/// are counted in these).
template <class Layout>
double drop_cell_width(const Layout& lay, int level) {
  return std::min({lay.cell_width(0, level), lay.cell_width(1, level), lay.cell_width(2, level)});
}

/// The block mesh's refinement target for a drop: the finest level `level` within a buffer of
/// the canopy's nodes (box coordinates of fluid `f`'s pose), graded outwards (each coarser
/// level twice as far). The buffer is the canopy's longest element edge now plus
/// (travel + 2) finest cells: `travel` is how many finest cells a node may move relative to
/// the box until the next regrid (drop_canopy_travel), and the two more keep every cell the
/// canopy cuts, with its interpolation stencil, on the finest level until then.
template <class Fluid>
fluid::blocks::near_points<fluid::block_layout> drop_block_target(const Fluid& f, const structure::nodes& nd,
                                                                  index_t canopy_nodes,
                                                                  const std::vector<std::array<index_t, 3>>& tris,
                                                                  int level, double travel) {
  const auto& lay = f.layout();
  const Eigen::Matrix3d Rt = f.pose().R.transpose();
  std::vector<Eigen::Vector3d> pts;
  pts.reserve(std::size_t(canopy_nodes));
  for (index_t i = 0; i < canopy_nodes; ++i) pts.push_back(Rt * (nd.position(i) - f.pose().X));
  double edge = 0;
  for (const auto& t : tris)
    for (int a = 0; a < 3; ++a)
      edge = std::max(edge, (nd.position(t[std::size_t(a)]) - nd.position(t[std::size_t((a + 1) % 3)])).norm());
  const double h = drop_cell_width(lay, level);
  return {lay, std::move(pts), edge + (travel + 2.0) * h, level, true};
}

/// The finest cells (of width h) a canopy node may move relative to the box of fluid `f`
/// until the next regrid, `finest_steps` steps of the finest level lasting `window` seconds
/// in all:
///   travel = min(K, 1 + 2 v_max window / h),
/// K = finest_steps the coupling's travel limit (a node moves at most a cell per finest step,
/// checked before each), v_max the largest speed of a canopy node relative to the grid now.
/// The speed term, twice the distance at today's speed plus a cell, is the bound when many
/// finest steps pass between regrids (a subcycled step of the coarsest level holds 2^L);
/// a node that still leaves the finest level stops the step with a message naming its face
/// (fluid::block_solver). window ≤ 0: the travel limit alone.
template <class Fluid>
double drop_canopy_travel(const Fluid& f, const structure::nodes& nd, index_t canopy_nodes, int level, int finest_steps,
                          double window) {
  const double K = double(finest_steps);
  if (!(window > 0) || finest_steps <= 1) return K;
  const auto& lay = f.layout();
  const double h = drop_cell_width(lay, level);
  double v = 0;
  for (index_t i = 0; i < canopy_nodes; ++i)
    v = std::max(v, (nd.velocity(i) - f.pose().grid_velocity(f.pose().to_box(nd.position(i)))).norm());
  return std::min(K, 1.0 + 2.0 * v * window / h);
}

/// The tensor box's refined block as a block-mesh criterion (--refine-column): `level` on
/// every block that meets [fine_lo, fine_hi] of the drop box `b` (the column about the
/// box axis from below the line confluence to above the crown, where the tensor box keeps
/// its finest cells), 0 elsewhere; the 2:1 balance grades the rest.
template <class Layout>
auto drop_column_target(const Layout& lay, const model::drop_box& b, int level) {
  return fluid::blocks::in_box{lay, b.fine_lo, b.fine_hi, level};
}

/// Place the box `b` of fluid `f` at the payload of `a`: R = the box axes, X = the payload
/// mass centre, and for a frame that follows the payload (one with `track`) V = the
/// payload's velocity, so the first stable step accounts for the box speed.
template <class Fluid>
void place_drop_box(Fluid& f, const model::drop_box& b, const structure::drop_assembly& a) {
  const auto& body = structure::payload(a).body();
  f.pose().R.col(0) = b.axes.col(0);
  f.pose().R.col(1) = b.axes.col(1);
  f.pose().R.col(2) = b.axes.col(2);
  f.pose().X = body.mass_centre();
  if constexpr (requires(const Eigen::Vector3d& x) { f.frame().track(x, x); }) f.pose().V = body.mass_centre_velocity();
}

/// The payload's rigid body of a drop assembly (the body a following box tracks).
struct drop_payload_body {
  template <class Assembly>
  const auto& operator()(const Assembly& a) const {
    return structure::payload(a).body();
  }
};

/// The drop's frame target for the explicit_stepper (frame_target.hpp): a box that
/// follows the payload (a frame with `track`) gets follow_body on the payload's mass
/// centre, extrapolated to the end of each step under gravity, track(x + v dt, v + g dt)
/// (the payload's own acceleration, which the drag reduces, is not known before the step);
/// a fixed box gets none.
template <class Fluid>
auto drop_frame_target(double gravity) {
  if constexpr (requires(Fluid & f, const Eigen::Vector3d& x) { f.frame().track(x, x); })
    return follow_body<drop_payload_body>{drop_payload_body{}, gravity};
  else return no_frame_target{};
}
template <class Fluid>
using drop_frame_target_t = decltype(drop_frame_target<Fluid>(0.0));

/// The step dt shortened to land on an instant `left` seconds ahead: all of `left` when
/// dt reaches it, half of it when dt would leave less than a step's sliver, else dt.
inline double landing_step(double dt, double left) {
  if (dt >= left * (1.0 - 1e-9)) return left;
  if (dt > 0.5 * left) return 0.5 * left;
  return dt;
}

}  // namespace parafsi::scene
