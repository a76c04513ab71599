/// \file assembly.hpp
/// `structure::assembly<Parts...>`: parts (membranes, cables/tapes, rigid bodies with
/// attached nodes) sharing one node set, advanced by the central-difference update.
///
/// One substep (methods §8.3, step 3):
///   place_attached_nodes → clear_forces (f = m g) → external loads (coupling hook)
///   → compute_element_forces (every element part, race-free) → scatter_element_forces
///   → step_bodies (node forces → body force + moment, body leapfrog)
///   → update_nodes (kick/drift) → check (numerical_failure naming node, element, time);
/// held (`hold(V)`, a captive structure): the loads and element forces as above, then
/// every body and node translates at V (step_bodies and update_nodes replaced); with
/// `hold(V, hold_scope::bodies)` only step_bodies is replaced (a canopy on a held payload).
/// `advance(Δt_f)` runs m = ceil(Δt_f/Δt_s,crit) equal substeps inside one fluid step,
/// Δt_s,crit = TSSF · min(membrane element limits, nodal line limits, body limits).
///
/// "Off" is a type: the fold runs over exactly the declared parts, so an assembly
/// without cables or without a rigid body holds no cable or body storage and has no
/// cable or body pass (`has_cables`, `has_body`, checked by a static test).
///
/// Part concept (what the fold calls): element parts provide `finalize(nodes&)`,
/// `compute_forces<Track>(node_kinematics)`, `scatter<Track>(nodes&)`,
/// `critical_dt(const nodes&)`, `strain_energy()`, `first_bad_element()` and
/// optionally `post_finalize(const nodes&)`, `add_node_stiffness(vector&)`,
/// `damping_ratio()`; body parts (`is_body = true`) provide `finalize`,
/// `post_finalize`, `place_nodes`, `step`, `hold(nodes, V)`, `translate(V, dt)`, `critical_dt(ksum)` and
/// momenta/energy.
#pragma once
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "../core/error.hpp"
#include "../core/simd.hpp"
#include "central_difference.hpp"
#include "energy.hpp"
#include "nodes.hpp"

namespace parafsi::structure {

template <class P>
concept body_part = requires {
  P::is_body;
}
&&P::is_body;
template <class P>
concept line_part = requires(const P& p, std::vector<double>& k) {
  p.add_node_stiffness(k);
};

/// Adds coupling / user loads to nodes; when energy is tracked they count as external work.
class load_sink {
 public:
  load_sink(nodes& nd, bool track) : s_(nd.data()), track_(track) {}
  void add(index_t i, const Eigen::Vector3d& f) {
    s_.get<field::fx>()[i] += f.x();
    s_.get<field::fy>()[i] += f.y();
    s_.get<field::fz>()[i] += f.z();
    if (track_) {
      s_.get<field::fex>()[i] += f.x();
      s_.get<field::fey>()[i] += f.y();
      s_.get<field::fez>()[i] += f.z();
    }
  }

 private:
  nodes::storage& s_;
  bool track_;
};

struct no_loads {
  void operator()(load_sink&, double) const noexcept {}
};

template <class... Parts>
class assembly {
 public:
  using parts_type = std::tuple<Parts...>;
  static constexpr std::size_t part_count = sizeof...(Parts);
  static constexpr std::size_t body_count = (std::size_t(0) + ... + std::size_t(body_part<Parts>));
  static constexpr std::size_t line_count = (std::size_t(0) + ... + std::size_t(line_part<Parts>));
  static constexpr bool has_body = body_count > 0;
  static constexpr bool has_cables = line_count > 0;

  /// Parts in any order; integrator settings (gravity, mass damping, TSSF) through
  /// integrator().
  explicit assembly(nodes nd, Parts... parts) : nodes_(std::move(nd)), parts_(std::move(parts)...) {}

  // ------------------------------------------------------------------ access
  nodes& node_set() noexcept { return nodes_; }
  const nodes& node_set() const noexcept { return nodes_; }
  template <std::size_t I>
  auto& part() noexcept {
    return std::get<I>(parts_);
  }
  template <std::size_t I>
  const auto& part() const noexcept {
    return std::get<I>(parts_);
  }
  central_difference& integrator() noexcept { return cd_; }
  double time() const noexcept { return t_; }
  long steps() const noexcept { return steps_; }
  /// Composed name, e.g. "assembly<membrane_tri, cable, rigid_body>".
  static std::string name() {
    std::string s = "assembly<";
    bool first = true;
    ((s += (first ? "" : ", "), s += Parts::name(), first = false), ...);
    return s + ">";
  }

