/// \file rigid_body.hpp
/// Six-degree-of-freedom rigid payload (the paper's Eq. 6), explicit and
/// consistent with the central-difference (leapfrog) update of the structure nodes.
///
/// Equations (m mass, J inertia about the mass centre in body axes, R = R(q) maps
/// body to inertial components, ω_b body angular velocity, ω = R ω_b):
///   m Ẍ = Σ F                                   (gravity is one of the loads)
///   J ω̇_b + ω_b × (J ω_b) = M_b                 (Euler's equations, body frame)
///   q̇ = ½ q ⊗ (0, ω_b),  |q| = 1
/// equivalently, with the inertial angular momentum about the mass centre
///   L = R J ω_b,  L̇ = M = R M_b,  ω_b = J⁻¹ Rᵀ L.
///
/// Integrator (momenta at half steps, configuration at full steps; exp(θ) is the unit
/// quaternion (cos(|θ|/2), sin(|θ|/2) θ/|θ|)):
///   1. P^{n+½} = P^{n−½} + Δt̄ F^n,  X^{n+1} = X^n + Δt P^{n+½}/m
///   2. L^{n+½} = L^{n−½} + Δt̄ M^n     (M^n about the mass centre, pose at t^n)
///   3. mid-step attitude by fixed point, started from ω_b^{n−½}:
///        q^{n+½} = q^n ⊗ exp(½Δt ω_b),  ω_b ← J⁻¹ R(q^{n+½})ᵀ L^{n+½},  repeat
///      (at least 2 passes, then until ω_b stops changing at round-off: 3–5 passes
///      at |ω|Δt ≲ 1e-2)
///   4. q^{n+1} = q^n ⊗ exp(Δt ω_b^{n+½}), renormalised.
/// Δt̄ = ½(Δt^{n−1} + Δt^n) is the central-difference kick; on the first step
/// Δt^{n−1} = 0, so the first kick is the usual half kick P^{½} = P⁰ + ½Δt F⁰ and the
/// constructor's velocities are the values at t = 0.
///
/// Properties: a torque-free body keeps L (and |L| = |J ω_b|) exactly, since step 3
/// only rotates the body-frame momentum; the map is symmetric (time-reversible) once
/// the fixed point has converged, so the energy error is bounded, O((|ω|Δt)²), with no
/// drift; |q| = 1 to round-off by renormalisation.
///
/// Time levels seen through the accessors after a step from t^n to t^{n+1}:
/// position(), attitude(), rotation(), point_position() are at t^{n+1};
/// velocity(), angular velocities, momenta, point_velocity() and kinetic_energy()
/// are the half-step values at t^{n+½} (the same convention as the node velocities of
/// the central-difference update); point_velocity(r) equals the secant velocity
/// (x^{n+1} − x^n)/Δt of the body point up to a factor 1 − O((|ω|Δt)²).
///
/// Body frame: its origin O is the mass centre of the bare body given to the
/// constructor, and every `r_body` argument is measured from O. Lumped masses of
/// attached nodes (`add_attached_mass`) move the composite mass centre to c (body
/// frame) and add to the inertia by the parallel-axis theorem; the full inertia
/// tensor about the composite mass centre is then used. position() is the position
/// of O; mass_centre() is that of the composite mass centre. `add_force` acts at the
/// composite mass centre (so gravity m g there gives no moment).
///
/// References: Simo J.C., Wong K.K. (1991) IJNME 31:19–52; Buss S.R. (2000) JCP
///   164:377–406; Miller T.F. et al. (2002) J. Chem. Phys. 116:8649 ("NO_SQUISH");
///   Landau L.D., Lifshitz E.M., Mechanics §35–37 (Euler's equations, free top).
#pragma once
#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "../core/error.hpp"

