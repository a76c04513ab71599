/// \file frame_target.hpp
/// Frame-target policies of explicit_stepper: who tells a tracking box
/// (frame::follow_payload) where to go. The stepper applies its policy at the start of
/// every step, before it plans the box motion (move_frame phase):
///   no_frame_target     — nothing (fixed, translating or rigid boxes; or the user calls
///                          fluid().frame().track(x_next, v_next) before each step);
///   follow_body{body, g} — the mass centre of a rigid body of the structure, predicted
///                          to the end of the step with its present velocity and gravity:
///                            x_next = x + v Δt,   v_next = v + g Δt,   g = (0, 0, −gravity),
///                          x, v the body's mass_centre() and mass_centre_velocity().
/// `body` maps the structure to the body: body_of<I> is the body of assembly part I
/// (its body() when the part has one, the part itself otherwise), or any callable.
#pragma once
#include <cstddef>

#include <Eigen/Core>

namespace parafsi {

/// No frame target: the box moves as its frame policy says on its own.
struct no_frame_target {
  static constexpr bool active = false;
};

/// The rigid body of assembly part I (`part<I>().body()`, or `part<I>()` when the part
/// is the body).
template <std::size_t I>
struct body_of_part {
  template <class Structure>
  const auto& operator()(const Structure& s) const {
    const auto& p = s.template part<I>();
    if constexpr (requires { p.body(); }) return p.body();
    else return p;
  }
};
template <std::size_t I>
inline constexpr body_of_part<I> body_of{};

/// Track a rigid body's mass centre: track(x + v Δt, v + g Δt) before each step.
template <class Body>
struct follow_body {
  static constexpr bool active = true;
  Body body;              ///< structure → body with mass_centre() and mass_centre_velocity()
  double gravity = 9.81;  ///< g (m/s²) along −z

  template <class Fluid, class Structure>
  void operator()(Fluid& f, const Structure& s, double dt) const {
    static_assert(
        requires(Fluid & fl, const Eigen::Vector3d& x) { fl.frame().track(x, x); },
        "follow_body: the fluid's frame must be a tracking frame (frame::follow_payload)");
    const auto& b = body(s);
    const Eigen::Vector3d xp = b.mass_centre(), vp = b.mass_centre_velocity();
    const Eigen::Vector3d g{0, 0, -gravity};
    f.frame().track(xp + vp * dt, vp + g * dt);
  }
};
template <class Body>
follow_body(Body, double) -> follow_body<Body>;
template <class Body>
follow_body(Body) -> follow_body<Body>;

}  // namespace parafsi
