/// \file drop_steps.hpp
/// The steps of the parachute drop that a program building the drop itself
/// (examples/drop_guide.cpp) shares with scene::run_drop (scene/drop.hpp):
///
///   make_drop_grid(box)               the rectilinear grid of a model::drop_box
///   place_drop_box(fluid, box, chute) the box pose: axes, payload mass centre, velocity
///   track_payload(stepper, dt)        the following box's target at the end of the step
///   landing_step(dt, left)            a step shortened to land on an output instant
///
/// track_payload is the one place of the tracking predictor, x + v dt and v + g dt of the
/// payload mass centre; a stepper that plans the frame itself from a frame target makes it
/// unnecessary.
#pragma once
#include <cstddef>

#include <Eigen/Core>

#include "../fluid/grid.hpp"
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
  if constexpr (requires(const Eigen::Vector3d& x) { f.frame().track(x, x); })
    f.pose().V = body.mass_centre_velocity();
}

/// The following box's target at the end of the coming step of length dt: the payload
/// mass centre's position and velocity extrapolated under the structure's gravity,
/// track(x + v dt, v + g dt) (the payload's own acceleration, which the drag reduces, is
/// not known before the step). Nothing for a frame without `track` (a fixed box).
template <class Stepper>
void track_payload(Stepper& s, double dt) {
  auto& f = s.fluid();
  if constexpr (requires(const Eigen::Vector3d& x) { f.frame().track(x, x); }) {
    const auto& body = structure::payload(s.structure()).body();
    const Eigen::Vector3d xp = body.mass_centre(), vp = body.mass_centre_velocity();
    const Eigen::Vector3d g = s.structure().integrator().gravity;
    f.frame().track(xp + vp * dt, vp + g * dt);
  }
}

/// The step dt shortened to land on an instant `left` seconds ahead: all of `left` when
/// dt reaches it, half of it when dt would leave less than a step's sliver, else dt.
inline double landing_step(double dt, double left) {
  if (dt >= left * (1.0 - 1e-9)) return left;
  if (dt > 0.5 * left) return 0.5 * left;
  return dt;
}

}  // namespace parafsi::scene
