/// \file explicit_stepper.hpp
/// `explicit_stepper<Fluid, Structure, Coupling>`: one step of the coupled system as a
/// short recipe of named, timed phases (DESIGN §4, methods §8.3):
///
///   1. move_frame  — the frame target (frame_target.hpp: e.g. follow_body, the payload's
///                    predicted mass centre) sets the tracking frame's target, then the box
///                    motion over the step is planned once and handed to the coupling
///                    (penalty: the pose at each substep) and to the fluid step;
///   2. exchange    — snapshot the fluid at tⁿ (velocity, ρ, K = γp), coupling stiffness
///                    and its caps, travel check, clear the fluid's source arrays;
///   3. structure   — m = ceil(Δt_f / Δt_s,crit) equal substeps, Δt_s,crit = min(assembly
///                    limit, coupling-spring limit); coupling forces enter each substep
///                    through the assembly's load hook, their reactions are accumulated
///                    as fluid impulses;
///   4. fluid       — impulses → sources (J, W)/(Δt_f V_cell), one fluid step with the
///                    planned motion (and the coupling as face patcher when it is one,
///                    fluid/patch.hpp);
///   (a `fluid_first` coupling — coupling::embedded — runs 4 before 3: its loads are
///   the face fluxes of the fluid step, applied to the structure substeps after it);
///   5. time        — t += Δt_f.
///
/// Leaving a part out: `no_fluid` or `no_structure` in its place (with
/// `coupling::none`) removes its storage and its passes at compile time:
///   explicit_stepper s{no_fluid{}, std::move(assembly)};   // structure only
///   explicit_stepper s{std::move(solver), no_structure{}}; // fluid only
/// Momentum: what the structure gains, the air loses (same kick lengths on both sides),
/// to round-off, every step (tests/test_coupling_impulse.cpp).
/// Frame tracking: give a frame target as the fourth argument,
///   explicit_stepper s{std::move(solver), std::move(assembly), coupling, follow_body{body_of<6>, 9.81}};
/// or call fluid().frame().track(...) yourself before step() (no_frame_target, the default).
/// No heap allocation happens inside step() after the first step (fluid, structure and
/// couplings keep their scratch; tests/test_no_allocation.cpp).
#pragma once
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>

#include "core/error.hpp"
#include "coupling/none.hpp"
#include "fluid/frame/pose.hpp"
#include "fluid/patch.hpp"
#include "frame_target.hpp"
#include "structure/assembly.hpp"
#include "structure/central_difference.hpp"

namespace parafsi {

/// Placeholders for a part left out of a stepper (no storage, no pass).
struct no_fluid {};
struct no_structure {};

/// Accumulated wall-clock seconds per phase.
struct stepper_phase_times {
  double move_frame = 0, exchange = 0, structure = 0, fluid = 0;
  double total() const { return move_frame + exchange + structure + fluid; }
};

template <class Fluid, class Structure, class Coupling = coupling::none, class FrameTarget = no_frame_target>
class explicit_stepper {
 public:
  static constexpr bool has_fluid = !std::is_same_v<Fluid, no_fluid>;
  static constexpr bool has_structure = !std::is_same_v<Structure, no_structure>;
  static constexpr bool coupled = Coupling::active;
  /// Couplings whose loads come from the fluid step's fluxes (coupling::embedded)
  /// declare `fluid_first = true`: the fluid step runs before the structure substeps.
  static constexpr bool fluid_first = [] {
    if constexpr (requires { Coupling::fluid_first; }) return coupled && bool(Coupling::fluid_first);
    else return false;
  }();
  static_assert(has_fluid || has_structure, "explicit_stepper: give a fluid solver, a structure assembly or both");
  static_assert(!coupled || (has_fluid && has_structure),
                "explicit_stepper: a coupling needs both a fluid and a structure; use coupling::none with "
                "no_fluid or no_structure");
  static constexpr bool has_frame_target = FrameTarget::active;
  static_assert(!has_frame_target || (has_fluid && has_structure),
                "explicit_stepper: a frame target follows a structure part with the fluid box; give both");
  /// The coupling replaces face fluxes in the fluid step (coupling::embedded).
  static constexpr bool patches_faces = coupled && fluid::face_patcher<Coupling>;

  explicit_stepper(Fluid f, Structure s, Coupling c = {}, FrameTarget target = {})
      : fluid_(std::move(f)), structure_(std::move(s)), coupling_(std::move(c)), target_(std::move(target)) {
    if constexpr (has_structure) {
      if (structure_.node_set().needs_finalize()) structure_.finalize();
      prev_substep_ = structure_.steps() == 0 ? 0.0 : -1.0;
    }
    if constexpr (coupled) coupling_.attach(fluid_, structure_);
    if constexpr (has_fluid) t_ = fluid_.time();
    else t_ = structure_.time();
  }