namespace parafsi::structure {

/// Mass properties of the bare body about its mass centre, principal body axes.
struct rigid_body_properties {
  double mass;                       ///< kg, > 0
  Eigen::Vector3d inertia_diagonal;  ///< principal moments (kg m²), > 0, triangle inequality
};

/// Everything a rigid_body holds: set_state(state()) restarts bit for bit.
struct rigid_body_state {
  double mass = 0;                                             ///< total mass (kg)
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();           ///< about the mass centre, body axes
  Eigen::Vector3d com_body = Eigen::Vector3d::Zero();          ///< mass centre c from O, body axes
  Eigen::Vector3d x_com = Eigen::Vector3d::Zero();             ///< mass centre at t^n
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();       ///< attitude at t^n
  Eigen::Quaterniond q_half = Eigen::Quaterniond::Identity();  ///< attitude at t^{n−½}
  Eigen::Vector3d p = Eigen::Vector3d::Zero();                 ///< linear momentum at t^{n−½}
  Eigen::Vector3d l = Eigen::Vector3d::Zero();                 ///< spin angular momentum at t^{n−½}
  Eigen::Vector3d omega_body = Eigen::Vector3d::Zero();        ///< ω_b at t^{n−½}
  Eigen::Vector3d force_com = Eigen::Vector3d::Zero();         ///< pending loads: forces at the mass centre
  Eigen::Vector3d force_points = Eigen::Vector3d::Zero();      ///< forces at body points
  Eigen::Vector3d moment_origin = Eigen::Vector3d::Zero();     ///< their moments about O + torques
  double dt_prev = 0;                                          ///< previous step (0: not started)
  double time = 0;                                             ///< sum of the steps taken (s)
  long steps = 0;                                              ///< number of steps taken
};

class rigid_body {
 public:
  /// Largest rotation per step (rad) allowed by critical_dt().
  static constexpr double max_rotation_per_step = 0.1;

  /// Uniform solid box of the given edge lengths (body axes along the edges).
  static rigid_body_properties cuboid(double mass, const Eigen::Vector3d& size) {
    require(std::isfinite(mass) && mass > 0, "rigid_body::cuboid: mass must be positive, got ", mass);
    for (int i = 0; i < 3; ++i)
      require(std::isfinite(size[i]) && size[i] > 0, "rigid_body::cuboid: edge length along ", axis_name(i),
              " must be positive, got ", size[i]);
    const Eigen::Vector3d s2 = size.cwiseProduct(size);
    return {mass, Eigen::Vector3d(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y()) * (mass / 12.0)};
  }

  /// Throws invalid_input unless the properties describe a physical rigid body.
  static void validate(const rigid_body_properties& props) {
    require(std::isfinite(props.mass) && props.mass > 0, "rigid_body: mass must be positive, got ", props.mass);
    const Eigen::Vector3d& I = props.inertia_diagonal;
    for (int i = 0; i < 3; ++i)
      require(std::isfinite(I[i]) && I[i] > 0, "rigid_body: principal moment of inertia I", axis_name(i),
              " must be positive, got ", I[i]);
    // Principal moments of a real mass distribution obey I_i <= I_j + I_k (equality
    // for a lamina); allow round-off in the user's arithmetic.
    const double tol = 1e-12 * I.sum();
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3, k = (i + 2) % 3;
      require(I[i] <= I[j] + I[k] + tol, "rigid_body: principal moments violate the triangle inequality: I",
              axis_name(i), " = ", I[i], " > I", axis_name(j), " + I", axis_name(k), " = ", I[j], " + ", I[k]);
    }
  }