  // ------------------------------------------------------------------ set-up
  /// Validate parts, lump masses, build scatter maps and time-step data. Called
  /// automatically by the first step and after any constraint change.
  void finalize() {
    nodes_.materialize();
    nodes_.reset_masses();
    std::apply([&](auto&... p) { (p.finalize(nodes_), ...); }, parts_);
    nodes_.finalize_masses();
    std::apply(
        [&](auto&... p) {
      (
          (void)[&] {
            if constexpr (requires { p.post_finalize(nodes_); }) p.post_finalize(nodes_);
          }(),
          ...);
        },
        parts_);
    ksum_.assign(std::size_t(nodes_.size()), 0.0);
    double xi = 0;
    std::apply(
        [&](auto&... p) {
      (
          (void)[&] {
            if constexpr (line_part<std::remove_cvref_t<decltype(p)>>) {
              p.add_node_stiffness(ksum_);
              xi = std::max(xi, p.damping_ratio());
            }
          }(),
          ...);
        },
        parts_);
    dt_nodal_ = std::numeric_limits<double>::infinity();
    for (index_t i = 0; i < nodes_.size(); ++i)
      if (nodes_.kind(i) == constraint::free && ksum_[std::size_t(i)] > 0)
        dt_nodal_ = std::min(dt_nodal_, std::sqrt(2.0 * nodes_.mass(i) / ksum_[std::size_t(i)]));
    dt_nodal_ *= std::sqrt(1.0 + xi * xi) - xi;
    nodes_.mark_finalized();
  }

  // ------------------------------------------------------------------ time step
  /// Largest stable substep, TSSF · min over parts (s).
  double stable_dt() {
    if (nodes_.needs_finalize()) finalize();
    double dt = dt_nodal_;
    std::apply(
        [&](auto&... p) {
      (
          (void)[&] {
            if constexpr (body_part<std::remove_cvref_t<decltype(p)>>) dt = std::min(dt, p.critical_dt(ksum_));
            else dt = std::min(dt, p.critical_dt(nodes_));
          }(),
          ...);
        },
        parts_);
    return cd_.tssf * dt;
  }

  /// What hold() holds: the whole structure, or its rigid bodies only.
  enum class hold_scope { structure, bodies };
  /// Hold the structure captive: from the next substep on, every node and body moves as
  /// one rigid translation at the velocity V (nodes x += V Δt, v = V whatever their
  /// constraint; bodies rigid_body::translate), so the shape of now is kept exactly. The
  /// loads (the load hook, element forces) are still evaluated each substep, so what a
  /// caller reads from them (a coupling's impulses on the cloth) is what the held shape
  /// feels; nothing responds to them. The same structure in a stream: a fixed canopy in
  /// the drop's air (scene::drop_config::captive_speed).
  /// With hold_scope::bodies only the rigid bodies translate at V (attitude kept); the
  /// nodes they carry follow them and every other node moves under its loads as before: a
  /// canopy on a held payload, free to breathe and to turn about its lines, as in a wind
  /// tunnel (the other nodes keep their velocities: a start that differs from V is
  /// impulsive). The bodies (and with hold_scope::structure every node) take the velocity V
  /// at once. While held, the energy ledger's external work leaves out the work of the hold
  /// (what holds the structure does work on it), so its balance() is not conserved. Not
  /// saved by a checkpoint: hold again after a load. release_hold() returns to the free
  /// update.
  void hold(const Eigen::Vector3d& V, hold_scope scope = hold_scope::structure) {
    require(V.allFinite(), "assembly::hold: non-finite velocity (", V.transpose(), ")");
    if (nodes_.needs_finalize()) finalize();
    held_ = true;
    hold_scope_ = scope;
    hold_velocity_ = V;
    std::apply(
        [&](auto&... p) {
      (
          (void)[&] {
            if constexpr (body_part<std::remove_cvref_t<decltype(p)>>) p.hold(nodes_, V);
          }(),
          ...);
        },
        parts_);
    if (scope == hold_scope::bodies) return;
    auto& s = nodes_.data();
    for (index_t i = 0; i < nodes_.size(); ++i) {
      s.template get<field::vx>()[i] = V.x();
      s.template get<field::vy>()[i] = V.y();
      s.template get<field::vz>()[i] = V.z();
    }
  }
  void release_hold() noexcept { held_ = false; }
  bool held() const noexcept { return held_; }
  hold_scope held_scope() const noexcept { return hold_scope_; }
  const Eigen::Vector3d& hold_velocity() const noexcept { return hold_velocity_; }

