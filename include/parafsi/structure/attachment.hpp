/// \file attachment.hpp
/// A rigid body as a part of a structural assembly, with nodes tied to body-fixed
/// points (the riser hanging point r_T; methods §7.3, the analogue of LS-DYNA's
/// *CONSTRAINED_EXTRA_NODES):
///   x_a = X + R r_a,   v_a = V + ω × (R r_a)        (placed every substep, never integrated)
///   F += Σ_a f_a,      M += Σ_a (R r_a) × f_a        (node forces handed to the body)
/// The lumped masses of attached nodes are given to the body once, at the first
/// finalize (rigid_body::add_attached_mass: mass, mass centre, parallel-axis inertia),
/// and gravity acts on the body's total mass at its mass centre.
/// Stable step: the body's own limit (rotation per step) and the springs on it,
///   Δt ≤ √(2 m_eff / Σ k),  m_eff the smallest effective mass over the attachment
///   points (rigid_body::effective_mass_at), Σ k the axial stiffness of every line
///   element ending on an attached node.
/// Because the forces on a node and on the body are equal and opposite and evaluated in
/// one configuration, linear and angular momentum of body + lines are conserved by the
/// combined leapfrog update (checked by a test).
///
/// References: Belytschko, Liu, Moran (2000) Nonlinear Finite Elements, §9 (rigid
///   bodies in explicit codes); LS-DYNA Keyword Manual, *CONSTRAINED_EXTRA_NODES.
#pragma once
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "nodes.hpp"
#include "rigid_body.hpp"

namespace parafsi::structure {

template <class Body = rigid_body>
class attachment {
 public:
  using body_type = Body;
  static constexpr bool is_body = true;
  static constexpr const char* name() { return "rigid_body"; }

  explicit attachment(Body body) : body_(std::move(body)) {}

  /// Tie node `node` to the body point r_body (from the body origin, body axes).
  void attach(index_t node, const Eigen::Vector3d& r_body) {
    require(r_body.allFinite(), "attachment::attach: non-finite body offset for node ", node);
    for (const auto& a : points_) require(a.node != node, "attachment::attach: node ", node, " is already attached");
    points_.push_back({node, r_body});
  }
  Body& body() noexcept { return body_; }
  const Body& body() const noexcept { return body_; }
  std::size_t size() const noexcept { return points_.size(); }
  /// Checkpoint (io/archive.hpp): the body's state (the attachment points are scene data).
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& self) {
    ar("body", self.body_);
  }

  void finalize(nodes& nd) {
    for (const auto& a : points_) {
      require(a.node >= 0 && a.node < nd.size(), "attachment: node id ", a.node, " outside [0, ", nd.size(), ")");
      nd.mark_attached(a.node);
    }
  }
  void post_finalize(nodes& nd) {
    if (!masses_given_) {
      for (const auto& a : points_) body_.add_attached_mass(nd.mass(a.node), a.r);
      masses_given_ = true;
    }
    place_nodes(nd);
  }

  /// x, v of every attached node from the body's pose.
  void place_nodes(nodes& nd) const {
    auto& s = nd.data();
    for (const auto& a : points_) {
      const Eigen::Vector3d x = body_.point_position(a.r), v = body_.point_velocity(a.r);
      s.get<field::x>()[a.node] = x.x();
      s.get<field::y>()[a.node] = x.y();
      s.get<field::z>()[a.node] = x.z();
      s.get<field::vx>()[a.node] = v.x();
      s.get<field::vy>()[a.node] = v.y();
      s.get<field::vz>()[a.node] = v.z();
    }
  }

  /// Hand the node forces and gravity to the body and advance it. Returns the work of
  /// gravity on the body over the kick (for the energy ledger).
  double step(const nodes& nd, const Eigen::Vector3d& g, double dt_kick, double dt) {
    body_.clear_loads();
    const Eigen::Vector3d fg = body_.mass() * g;
    body_.add_force(fg);
    for (const auto& a : points_) body_.add_force_at(nd.force(a.node), a.r);
    const Eigen::Vector3d p0 = body_.linear_momentum();
    body_.step(dt);
    const Eigen::Vector3d p1 = body_.linear_momentum();
    return dt_kick * fg.dot(0.5 * (p0 + p1) / body_.mass());
  }

  /// The start of a hold (assembly::hold): the body moves at V without spin from now on, and
  /// its nodes with it.
  void hold(nodes& nd, const Eigen::Vector3d& V) {
    body_.set_translation_velocity(V);
    place_nodes(nd);
  }
  /// The held step (assembly::hold): the body translates at V over dt whatever the
  /// node forces on it (rigid_body::translate); returns the external work, 0.
  double translate(const Eigen::Vector3d& V, double dt) {
    body_.translate(V, dt);
    return 0.0;
  }

  /// Body limit and the attachment-spring limit (ksum: Σ k_e per node).
  double critical_dt(const std::vector<double>& ksum) const {
    double dt = body_.critical_dt();
    double k = 0, meff = std::numeric_limits<double>::infinity();
    for (const auto& a : points_) {
      if (std::size_t(a.node) < ksum.size()) k += ksum[std::size_t(a.node)];
      meff = std::min(meff, body_.effective_mass_at(a.r));
    }
    if (k > 0) dt = std::min(dt, std::sqrt(2.0 * meff / k));
    return dt;
  }
  double kinetic_energy() const { return body_.kinetic_energy(); }
  Eigen::Vector3d linear_momentum() const { return body_.linear_momentum(); }
  Eigen::Vector3d angular_momentum() const { return body_.angular_momentum_world(); }

 private:
  struct point {
    index_t node;
    Eigen::Vector3d r;
  };
  Body body_;
  std::vector<point> points_;
  bool masses_given_ = false;
};

}  // namespace parafsi::structure