  // ------------------------------------------------------------- views
  double time() const noexcept { return t_; }
  long steps() const noexcept { return steps_; }
  const Fluid& fluid() const noexcept requires has_fluid { return fluid_; }
  Fluid& fluid() noexcept requires has_fluid { return fluid_; }
  const Structure& structure() const noexcept requires has_structure { return structure_; }
  Structure& structure() noexcept requires has_structure { return structure_; }
  const Coupling& coupling() const noexcept { return coupling_; }
  Coupling& coupling() noexcept { return coupling_; }
  const FrameTarget& frame_target() const noexcept { return target_; }
  FrameTarget& frame_target() noexcept { return target_; }
  /// Structure substeps of the last step.
  long last_substeps() const noexcept { return last_m_; }
  /// Length of the last structure substep (0 before the first step): the next step's
  /// first coupling kick uses it, so a checkpoint stores it.
  double previous_substep() const noexcept { return prev_substep_; }
  /// Restore the stepper's clock after its parts were restored from a checkpoint.
  void restore_clock(double t, long steps, double previous_substep, long last_substeps) {
    require(std::isfinite(t) && steps >= 0, "explicit_stepper::restore_clock: bad time/steps");
    t_ = t;
    steps_ = steps;
    prev_substep_ = previous_substep;
    last_m_ = last_substeps;
  }
  const stepper_phase_times& timings() const noexcept { return times_; }
  void reset_timings() noexcept { times_ = {}; }
  /// Checkpoint (io/archive.hpp): the clock and the coupling's state; the fluid and the
  /// structure are written by their own serialize (io::save_checkpoint gives each its
  /// section).
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& self) {
    ar.check("coupling_type", std::string(Coupling::name()), "the coupling");
    ar("time", self.t_);
    ar("steps", self.steps_);
    ar("last_substeps", self.last_m_);
    ar("previous_substep", self.prev_substep_);
    ar("coupling", self.coupling_);
    if constexpr (Archive::loading)
      if (self.steps_ < 0) ar.fail("the stepper's step count is ", self.steps_);
  }
  /// Upper bound on substeps per fluid step; more is an error naming the cause.
  long max_substeps = 10000;

  // ------------------------------------------------------------- stepping
  /// Largest stable step: the fluid's CFL step (and the coupling's travel limit);
  /// structure-only: the assembly's stable substep.
  double stable_dt(double cfl = 0.5) {
    if constexpr (has_fluid) {
      double dt = fluid_.stable_dt(cfl);
      if constexpr (coupled) dt = std::min(dt, coupling_.travel_dt(fluid_, structure_));
      return dt;
    } else {
      return structure_.stable_dt();
    }
  }

  void step(double dt) {
    require(dt > 0 && std::isfinite(dt), "explicit_stepper::step: dt must be > 0 and finite, got ", dt);
    if constexpr (has_fluid)
      timed(times_.move_frame, [&] {
        if constexpr (has_frame_target) target_(fluid_, structure_, dt);
        motion_ = fluid_.plan_motion(dt);
        if constexpr (coupled) coupling_.plan(fluid_, motion_);
      });
    if constexpr (coupled) timed(times_.exchange, [&] { coupling_.exchange(fluid_, structure_, dt); });
    auto structure_phase = [&] {
      if constexpr (has_structure) timed(times_.structure, [&] { last_m_ = structure_substeps(dt); });
    };
    auto fluid_phase = [&] {
      if constexpr (has_fluid) {
        timed(times_.fluid, [&] {
          if constexpr (coupled) coupling_.finish(fluid_, dt);
          if constexpr (patches_faces) fluid_.step(dt, motion_, coupling_);
          else fluid_.step(dt, motion_);
        });
      }
    };
    if constexpr (fluid_first) {
      fluid_phase();
      structure_phase();
    } else {
      structure_phase();
      fluid_phase();
    }
    t_ += dt;
    ++steps_;
  }

  /// Largest stable step of the coarsest fluid level under level subcycling
  /// (step_subcycled): the fluid's (fluid::block_solver::stable_dt_subcycled) and the
  /// coupling's travel limit for each of the finest level's steps, of which there are
  /// fluid().finest_substeps() in the step.
  double stable_dt_subcycled(double cfl = 0.5) requires has_fluid {
    double dt = fluid_.stable_dt_subcycled(cfl);
    if constexpr (coupled)
      dt = std::min(dt, coupling_.travel_dt(fluid_, structure_) * double(fluid_.finest_substeps()));
    return dt;
  }