  /// Advance by dt_outer in m = ceil(dt_outer/stable_dt()) equal substeps; returns m.
  template <class Loads = no_loads>
  long advance(double dt_outer, Loads&& loads = {}) {
    const long m = central_difference::substeps(dt_outer, stable_dt());
    const double dt = dt_outer / double(m);
    for (long k = 0; k < m; ++k) step(dt, loads);
    return m;
  }

  /// One substep of length dt. `loads(load_sink&, t)` may add external nodal forces.
  template <class Loads = no_loads>
  void step(double dt, Loads&& loads = {}) {
    require(dt > 0 && std::isfinite(dt), "assembly::step: time step must be > 0, got ", dt);
    cd_.validate();
    if (nodes_.needs_finalize()) finalize();
    if (track_) substep<true>(dt, loads);
    else substep<false>(dt, loads);
  }

  // ------------------------------------------------------------------ diagnostics
  /// Start energy bookkeeping (resets damping and external work to zero).
  void track_energy(bool on = true) {
    track_ = on;
    ledger_ = {};
    if (on) {
      if (nodes_.needs_finalize()) finalize();
      ledger_.kinetic = kinetic_energy();
    }
  }
  const energy_ledger& energy() const noexcept { return ledger_; }

  /// ½ Σ m|v|² over free nodes + rigid bodies (velocities at the last half step).
  double kinetic_energy() const {
    const auto& s = nodes_.data();
    const double* vx = s.get<field::vx>();
    const double* vy = s.get<field::vy>();
    const double* vz = s.get<field::vz>();
    const double* m = s.get<field::m>();
    const double* mi = s.get<field::minv>();
    double k = 0;
    for (index_t i = 0; i < nodes_.size(); ++i)
      if (mi[i] > 0) k += 0.5 * m[i] * (vx[i] * vx[i] + vy[i] * vy[i] + vz[i] * vz[i]);
    for_each_body([&](const auto& b) { k += b.kinetic_energy(); });
    return k;
  }
  /// Σ m v over free nodes + bodies.
  Eigen::Vector3d linear_momentum() const {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (index_t i = 0; i < nodes_.size(); ++i)
      if (nodes_.kind(i) == constraint::free) p += nodes_.mass(i) * nodes_.velocity(i);
    for_each_body([&](const auto& b) { p += b.linear_momentum(); });
    return p;
  }
  /// Σ m x × v over free nodes + bodies' angular momentum, about the origin.
  Eigen::Vector3d angular_momentum() const {
    Eigen::Vector3d l = Eigen::Vector3d::Zero();
    for (index_t i = 0; i < nodes_.size(); ++i)
      if (nodes_.kind(i) == constraint::free) l += nodes_.mass(i) * nodes_.position(i).cross(nodes_.velocity(i));
    for_each_body([&](const auto& b) { l += b.angular_momentum(); });
    return l;
  }

  template <class F>
  void for_each_body(F&& f) const {
    std::apply(
        [&](const auto&... p) {
      (
          (void)[&] {
            if constexpr (body_part<std::remove_cvref_t<decltype(p)>>) f(p);
          }(),
          ...);
        },
        parts_);
  }

  // ------------------------------------------------------------------ checkpoint
  /// Length of the last substep (0 before the first): the next kick is ½(previous + Δt).
  double previous_step() const noexcept { return dt_prev_; }
  bool tracking_energy() const noexcept { return track_; }
  /// Restore the clock of a checkpointed run (io/checkpoint.hpp): time, substep count,
  /// last substep length and energy bookkeeping. Nodes, element loads and bodies are
  /// restored through their own accessors.
  void restore_clock(double t, long steps, double previous_step, bool track, const energy_ledger& ledger) {
    require(std::isfinite(t) && steps >= 0 && std::isfinite(previous_step) && previous_step >= 0,
            "assembly::restore_clock: need finite t, steps >= 0 and previous step >= 0, got t = ", t,
            ", steps = ", steps, ", previous step = ", previous_step);
    t_ = t;
    steps_ = steps;
    dt_prev_ = previous_step;
    track_ = track;
    ledger_ = ledger;
  }