  rigid_body(rigid_body_properties props, Eigen::Vector3d position,
             Eigen::Quaterniond attitude = Eigen::Quaterniond::Identity(),
             Eigen::Vector3d velocity = Eigen::Vector3d::Zero(), Eigen::Vector3d omega_body = Eigen::Vector3d::Zero()) {
    validate(props);
    require(position.allFinite(), "rigid_body: position must be finite, got (", position.transpose(), ")");
    require(attitude.coeffs().allFinite() && attitude.norm() > 0,
            "rigid_body: attitude quaternion must be finite and non-zero, got (w,x,y,z) = (", attitude.w(), ", ",
            attitude.x(), ", ", attitude.y(), ", ", attitude.z(), ")");
    require(velocity.allFinite(), "rigid_body: velocity must be finite, got (", velocity.transpose(), ")");
    require(omega_body.allFinite(), "rigid_body: body angular velocity must be finite, got (", omega_body.transpose(),
            ")");
    s_.mass = props.mass;
    s_.inertia = props.inertia_diagonal.asDiagonal();
    s_.x_com = position;
    s_.q = attitude.normalized();
    s_.q_half = s_.q;
    s_.p = props.mass * velocity;
    s_.omega_body = omega_body;
    s_.l = s_.q * (s_.inertia * omega_body);
    update_inverse();
  }

  // ---- pose and kinematics -------------------------------------------------------
  /// Position of the body-frame origin O (mass centre of the bare body), t^n.
  Eigen::Vector3d position() const { return point_position(Eigen::Vector3d::Zero()); }
  /// Composite mass centre (equals position() unless attached masses moved it), t^n.
  Eigen::Vector3d mass_centre() const { return s_.x_com; }
  Eigen::Quaterniond attitude() const { return s_.q; }
  Eigen::Matrix3d rotation() const { return s_.q.toRotationMatrix(); }
  /// Velocity of O, t^{n−½}.
  Eigen::Vector3d velocity() const { return point_velocity(Eigen::Vector3d::Zero()); }
  /// Velocity of the composite mass centre, t^{n−½}.
  Eigen::Vector3d mass_centre_velocity() const { return s_.p / s_.mass; }
  Eigen::Vector3d angular_velocity_world() const { return s_.q_half * s_.omega_body; }
  Eigen::Vector3d angular_velocity_body() const { return s_.omega_body; }
  /// X + R r: inertial position of the body point r (from O, body axes), t^n.
  Eigen::Vector3d point_position(const Eigen::Vector3d& r_body) const {
    return s_.x_com + s_.q * (r_body - s_.com_body);
  }
  /// V + ω × (R r) of the body point r, t^{n−½} (mid-step attitude).
  Eigen::Vector3d point_velocity(const Eigen::Vector3d& r_body) const {
    return s_.p / s_.mass + angular_velocity_world().cross(s_.q_half * (r_body - s_.com_body));
  }

  // ---- loads (accumulate until clear_loads(); step() does not clear them) ----------
  void clear_loads() {
    s_.force_com.setZero();
    s_.force_points.setZero();
    s_.moment_origin.setZero();
  }
  /// Force at the composite mass centre (no moment), inertial components.
  void add_force(const Eigen::Vector3d& f_world) { s_.force_com += f_world; }
  /// Force at the body point r: adds f and the moment (R (r − c)) × f about the mass centre.
  void add_force_at(const Eigen::Vector3d& f_world, const Eigen::Vector3d& r_body) {
    s_.force_points += f_world;
    s_.moment_origin += (s_.q * r_body).cross(f_world);
  }
  /// Pure torque (inertial components).
  void add_torque(const Eigen::Vector3d& m_world) { s_.moment_origin += m_world; }
  /// Total applied force (inertial).
  Eigen::Vector3d force() const { return s_.force_com + s_.force_points; }
  /// Total applied moment about the composite mass centre (inertial), at the current pose.
  Eigen::Vector3d moment() const { return s_.moment_origin - (s_.q * s_.com_body).cross(s_.force_points); }