  /// One step dt of the coarsest fluid level with level subcycling
  /// (fluid::block_solver::step_subcycled): the frame moves as in step(); the coupling
  /// (a fluid_first face patcher: coupling::embedded) finds its faces before each step of
  /// the finest level, whose stages it patches, and the structure takes its substeps after
  /// each, so the membrane and the finest level advance together while the coarser levels
  /// take their longer steps. last_substeps() is then the structure substeps of the whole
  /// step; the coupling's diagnostics (faces, impulse, work, through-flow) describe the
  /// last step of the finest level, as its exchange starts them anew.
  /// (Only for a coupling that patches the fluid's faces and runs the fluid first, or none.)
  void step_subcycled(double dt) requires(has_fluid && (!coupled || (patches_faces && fluid_first))) {
    require(dt > 0 && std::isfinite(dt), "explicit_stepper::step_subcycled: dt must be > 0 and finite, got ", dt);
    timed(times_.move_frame, [&] {
      if constexpr (has_frame_target) target_(fluid_, structure_, dt);
      motion_ = fluid_.plan_motion(dt);
      if constexpr (coupled) coupling_.plan(fluid_, motion_);
    });
    struct finest_hooks {
      explicit_stepper& s;
      long substeps = 0;
      void before(double, double dt_f) {
        if constexpr (coupled) {
          timed(s.times_.exchange, [&] { s.coupling_.exchange(s.fluid_, s.structure_, dt_f); });
          s.coupling_.finish(s.fluid_, dt_f);
        }
      }
      void after(double, double dt_f) {
        if constexpr (has_structure) timed(s.times_.structure, [&] { substeps += s.structure_substeps(dt_f); });
      }
    } hooks{*this};
    const double exchange0 = times_.exchange, structure0 = times_.structure;
    const auto t0 = std::chrono::steady_clock::now();
    if constexpr (coupled) fluid_.step_subcycled(dt, motion_, coupling_, hooks);
    else {
      fluid::no_patches none;
      fluid_.step_subcycled(dt, motion_, none, hooks);
    }
    times_.fluid += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() -
                    (times_.exchange - exchange0) - (times_.structure - structure0);
    last_m_ = hooks.substeps;
    t_ += dt;
    ++steps_;
  }

 private:
  /// The structure over dt in m = ceil(dt / Δt_s,crit) equal substeps, the coupling's
  /// forces in each (their kicks continuing the previous substep's); returns m.
  long structure_substeps(double dt) {
    double crit = structure_.stable_dt();
    if constexpr (coupled) crit = std::min(crit, coupling_.structure_dt());
    const long m = structure::central_difference::substeps(dt, crit);
    if (m > max_substeps)
      throw invalid_input(detail::concat("explicit_stepper::step: the structure needs ", m, " substeps in a step of ",
                                         dt, " s (stable substep ", crit, " s, max_substeps = ", max_substeps,
                                         "); reduce the fluid step or the coupling stiffness (PFAC)"));
    const double ds = dt / double(m);
    for (long k = 0; k < m; ++k) {
      const double prev = prev_substep_ < 0 ? ds : prev_substep_;
      const double kick = 0.5 * (prev + ds);
      if constexpr (coupled) {
        const double tau = double(k) * ds;
        structure_.step(ds, [&](structure::load_sink& sink, double) {
          coupling_.apply(sink, structure_.node_set(), tau, kick, ds);
        });
      } else {
        structure_.step(ds);
      }
      prev_substep_ = ds;
    }
    return m;
  }

  template <class F>
  static void timed(double& acc, F&& f) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    acc += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }

  [[no_unique_address]] Fluid fluid_;
  [[no_unique_address]] Structure structure_;
  [[no_unique_address]] Coupling coupling_;
  [[no_unique_address]] FrameTarget target_;
  frame::motion motion_{};  ///< the box motion of the current step (move_frame phase)
  double t_ = 0;
  double prev_substep_ = 0;
  long steps_ = 0;
  long last_m_ = 0;
  stepper_phase_times times_{};
};

template <class F, class S>
explicit_stepper(F, S) -> explicit_stepper<F, S, coupling::none>;
template <class F, class S, class C>
explicit_stepper(F, S, C) -> explicit_stepper<F, S, C>;
template <class F, class S, class C, class T>
explicit_stepper(F, S, C, T) -> explicit_stepper<F, S, C, T>;

}  // namespace parafsi
