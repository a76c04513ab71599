/// \file payload.hpp
/// Cuboid rigid payload (plain data, no solver types): mass, edge lengths, principal
/// inertia of a uniform box, and the riser hanging point r_T in body coordinates.
///
/// Body axes: origin at the mass centre, edges along the axes, body +z pointing to the
/// canopy (the riser). The hanging point is the centre of the top face,
/// r_T = (0, 0, c/2). Principal moments of a uniform box of edges (a, b, c):
///     J = m/12 · (b² + c², a² + c², a² + b²).
/// The paper gives 1.8 kg and "a cuboid with the same size as the actual payload" but no
/// size; the default 0.15 × 0.15 × 0.10 m (800 kg/m³, a ballast box) is our choice, and
/// only enters through J and r_T (payload aerodynamics is neglected, as in the paper).
/// With structure::rigid_body: `rigid_body{rigid_body::cuboid(p.mass, p.size), p.position,
/// p.attitude, p.velocity}` and `attachment.attach(hanging_node, p.hanging_point)`.
#pragma once
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "../core/error.hpp"

namespace parafsi::model {

struct payload_parameters {
  double mass = 1.8;                                         ///< kg
  Eigen::Vector3d size = Eigen::Vector3d(0.15, 0.15, 0.10);  ///< edge lengths a, b, c (m), c along the axis

  void validate() const {
    require(mass > 0 && std::isfinite(mass), "model::payload: mass must be > 0, got ", mass);
    for (int i = 0; i < 3; ++i)
      require(size[i] > 0 && std::isfinite(size[i]), "model::payload: edge length ", i, " must be > 0, got ", size[i]);
  }
};

struct payload_data {
  double mass = 0;
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  Eigen::Vector3d inertia_diagonal = Eigen::Vector3d::Zero();    ///< about the mass centre, body axes (kg m²)
  Eigen::Vector3d hanging_point = Eigen::Vector3d::Zero();       ///< r_T, body axes (m)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();            ///< mass centre, world (m)
  Eigen::Quaterniond attitude = Eigen::Quaterniond::Identity();  ///< body → world
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();            ///< m/s
  /// World position of the hanging point.
  Eigen::Vector3d hanging_point_world() const { return position + attitude * hanging_point; }
};

/// The payload at the origin, body axes = world axes, at rest.
inline payload_data cuboid_payload(const payload_parameters& p = {}) {
  p.validate();
  payload_data d;
  d.mass = p.mass;
  d.size = p.size;
  const Eigen::Vector3d s2 = p.size.cwiseProduct(p.size);
  d.inertia_diagonal = Eigen::Vector3d(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y()) * (p.mass / 12.0);
  d.hanging_point = Eigen::Vector3d(0, 0, 0.5 * p.size.z());
  return d;
}

}  // namespace parafsi::model
