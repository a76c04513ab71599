/// \file translate.hpp
/// A box translating with a prescribed velocity V (no rotation). The velocity may be
/// changed between steps with `set_velocity`.
#pragma once
#include "../../core/policy.hpp"
#include "pose.hpp"

namespace parafsi::frame {

struct translate {
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  using policy_kind = kind::frame;
  static constexpr const char* name() noexcept { return "translate"; }
  void set_velocity(const Eigen::Vector3d& v) { velocity = v; }
  void plan(pose& p, double, double) const {
    p.V = velocity;
    p.Omega.setZero();
  }
  /// Checkpoint (io/archive.hpp): the velocity.
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& self) {
    ar("velocity", self.velocity);
  }
};

}  // namespace parafsi::frame