  /// Attach a lumped mass m (e.g. of a node tied to the body) at body point r. The
  /// body's kinematic state (velocity of O, angular velocity) is kept, so the mass
  /// joins moving with the body; mass, mass centre and inertia (parallel-axis theorem,
  /// full tensor about the new mass centre) are updated. Meant for set-up.
  void add_attached_mass(double m, const Eigen::Vector3d& r_body) {
    require(std::isfinite(m) && m >= 0, "rigid_body::add_attached_mass: mass must be non-negative, got ", m);
    require(r_body.allFinite(), "rigid_body::add_attached_mass: offset must be finite, got (", r_body.transpose(), ")");
    if (m == 0) return;
    const Eigen::Vector3d v_origin = velocity();
    const Eigen::Vector3d omega_w = angular_velocity_world();
    const Eigen::Vector3d x_origin = position();
    const double m_old = s_.mass, m_new = m_old + m;
    const Eigen::Vector3d c_old = s_.com_body;
    const Eigen::Vector3d c_new = (m_old * c_old + m * r_body) / m_new;
    // Inertia about the new mass centre: shift the old tensor, add the point mass.
    s_.inertia = s_.inertia + point_inertia(m_old, c_old - c_new) + point_inertia(m, r_body - c_new);
    s_.mass = m_new;
    s_.com_body = c_new;
    update_inverse();
    s_.x_com = x_origin + s_.q * c_new;
    s_.p = m_new * (v_origin + omega_w.cross(s_.q_half * c_new));
    s_.omega_body = s_.q_half.conjugate() * omega_w;
    s_.l = s_.q_half * (s_.inertia * s_.omega_body);
  }

  // ---- time step ------------------------------------------------------------------
  /// One leapfrog step of length dt with the accumulated loads (see the file comment).
  void step(double dt) {
    require(std::isfinite(dt) && dt > 0, "rigid_body::step: time step must be positive, got ", dt);
    const Eigen::Vector3d F = force();
    const Eigen::Vector3d M = moment();
    if (!F.allFinite() || !M.allFinite())
      throw numerical_failure(detail::concat("rigid_body::step: non-finite load at t = ", s_.time, ": force (",
                                             F.transpose(), "), moment (", M.transpose(), ")"),
                              -1, s_.time);
    const double kick = 0.5 * (s_.dt_prev + dt);

    // 1.-2. Kicks and drift of the mass centre.
    s_.p += kick * F;
    s_.l += kick * M;
    s_.x_com += (dt / s_.mass) * s_.p;

    // 3. Mid-step body angular velocity by fixed point. The body-frame momentum at
    // t^n is rotated back by half the step: R(q^{n+½})ᵀ L = exp(½Δt ω_b)ᵀ R(q^n)ᵀ L.
    const Eigen::Vector3d pi_n = s_.q.conjugate() * s_.l;
    Eigen::Vector3d w = s_.omega_body;
    Eigen::Quaterniond half;
    const double scale = std::max(w.norm(), (inertia_inv_ * pi_n).norm());
    double change = std::numeric_limits<double>::infinity();
    for (int it = 1;; ++it) {
      half = exp_map(0.5 * dt * w);
      const Eigen::Vector3d w_new = inertia_inv_ * (half.conjugate() * pi_n);
      const double previous = change;
      change = (w_new - w).norm();
      w = w_new;
      // Converged, or stalled at the round-off floor (the contraction is monotone).
      if (it >= min_iterations && (change <= converged_tolerance * scale || change >= previous)) break;
      if (it >= max_iterations) break;
    }
    if (!(change <= 1e-8 * scale + std::numeric_limits<double>::min()))
      throw numerical_failure(detail::concat("rigid_body::step: mid-step attitude did not converge at t = ", s_.time,
                                             " (|omega| dt = ", w.norm() * dt, " rad, change ", change,
                                             "); use a step below critical_dt() = ", critical_dt()),
                              -1, s_.time);
    half = exp_map(0.5 * dt * w);

    // 4. Attitude update by the exponential map, then renormalise.
    s_.q_half = (s_.q * half).normalized();
    s_.q = (s_.q * exp_map(dt * w)).normalized();
    s_.omega_body = w;
    s_.dt_prev = dt;
    s_.time += dt;
    ++s_.steps;

    if (!s_.x_com.allFinite() || !s_.p.allFinite() || !s_.l.allFinite() || !s_.q.coeffs().allFinite() || !w.allFinite())
      throw numerical_failure(detail::concat("rigid_body::step: state became non-finite at t = ", s_.time,
                                             ": position (", s_.x_com.transpose(), "), momentum (", s_.p.transpose(),
                                             "), angular momentum (", s_.l.transpose(), ")"),
                              -1, s_.time);
  }

