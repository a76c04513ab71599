/// \file rigid.hpp
/// A box in prescribed rigid motion: velocity V and angular velocity Ω (inertial),
/// both constant unless changed between steps. Used by verification scenes
/// (free-stream preservation on a translating and rotating box).
#pragma once
#include "../../core/policy.hpp"
#include "pose.hpp"

namespace parafsi::frame {

struct rigid {
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  using policy_kind = kind::frame;
  static constexpr const char* name() noexcept { return "rigid"; }
  void plan(pose& p, double, double) const {
    p.V = velocity;
    p.Omega = angular_velocity;
  }
  /// Checkpoint (io/archive.hpp): the velocities.
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& self) {
    ar("velocity", self.velocity);
    ar("angular_velocity", self.angular_velocity);
  }
};

}  // namespace parafsi::frame