  /// Forces at the current state without advancing (phases 1–3 of a substep): the
  /// node force arrays then hold f = m g + external + element forces. For tests,
  /// diagnostics and coupling set-up. Returns the strain energy.
  template <class Loads = no_loads>
  double evaluate_forces(Loads&& loads = {}) {
    if (nodes_.needs_finalize()) finalize();
    return compute_phase<true>(loads);
  }

  /// Checkpoint (io/archive.hpp; Self = const assembly on save, assembly on load). In
  /// order: the signature (type, node count, each part's name and element count); the
  /// constraint kinds and point masses (nodes::serialize), after which a load finalizes
  /// the scene if needed; a digest of each element part's connectivity, rest lengths and
  /// reference areas (scene data, compared); the node arrays by tag name (x … fez,
  /// padding included); each part's own state (its serialize: membrane pressures, rigid
  /// bodies); the integrator settings; the clock and the energy ledger. Elements hold
  /// no other history (total-Lagrangian membranes, elastic + damped cables).
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& self) {
    if constexpr (Archive::saving)
      require(!self.nodes_.needs_finalize(),
              "io::save_checkpoint: the assembly is not finalized (call finalize() or step first)");
    auto each_part = [&](auto&& f) {
      [&]<std::size_t... I>(std::index_sequence<I...>) {
        (f(std::string("part") + std::to_string(I), std::get<I>(self.parts_)), ...);
      }
      (std::make_index_sequence<part_count>{});
    };
    const index_t N = self.nodes_.size();
    ar.check("type", name(), "the assembly type");
    ar.check("nodes", N, "the node count");
    ar.check("field_length", std::int64_t(simd::padded(std::size_t(N)) + simd::width),
             "the node field length (SIMD padding; another SIMD width?)");
    each_part([&](const std::string& k, auto& p) {
      ar.check(k + ".name", std::string(p.name()), k);
      if constexpr (requires { p.element(index_t(0)); })
        ar.check(k + ".elements", p.size(), k + " (" + p.name() + ") element count");
    });
    ar("nodes", self.nodes_);
    if constexpr (Archive::loading)
      if (self.nodes_.needs_finalize()) self.finalize();  // masses, scatter maps, reference geometry
    each_part([&](const std::string& k, auto& p) {
      if constexpr (requires { p.element(index_t(0)); })
        ar.check_digest(k + ".reference", k + " (" + p.name() + "): connectivity, rest lengths or reference areas",
                        [&](auto put) {
          for (index_t e = 0; e < p.size(); ++e) {
            for (auto n : p.element(e)) put(n);
            if constexpr (requires { p.rest_length(e); }) put(p.rest_length(e));
            if constexpr (requires { p.reference_area(e); }) put(p.reference_area(e));
          }
        });
    });
    ar.fields("node", self.nodes_.data());
    each_part([&](const std::string& k, auto& p) {
      using P = std::remove_cvref_t<decltype(p)>;
      if constexpr (requires { P::serialize(ar, p); }) ar(k, p);
    });
    ar("gravity", self.cd_.gravity);
    ar("mass_damping", self.cd_.mass_damping);
    ar("tssf", self.cd_.tssf);
    ar("time", self.t_);
    ar("steps", self.steps_);
    ar("previous_step", self.dt_prev_);
    ar("track_energy", self.track_);
    ar("energy.kinetic", self.ledger_.kinetic);
    ar("energy.strain", self.ledger_.strain);
    ar("energy.damping", self.ledger_.damping);
    ar("energy.external", self.ledger_.external);
    if constexpr (Archive::loading)
      if (self.steps_ < 0 || self.dt_prev_ < 0)
        ar.fail("the clock holds ", self.steps_, " steps and a previous step of ", self.dt_prev_, " s");
  }

 private:
  template <bool Track, class Loads>
  double compute_phase(Loads& loads) {
    // Phase 1. Attached nodes from the body poses.
    std::apply(
        [&](auto&... p) {
      (
          (void)[&] {
            if constexpr (body_part<std::remove_cvref_t<decltype(p)>>) p.place_nodes(nodes_);
          }(),
          ...);
        },
        parts_);
    // Phase 2. Body loads and external loads.
    cd_.template clear_forces<Track>(nodes_);
    {
      load_sink sink(nodes_, Track);
      loads(sink, t_);
    }
    // Phase 3. Element forces (membranes, cables, tapes), then race-free scatter.
    const node_kinematics kin = nodes_.kinematics();
    double strain = 0;  // filled when Track
    std::apply(
        [&](auto&... p) {
      (
          (void)[&] {
            if constexpr (!body_part<std::remove_cvref_t<decltype(p)>>) {
              p.template compute_forces<Track>(kin);
              p.template scatter<Track>(nodes_);
              if constexpr (Track) strain += p.strain_energy();
            }
          }(),
          ...);
        },
        parts_);
    return strain;
  }