  /// The velocity of a held body (structure::assembly::hold): P = m V, no spin (L = ω_b = 0,
  /// the mid-step attitude the attitude), the pose kept.
  void set_translation_velocity(const Eigen::Vector3d& V) {
    require(V.allFinite(), "rigid_body::set_translation_velocity: non-finite velocity (", V.transpose(), ")");
    s_.p = s_.mass * V;
    s_.l.setZero();
    s_.omega_body.setZero();
    s_.q_half = s_.q;
  }
  /// A step of length dt as a rigid translation at the velocity V, whatever the loads:
  /// the mass centre moves by V dt, the attitude stays, P = m V and L = ω_b = 0 (the
  /// body held captive, structure::assembly::hold). The pending loads are cleared.
  void translate(const Eigen::Vector3d& V, double dt) {
    require(std::isfinite(dt) && dt > 0, "rigid_body::translate: time step must be positive, got ", dt);
    require(V.allFinite(), "rigid_body::translate: non-finite velocity (", V.transpose(), ")");
    clear_loads();
    s_.x_com += dt * V;
    set_translation_velocity(V);
    s_.dt_prev = dt;
    s_.time += dt;
    ++s_.steps;
  }

  /// Rotational limit: the body may turn at most max_rotation_per_step (0.1 rad) per
  /// step, Δt ≤ 0.1/|ω|. The rate of change of ω_b in the body frame is at most |ω|²
  /// (|J_j − J_k| ≤ J_i), so this also keeps the fixed point strongly contracting.
  /// A body at rest imposes no limit: +infinity (take the minimum over all parts; the
  /// translational and attachment limits belong to the springs acting on the body, see
  /// effective_mass_at()).
  double critical_dt() const {
    const double w = s_.omega_body.norm();
    return w > 0 ? max_rotation_per_step / w : std::numeric_limits<double>::infinity();
  }

