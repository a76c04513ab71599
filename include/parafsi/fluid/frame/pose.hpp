/// \file pose.hpp
/// Rigid pose of the fluid box: a box point ξ sits at x = X + R ξ (inertial).
/// Over one step the box moves with constant velocity V and angular velocity Ω
/// (inertial components); advancing is exact for that motion:
///   X ← X + V Δt,   R ← exp([Ω]× Δt) R.
/// The grid velocity at a box point is w = V + Ω × (R ξ); its normal component on a
/// face with box normal e_d is ŵ_d = v̂_d + (ω̂ × ξ)_d, with v̂ = Rᵀ V, ω̂ = Rᵀ Ω.
#pragma once
#include <Eigen/Dense>
#include <Eigen/Geometry>

namespace parafsi::frame {

/// The box motion over one step, as a frame plans it: constant V and Ω.
struct motion {
  Eigen::Vector3d V = Eigen::Vector3d::Zero();      ///< velocity of the box origin (m/s)
  Eigen::Vector3d Omega = Eigen::Vector3d::Zero();  ///< angular velocity (rad/s, inertial)
};

struct pose {
  Eigen::Vector3d X = Eigen::Vector3d::Zero();      ///< box origin (m, inertial)
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  ///< box axes as columns
  Eigen::Vector3d V = Eigen::Vector3d::Zero();      ///< velocity of the box origin (m/s)
  Eigen::Vector3d Omega = Eigen::Vector3d::Zero();  ///< angular velocity (rad/s, inertial)

  Eigen::Vector3d to_inertial(const Eigen::Vector3d& xi) const { return X + R * xi; }
  Eigen::Vector3d to_box(const Eigen::Vector3d& x) const { return R.transpose() * (x - X); }
  /// Grid velocity at box point ξ (inertial components).
  Eigen::Vector3d grid_velocity(const Eigen::Vector3d& xi) const { return V + Omega.cross(R * xi); }

  /// Take a planned motion for the coming step.
  void set_motion(const motion& m) {
    V = m.V;
    Omega = m.Omega;
  }
  motion current_motion() const { return {V, Omega}; }

  void advance(double dt) {
    X += V * dt;
    const double a = Omega.norm() * dt;  // signed: dt < 0 turns back (SSP-RK3's stage 3)
    if (a != 0.0) {
      R = Eigen::AngleAxisd(a, Omega.normalized()).toRotationMatrix() * R;
      // Keep R orthonormal to round-off over long runs.
      Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
      R = svd.matrixU() * svd.matrixV().transpose();
    }
  }
};

}  // namespace parafsi::frame