  template <bool Track, class Loads>
  void substep(double dt, Loads& loads) {
    const double dt_kick = 0.5 * (dt_prev_ + dt);
    const double strain = compute_phase<Track>(loads);
    if (held_ && hold_scope_ == hold_scope::structure) {
      held_update(dt);
      if constexpr (Track) {
        ledger_.kinetic = kinetic_energy();
        ledger_.strain = strain;
      }
      t_ += dt;
      dt_prev_ = dt;
      ++steps_;
      return;
    }
    // Phase 4. Rigid bodies.
    double w_body = 0;
    std::apply(
        [&](auto&... p) {
      (
          (void)[&] {
            if constexpr (body_part<std::remove_cvref_t<decltype(p)>>)
              w_body += held_ ? p.translate(hold_velocity_, dt) : p.step(nodes_, cd_.gravity, dt_kick, dt);
          }(),
          ...);
        },
        parts_);
    // Phase 5. Central-difference update of the nodes.
    const auto r = cd_.template update<Track>(nodes_, dt_kick, dt);
    if (r.bad_node >= 0) fail(r.bad_node);
    if constexpr (Track) {
      double kb = 0;
      for_each_body([&](const auto& b) { kb += b.kinetic_energy(); });
      ledger_.kinetic = r.kinetic + kb;
      ledger_.strain = strain;
      ledger_.damping += r.damping;
      ledger_.external += r.external + w_body;
    }
    t_ += dt;
    dt_prev_ = dt;
    ++steps_;
  }

  /// Phases 4–5 of a held substep (hold()): bodies and nodes translate at V.
  void held_update(double dt) {
    std::apply(
        [&](auto&... p) {
      (
          (void)[&] {
            if constexpr (body_part<std::remove_cvref_t<decltype(p)>>) p.translate(hold_velocity_, dt);
          }(),
          ...);
        },
        parts_);
    auto& s = nodes_.data();
    double* x[3] = {s.template get<field::x>(), s.template get<field::y>(), s.template get<field::z>()};
    double* v[3] = {s.template get<field::vx>(), s.template get<field::vy>(), s.template get<field::vz>()};
    for (int d = 0; d < 3; ++d)
      for (index_t i = 0; i < nodes_.size(); ++i) {
        x[d][i] += hold_velocity_[d] * dt;
        v[d][i] = hold_velocity_[d];
      }
  }

  [[noreturn]] void fail(index_t node) {
    std::string where;
    std::apply(
        [&](const auto&... p) {
      (
          (void)[&] {
            if constexpr (!body_part<std::remove_cvref_t<decltype(p)>>) {
              const index_t e = p.first_bad_element();
              if (e >= 0 && where.empty())
                where = parafsi::detail::concat(" (first non-finite force: ", p.name(), " element ", e, ")");
            }
          }(),
          ...);
        },
        parts_);
    throw numerical_failure(parafsi::detail::concat("structure::assembly: node ", node, " became non-finite at t = ",
                                                    t_, where, "; the step may exceed stable_dt() = ", stable_dt()),
                            node, t_);
  }

  nodes nodes_;
  parts_type parts_;
  central_difference cd_;
  std::vector<double> ksum_;
  double dt_nodal_ = std::numeric_limits<double>::infinity();
  double t_ = 0, dt_prev_ = 0;
  long steps_ = 0;
  bool track_ = false;
  hold_scope hold_scope_ = hold_scope::structure;            ///< of what
  bool held_ = false;                                        ///< hold(): rigid translation
  Eigen::Vector3d hold_velocity_ = Eigen::Vector3d::Zero();  ///< its velocity (m/s)
  energy_ledger ledger_{};
};

/// Deduction: assembly{nodes, part1, part2, ...}.
template <class... Parts>
assembly(nodes, Parts...) -> assembly<Parts...>;

}  // namespace parafsi::structure
