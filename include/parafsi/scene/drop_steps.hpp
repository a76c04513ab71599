/// \file drop_steps.hpp
/// The steps of the parachute drop that a program building the drop itself
/// (examples/drop_guide.cpp) shares with scene::run_drop (scene/drop.hpp):
///
///   make_drop_grid(box)               the rectilinear grid of a model::drop_box
///   place_drop_box(fluid, box, chute) the box pose: axes, payload mass centre, velocity
///   drop_frame_target<Fluid>(g)       the stepper's frame target: the payload's mass centre
///   landing_step(dt, left)            a step shortened to land on an output instant
///
/// The box motion itself is planned by the stepper (move_frame phase) from the frame target.
#pragma once
#include <cstddef>
#include <type_traits>

#include <Eigen/Core>

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