  // ---- mass properties ------------------------------------------------------------
  double mass() const { return s_.mass; }
  /// Inertia tensor about the composite mass centre in body axes (diagonal unless
  /// attached masses made it otherwise).
  Eigen::Matrix3d inertia_body() const { return s_.inertia; }
  /// Composite mass centre c measured from O, body axes.
  Eigen::Vector3d mass_centre_body() const { return s_.com_body; }
  /// Smallest effective mass of the body point r over all directions n:
  /// 1/m_eff(n) = 1/m + (ρ×n)·J_w⁻¹(ρ×n), ρ = R(r − c). A spring of stiffness k
  /// attached there needs Δt ≤ 2 √(m_eff/k).
  double effective_mass_at(const Eigen::Vector3d& r_body) const {
    const Eigen::Matrix3d R = rotation();
    const Eigen::Vector3d rho = R * (r_body - s_.com_body);
    Eigen::Matrix3d S;
    S << 0, -rho.z(), rho.y(), rho.z(), 0, -rho.x(), -rho.y(), rho.x(), 0;
    const Eigen::Matrix3d Jinv_w = R * inertia_inv_ * R.transpose();
    const Eigen::Matrix3d Minv = Eigen::Matrix3d::Identity() / s_.mass - S * Jinv_w * S;
    const double lmax =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(Minv, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
    return 1.0 / lmax;
  }

  // ---- invariants (half-step values) ----------------------------------------------
  /// ½|P|²/m + ½ ω_b·J ω_b.
  double kinetic_energy() const {
    return 0.5 * s_.p.squaredNorm() / s_.mass + 0.5 * s_.omega_body.dot(s_.inertia * s_.omega_body);
  }
  Eigen::Vector3d linear_momentum() const { return s_.p; }
  /// About the inertial origin: X_c × P + L (orbital + spin; X_c at t^n, P and L at t^{n−½}).
  Eigen::Vector3d angular_momentum_world() const { return s_.x_com.cross(s_.p) + s_.l; }
  /// About the mass centre (inertial components).
  Eigen::Vector3d spin_angular_momentum_world() const { return s_.l; }

  /// Sum of the steps taken since construction (s).
  double time() const { return s_.time; }
  long steps() const { return s_.steps; }

  // ---- checkpoint -----------------------------------------------------------------
  const rigid_body_state& state() const { return s_; }
  void set_state(const rigid_body_state& s) {
    require(std::isfinite(s.mass) && s.mass > 0, "rigid_body::set_state: mass must be positive, got ", s.mass);
    require(s.inertia.allFinite() && s.inertia.isApprox(s.inertia.transpose()),
            "rigid_body::set_state: inertia must be a finite symmetric tensor");
    const Eigen::Vector3d eig =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(s.inertia, Eigen::EigenvaluesOnly).eigenvalues();
    require(eig.minCoeff() > 0, "rigid_body::set_state: inertia must be positive definite, smallest moment ",
            eig.minCoeff());
    require(s.x_com.allFinite() && s.p.allFinite() && s.l.allFinite() && s.omega_body.allFinite() &&
                s.q.coeffs().allFinite() && s.q_half.coeffs().allFinite() && s.com_body.allFinite(),
            "rigid_body::set_state: state must be finite");
    require(std::isfinite(s.dt_prev) && s.dt_prev >= 0, "rigid_body::set_state: dt_prev must be >= 0, got ", s.dt_prev);
    s_ = s;
    update_inverse();
  }
  /// Checkpoint (io/archive.hpp): every field of state(); a load goes through set_state.
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& self) {
    rigid_body_state s = self.state();
    ar("mass", s.mass);
    ar("inertia", s.inertia);
    ar("com_body", s.com_body);
    ar("x_com", s.x_com);
    ar("q", s.q);
    ar("q_half", s.q_half);
    ar("p", s.p);
    ar("l", s.l);
    ar("omega_body", s.omega_body);
    ar("force_com", s.force_com);
    ar("force_points", s.force_points);
    ar("moment_origin", s.moment_origin);
    ar("dt_prev", s.dt_prev);
    ar("time", s.time);
    ar("steps", s.steps);
    if constexpr (Archive::loading) self.set_state(s);
  }

  /// exp(θ) = (cos(|θ|/2), sin(|θ|/2) θ/|θ|), the unit quaternion of the rotation vector θ.
  static Eigen::Quaterniond exp_map(const Eigen::Vector3d& theta) {
    const double a = theta.norm();
    if (a == 0) return Eigen::Quaterniond::Identity();
    const double s = std::sin(0.5 * a) / a;
    return Eigen::Quaterniond(std::cos(0.5 * a), s * theta.x(), s * theta.y(), s * theta.z());
  }

 private:
  static constexpr char axis_name(int i) { return "xyz"[i]; }
  static constexpr int min_iterations = 2;
  static constexpr int max_iterations = 50;
  static constexpr double converged_tolerance = 1e-15;

  static Eigen::Matrix3d point_inertia(double m, const Eigen::Vector3d& r) {
    return m * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
  }
  void update_inverse() {
    const bool diagonal = s_.inertia.isDiagonal(0.0);
    inertia_inv_ = diagonal ? Eigen::Matrix3d(s_.inertia.diagonal().cwiseInverse().asDiagonal())
                            : Eigen::Matrix3d(s_.inertia.inverse());
  }

  rigid_body_state s_;
  Eigen::Matrix3d inertia_inv_ = Eigen::Matrix3d::Identity();
};

}  // namespace parafsi::structure
