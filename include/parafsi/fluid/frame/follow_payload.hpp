/// \file follow_payload.hpp
/// The paper's adaptive moving fluid mesh (its Eq. 1): the box translates with a
/// tracked point (the payload's mass centre) and turns so that a chosen box axis
/// stays aligned with the point's velocity. The paper writes the turning rate as
///   ω = (v_d × v̇_d) / (v_d · v_d),
/// the angular velocity of the velocity direction. Here the rate is computed per
/// step so that the box reaches the target exactly at the end of the step:
///   V = (x_target(t+Δt) − X(t)) / Δt,
///   Ω = θ/Δt · (a × v̂)/|a × v̂|,  a = R e_axis,  θ = atan2(|a × v̂|, a · v̂),
/// which is the discrete form of Eq. 1 without drift. Below `min_speed` the box
/// does not turn (the direction of a near-zero velocity is undefined), and the
/// turning rate is capped at `max_rate` to keep face speeds bounded.
/// The payload's state is an input: call `track(x, v)` with the target's position
/// and velocity at the end of the coming step before each `step(dt)`.
#pragma once
#include <cmath>
#include "../../core/policy.hpp"

#include "pose.hpp"

namespace parafsi::frame {

struct follow_payload {
  Eigen::Vector3d axis{0.0, 0.0, -1.0};  ///< box axis aligned with the velocity (box coords)
  double min_speed = 0.5;                ///< no turning below this speed (m/s)
  double max_rate = 10.0;                ///< cap on |Ω| (rad/s)
  bool turn = true;                      ///< false: translate only (compared option)

  Eigen::Vector3d target_position = Eigen::Vector3d::Zero();
  Eigen::Vector3d target_velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  ///< target point in box coordinates

  using policy_kind = kind::frame;
  static constexpr const char* name() noexcept { return "follow_payload"; }

  /// Target state at the end of the coming step.
  void track(const Eigen::Vector3d& x_next, const Eigen::Vector3d& v_next) {
    target_position = x_next;
    target_velocity = v_next;
  }

  void plan(pose& p, double, double dt) const {
    p.Omega.setZero();
    const double speed = target_velocity.norm();
    if (turn && speed > min_speed && dt > 0.0) {
      const Eigen::Vector3d a = p.R * axis.normalized();
      const Eigen::Vector3d vhat = target_velocity / speed;
      const Eigen::Vector3d c = a.cross(vhat);
      const double s = c.norm();
      if (s > 1e-14) {
        const double theta = std::atan2(s, a.dot(vhat));
        double rate = theta / dt;
        if (rate > max_rate) rate = max_rate;
        p.Omega = c / s * rate;
      }
    }
    // The target's box point must arrive at target_position: with the rotation over
    // the step, X(t+Δt) = x_target − R(t+Δt) offset.
    if (dt > 0.0) {
      Eigen::Matrix3d R_next = p.R;
      const double ang = p.Omega.norm() * dt;
      if (ang > 0.0) R_next = Eigen::AngleAxisd(ang, p.Omega.normalized()).toRotationMatrix() * p.R;
      p.V = (target_position - R_next * offset - p.X) / dt;
    }
  }

  /// Checkpoint (io/archive.hpp): settings, target and offset (a restart continues with
  /// the values of the run that wrote the file).
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& self) {
    ar("axis", self.axis);
    ar("min_speed", self.min_speed);
    ar("max_rate", self.max_rate);
    ar("turn", self.turn);
    ar("target_position", self.target_position);
    ar("target_velocity", self.target_velocity);
    ar("offset", self.offset);
  }
};

}  // namespace parafsi::frame
