/// \file solver.hpp
/// Cell-centred finite-volume compressible Navier–Stokes on a rigidly moving
/// rectilinear box (ALE form, absolute inertial velocities as unknowns):
///   V_i dU_i/dt = −Σ_f A_f Ĝ_f + Σ_f A_f F̂_v,f + V_i S_i,
/// Ĝ_f the Galilean-shifted Riemann flux on the moving face (flux/ale.hpp), F̂_v the
/// viscous and heat flux with laminar + eddy viscosity, S the user/coupling sources
/// and the optional sponge. Time integration: SSP-RK2 (Heun) or SSP-RK3, each stage
/// with the box pose at its own time. The geometric conservation law holds identically
/// for a rigid box (face-centroid grid velocities), so a uniform state stays uniform
/// to round-off.
///
/// This header is the state and the recipe; the phases live in fluid/detail/:
///   ghosts.hpp (boundary ghost cells) · primitives.hpp · sweep.hpp (MUSCL + Riemann
///   fluxes per axis) · patch_faces.hpp (coupling face patches, fluid/patch.hpp) ·
///   viscous.hpp · sources.hpp (sources + sponge) · update.hpp · stable_dt.hpp.
///
/// Policies (types carry choices, values carry parameters), composed in any order:
///   gas::ideal · flux::{hllc_lm, hllc, rusanov, ausm_plus_up} ·
///   recon::{muscl<limiter::{van_leer, minmod, mc}>, first_order} ·
///   turbulence::{none, prandtl_mixing_length, smagorinsky} ·
///   viscosity::{inviscid, constant, sutherland} ·
///   frame::{fixed, translate, rigid, follow_payload}.
/// With `viscosity::inviscid` and `turbulence::none` the solver holds no gradient or
/// eddy-viscosity storage and has no viscous pass (checked by a static test).
///
/// The box motion of a step is planned once (plan_motion) and applied by the step; a
/// coupled stepper plans it in its move_frame phase and hands it in
/// (step(dt, motion, patcher)). No heap allocation happens inside step() after the first
/// step (the row buffers are sized then).
///
/// References: Toro E.F. (2009) Riemann Solvers and Numerical Methods, 3rd ed.;
///   Gottlieb S., Shu C.-W. (1998) Math. Comp. 67:73 (SSP-RK2);
///   Thomas P.D., Lombard C.K. (1979) AIAA J. 17:1030 (geometric conservation law).
#pragma once
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/policy.hpp"
#include "../core/soa.hpp"
#include "boundary/condition.hpp"
#include "detail/ghosts.hpp"
#include "detail/patch_faces.hpp"
#include "detail/primitives.hpp"
#include "detail/sources.hpp"
#include "detail/stable_dt.hpp"
#include "detail/stage.hpp"
#include "detail/sweep.hpp"
#include "detail/update.hpp"
#include "detail/viscous.hpp"
#include "fields.hpp"
#include "flux/ale.hpp"
#include "flux/hllc_lm.hpp"
#include "frame/fixed.hpp"
#include "gas.hpp"
#include "grid.hpp"
#include "patch.hpp"
#include "reconstruction/muscl.hpp"
#include "time/ssp_rk2.hpp"
#include "time/ssp_rk3.hpp"
#include "turbulence/none.hpp"
#include "view.hpp"
#include "viscosity/inviscid.hpp"
#include "wall_distance.hpp"

namespace parafsi::fluid {

struct empty_storage {};

/// Per-step phase timings (seconds, accumulated) for profiling.
struct phase_times {
  double boundaries = 0, primitives = 0, fluxes = 0, viscous = 0, sources = 0, update = 0;
  double exchange = 0;  ///< messages between processes (a distributed block mesh)
  double total() const { return boundaries + primitives + fluxes + viscous + sources + update + exchange; }
};

/// Totals over interior cells (inertial frame): mass, momentum, total energy.
struct totals {
  double mass = 0;
  std::array<double, 3> momentum{};
  double energy = 0;
  double kinetic = 0;  ///< kinetic energy ½ ρ|u|² integrated (J)

  /// Add a cell of conserved state q and volume vol.
  void add(const cons<double>& q, double vol) noexcept {
    mass += q.rho * vol;
    momentum[0] += q.m.x * vol;
    momentum[1] += q.m.y * vol;
    momentum[2] += q.m.z * vol;
    energy += q.E * vol;
    kinetic += 0.5 * dot(q.m, q.m) / q.rho * vol;
  }
};

template <class Flux = flux::hllc_lm, class Recon = recon::muscl<limiter::van_leer>,
          class Turbulence = turbulence::none, class Viscosity = viscosity::inviscid, class Frame = frame::fixed,
          class Time = time::ssp_rk2>
class solver {
 public:
  using flux_type = Flux;
  using recon_type = Recon;
  using turbulence_type = Turbulence;
  using viscosity_type = Viscosity;
  using frame_type = Frame;
  using time_type = Time;
  static constexpr bool is_viscous = Viscosity::active || Turbulence::active;
  static constexpr bool has_eddy_viscosity = Turbulence::active;
  static constexpr bool needs_wall_distance = [] {
    if constexpr (Turbulence::active) return Turbulence::needs_wall_distance;
    else return false;
  }();
  static constexpr index_t ng = rectilinear_grid::ghosts;
  static constexpr int stages = Time::stages;

  using cons_storage = soa_of_t<conserved_fields>;
  using prim_storage = soa_of_t<primitive_fields>;
  using viscous_storage = std::conditional_t<is_viscous, soa_of_t<viscous_fields>, empty_storage>;
  using turbulence_storage = std::conditional_t<
      has_eddy_viscosity,
      std::conditional_t<needs_wall_distance, soa<field::mu_t, field::wall_distance>, soa<field::mu_t>>, empty_storage>;

  /// Compose from a grid, boundary set and any policy values (order free).
  template <policy... Ps>
  solver(rectilinear_grid grid, boundary::set bc, const Ps&... policies)
      : grid_(std::move(grid)),
        bc_(std::move(bc)),
        gas_(pick_value<kind::gas, gas::ideal>(policies...)),
        flux_(pick_value<kind::flux, Flux>(policies...)),
        recon_(pick_value<kind::reconstruction, Recon>(policies...)),
        turb_(pick_value<kind::turbulence, Turbulence>(policies...)),
        visc_(pick_value<kind::viscosity, Viscosity>(policies...)),
        frame_(pick_value<kind::frame, Frame>(policies...)) {
    static_assert(((count_kind_v<kind::gas, Ps...> <= 1) && (count_kind_v<kind::flux, Ps...> <= 1) &&
                   (count_kind_v<kind::reconstruction, Ps...> <= 1) && (count_kind_v<kind::turbulence, Ps...> <= 1) &&
                   (count_kind_v<kind::viscosity, Ps...> <= 1) && (count_kind_v<kind::frame, Ps...> <= 1) &&
                   (count_kind_v<kind::time, Ps...> <= 1)),
                  "fluid::solver: at most one policy of each kind (gas, flux, reconstruction, "
                  "turbulence, viscosity, frame, time) may be given");
    gas_.validate();
    if constexpr (requires { visc_.validate(); }) visc_.validate();
    if constexpr (requires { turb_.validate(); }) turb_.validate();
    for (int d = 0; d < 3; ++d) {
      const bool plo = std::holds_alternative<boundary::periodic>(bc_.face[std::size_t(2 * d)]);
      const bool phi = std::holds_alternative<boundary::periodic>(bc_.face[std::size_t(2 * d + 1)]);
      require(plo == phi, "fluid::solver: periodic boundary on axis ", d, " must be set on both faces");
      if (!plo) require(grid_.n(d) >= 2, "fluid::solver: axis ", d, " needs >= 2 cells with non-periodic faces");
    }
    bc_.validate();
    const index_t N = grid_.total_cells();
    U_.resize(N, 0.0);
    U0_.resize(N, 0.0);
    W_.resize(N, 1.0);
    dU_.resize(N, 0.0);
    if constexpr (is_viscous) visc_store_.resize(N, 0.0);
    if constexpr (has_eddy_viscosity) {
      turb_store_.resize(N, 0.0);
      if constexpr (needs_wall_distance) {
        double* d = turb_store_.template get<field::wall_distance>();
        for (index_t c = 0; c < N; ++c) d[c] = 1e30;
      }
    }
    if (bc_.layer.cells > 0) {
      sponge_.emplace(N, 0.0);
      sponge_target_ = detail::setup_sponge(grid_, bc_, gas_, sponge_->template get<field::sponge_sigma>(),
                                            sponge_target_);
    }
    bad_rows_.assign(std::size_t(grid_.n(1) * grid_.n(2)), 0);
    threaded_ = grid_.interior_cells() >= 32768;
    // Ambient default state everywhere (ghosts and padding included).
    fill_uniform({1.18, {0.0, 0.0, 0.0}, 101325.0});
  }

  // ------------------------------------------------------------------ set-up
  /// Set every cell to one primitive state.
  void fill_uniform(const prim<double>& w) {
    validate_state(w, "fill_uniform");
    const cons<double> q = to_cons(w, gas_);
    const auto U = detail::conserved_ptrs(U_);
    for (index_t c = 0; c < grid_.total_cells() + index_t(simd::width); ++c) detail::store_cons(U, c, q);
  }
  /// Initialise interior cells from f(ξ) → prim<double> (ξ: cell centre, box coordinates).
  template <class F>
  void initialize(F&& f) {
    for (index_t k = 0; k < grid_.n(2); ++k)
      for (index_t j = 0; j < grid_.n(1); ++j)
        for (index_t i = 0; i < grid_.n(0); ++i) {
          const Eigen::Vector3d xi{grid_.centre(0, i), grid_.centre(1, j), grid_.centre(2, k)};
          const prim<double> w = f(xi);
          validate_state(w, "initialize");
          detail::store_cons(detail::conserved_ptrs(U_), grid_.index(i, j, k), to_cons(w, gas_));
        }
  }
  /// Cell-average initialisation by n³-point midpoint quadrature of f(ξ) → prim.
  template <class F>
  void initialize_averaged(F&& f, int n) {
    require(n >= 1, "initialize_averaged: need n >= 1");
    for (index_t k = 0; k < grid_.n(2); ++k)
      for (index_t j = 0; j < grid_.n(1); ++j)
        for (index_t i = 0; i < grid_.n(0); ++i) {
          cons<double> acc{0, {0, 0, 0}, 0};
          for (int c = 0; c < n; ++c)
            for (int b = 0; b < n; ++b)
              for (int a = 0; a < n; ++a) {
                const Eigen::Vector3d xi{grid_.face(0, i) + grid_.width(0, i) * (a + 0.5) / n,
                                         grid_.face(1, j) + grid_.width(1, j) * (b + 0.5) / n,
                                         grid_.face(2, k) + grid_.width(2, k) * (c + 0.5) / n};
                const prim<double> w = f(xi);
                validate_state(w, "initialize_averaged");
                acc = acc + to_cons(w, gas_);
              }
          detail::store_cons(detail::conserved_ptrs(U_), grid_.index(i, j, k), acc * (1.0 / double(n * n * n)));
        }
  }

  void set_time(double t) { t_ = t; }
  frame::pose& pose() noexcept { return pose_; }
  const frame::pose& pose() const noexcept { return pose_; }
  Frame& frame() noexcept { return frame_; }
  const Frame& frame() const noexcept { return frame_; }
  const boundary::set& boundaries() const noexcept { return bc_; }
  const gas::ideal& gas() const noexcept { return gas_; }
  const Flux& flux() const noexcept { return flux_; }
  const rectilinear_grid& grid() const noexcept { return grid_; }
  double time() const noexcept { return t_; }
  long steps() const noexcept { return steps_; }
  /// Restore the step count (restart from a checkpoint).
  void set_steps(long n) { steps_ = n; }
  /// Use OpenMP threads in the step phases (default: on for grids of ≥ 32768 cells).
  void set_threading(bool on) noexcept { threaded_ = on; }
  bool threading() const noexcept { return threaded_; }
  const phase_times& timings() const noexcept { return times_; }
  void reset_timings() noexcept { times_ = {}; }

  /// Composed policy names, for logs.
  std::string name() const {
    return std::string("fluid::solver<") + Flux::name() + ", recon:" + Recon::name() + ", " + Turbulence::name() +
           ", " + Viscosity::name() + ", " + Frame::name() + ", " + Time::name() + ">";
  }

  /// Enable the per-cell source hook (momentum N/m³ and energy W/m³, inertial),
  /// held constant over a step; zero-initialised. The coupling fills it.
  void enable_sources() {
    if (!sources_) sources_.emplace(grid_.total_cells(), 0.0);
  }
  bool has_sources() const noexcept { return sources_.has_value(); }
  /// Mass source per cell (kg/(m³ s)), e.g. a porous through-flow; zero by default.
  double* source_mass() {
    require(sources_.has_value(), "fluid::solver::source_mass: call enable_sources() first");
    return sources_->template get<field::s_rho>();
  }
  double* source(int component) {
    require(sources_.has_value(), "fluid::solver::source: call enable_sources() first");
    switch (component) {
      case 0: return sources_->template get<field::s_mx>();
      case 1: return sources_->template get<field::s_my>();
      case 2: return sources_->template get<field::s_mz>();
      default: return sources_->template get<field::s_E>();
    }
  }
  /// Distance to the nearest body per cell (mixing-length closure); +∞ by default.
  double* wall_distance() requires needs_wall_distance { return turb_store_.template get<field::wall_distance>(); }
  /// The wall distance of every cell (ghosts included) from the structure's `points` (box
  /// coordinates) within the closure's reach (wall_distance.hpp): on a stretched box one
  /// reach for every cell, the closure's largest.
  void wall_distance_from(std::span<const Eigen::Vector3d> points) requires needs_wall_distance {
    distance_to_points(grid_, points, turb_.wall_reach(std::numeric_limits<double>::infinity()),
                       std::span<double>(wall_distance(), std::size_t(grid_.total_cells())), true);
  }
  /// The turbulence closure (its constants).
  const Turbulence& turbulence() const noexcept { return turb_; }

  // ------------------------------------------------------------------ access
  index_t index(index_t i, index_t j, index_t k) const noexcept { return grid_.index(i, j, k); }
  cons<double> conserved(index_t i, index_t j, index_t k) const noexcept {
    return detail::load_cons(detail::conserved_ptrs(U_), grid_.index(i, j, k));
  }
  prim<double> primitive(index_t i, index_t j, index_t k) const noexcept { return to_prim(conserved(i, j, k), gas_); }
  void set_primitive(index_t i, index_t j, index_t k, const prim<double>& w) {
    validate_state(w, "set_primitive");
    detail::store_cons(detail::conserved_ptrs(U_), grid_.index(i, j, k), to_cons(w, gas_));
  }
  /// Read-only view of the current state (grid, pose, gas, cell arrays).
  fluid::view view() const noexcept { return fluid::view::of(grid_, pose_, gas_, U_); }
  const cons_storage& conserved_storage() const noexcept { return U_; }
  cons_storage& conserved_storage() noexcept { return U_; }
  /// Eddy viscosity field (after the last stage).
  const double* eddy_viscosity() const requires has_eddy_viscosity { return turb_store_.template get<field::mu_t>(); }
  /// Sums over interior cells, in a fixed order (bit-reproducible).
  fluid::totals totals() const {
    fluid::totals t;
    for (index_t k = 0; k < grid_.n(2); ++k)
      for (index_t j = 0; j < grid_.n(1); ++j)
        for (index_t i = 0; i < grid_.n(0); ++i) t.add(conserved(i, j, k), grid_.cell_volume(i, j, k));
    return t;
  }

  // ------------------------------------------------------------------ stepping
  /// Largest stable step: min(CFL / max Σ_d (|u_d − w_d| + c)/h_d, viscous limit).
  double stable_dt(double cfl = 0.5) const {
    require(cfl > 0.0 && cfl <= 1.0, "fluid::solver::stable_dt: CFL must be in (0, 1], got ", cfl);
    const double* mu_t = nullptr;
    if constexpr (has_eddy_viscosity) mu_t = turb_store_.template get<field::mu_t>();
    const double lam = detail::max_wave_rate<is_viscous>(grid_, gas_, pose_, detail::conserved_ptrs(U_), visc_, turb_,
                                                         mu_t, cfl, rate_slots_, threaded_);
    require(std::isfinite(lam) && lam > 0.0,
            "fluid::solver::stable_dt: non-finite wave speed (a cell's state is NaN or infinite, or its pressure "
            "and density differ in sign)");
    return cfl / lam;
  }

  /// The box motion the frame plans for a step of dt from the current pose and time.
  frame::motion plan_motion(double dt) const {
    frame::pose p = pose_;
    frame_.plan(p, t_, dt);
    return p.current_motion();
  }

  /// One Runge–Kutta step of size dt (SSP-RK2 or SSP-RK3 in Shu–Osher form) with the
  /// box motion `m` (planned by plan_motion) and the face patches of `patcher`. Every
  /// stage uses the box pose at its own time tⁿ + c_s Δt.
  template <face_patcher Patcher>
  void step(double dt, const frame::motion& m, Patcher& patcher) {
    require(dt > 0.0 && std::isfinite(dt), "fluid::solver::step: dt must be positive and finite, got ", dt);
    pose_.set_motion(m);
    copy_state(U0_, U_);
    double pose_time = 0.0;  // offset of the current pose from tⁿ
    for (int s = 0; s < Time::stages; ++s) {
      const double c = Time::c[std::size_t(s)];
      if (c != pose_time) {
        pose_.advance((c - pose_time) * dt);  // exact for the step's rigid motion
        pose_time = c;
      }
      compute_rhs(t_ + c * dt, s, patcher);
      update(Time::a[std::size_t(s)], Time::b[std::size_t(s)], dt, t_ + dt, /*last=*/s + 1 == Time::stages);
    }
    if (pose_time != 1.0) pose_.advance((1.0 - pose_time) * dt);
    t_ += dt;
    ++steps_;
  }
  /// Step with the frame's own plan.
  template <face_patcher Patcher>
  void step(double dt, Patcher& patcher) {
    step(dt, plan_motion(dt), patcher);
  }
  void step(double dt, const frame::motion& m) {
    no_patches none;
    step(dt, m, none);
  }
  void step(double dt) {
    no_patches none;
    step(dt, plan_motion(dt), none);
  }

  /// Plan and apply only the box motion (tests of the frame).
  void advance_pose_only(double dt) {
    pose_.set_motion(plan_motion(dt));
    pose_.advance(dt);
    t_ += dt;
  }

  // ------------------------------------------------------------------ checkpoint
  /// Checkpoint (io/archive.hpp; Self = const solver on save, solver on load). Signature
  /// first (policies, ghosts, grid faces, gas), then everything the next step reads:
  /// time, step count, pose, the frame policy's state, the conserved fields (by tag
  /// name, ghosts and SIMD padding included), the sources if enabled, and μ_t and the
  /// wall distance when the closure keeps them (stable_dt reads μ_t).
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& self) {
    ar.check("type", self.name(), "the solver type");
    ar.check("ghosts", std::int64_t(ng), "the number of ghost layers");
    for (int d = 0; d < 3; ++d)
      ar.check("grid.axis" + std::to_string(d), self.grid_.axis_of(d).faces,
               [d](const std::vector<double>& file, const std::vector<double>& mine) -> std::string {
                 if (file.size() != mine.size())
                   return parafsi::detail::concat("grid axis ", d, " has ", index_t(file.size()) - 1,
                                                  " cells in the file but ", index_t(mine.size()) - 1,
                                                  " in this solver");
                 for (std::size_t i = 0; i < file.size(); ++i)
                   if (file[i] != mine[i])
                     return parafsi::detail::concat("grid axis ", d, " face ", i, " is at ", file[i],
                                                    " in the file but ", mine[i], " in this solver");
                 return {};
               });
    ar.check("total_cells", self.grid_.total_cells(), "the cell count incl. ghosts");
    ar.check("field_length", std::int64_t(simd::padded(std::size_t(self.grid_.total_cells())) + simd::width),
             "the field length (cells + SIMD padding; another SIMD width?)");
    ar.check("gas.gamma", self.gas_.gamma, "gas gamma");
    ar.check("gas.R", self.gas_.R, "gas constant R");
    ar("time", self.t_);
    ar("steps", self.steps_);
    ar("pose.X", self.pose_.X);
    ar("pose.R", self.pose_.R);
    ar("pose.V", self.pose_.V);
    ar("pose.Omega", self.pose_.Omega);
    ar("frame", self.frame_);
    ar.fields("conserved", self.U_);
    bool sources = self.sources_.has_value();
    ar("sources", sources);
    if constexpr (Archive::loading) {
      if (sources) self.enable_sources();
      else if (self.sources_) self.sources_->resize(self.grid_.total_cells(), 0.0);  // none in the file: zero
    }
    if (sources) ar.fields("sources", *self.sources_);
    if constexpr (has_eddy_viscosity) ar.fields("turbulence", self.turb_store_);
  }

 private:
  void copy_state(cons_storage& dst, const cons_storage& src) const {
    for (std::size_t f = 0; f < cons_storage::field_count; ++f) {
      double* d = dst.data(f);
      const double* s = src.data(f);
      detail::par_for(threaded_, 0, src.size(), [&](index_t c) { d[c] = s[c]; });
    }
  }
  void validate_state(const prim<double>& w, const char* where) const {
    require(std::isfinite(w.rho) && w.rho > 0.0, "fluid::solver::", where, ": density must be > 0, got ", w.rho);
    require(std::isfinite(w.p) && w.p > 0.0, "fluid::solver::", where, ": pressure must be > 0, got ", w.p);
    require(std::isfinite(w.u.x) && std::isfinite(w.u.y) && std::isfinite(w.u.z), "fluid::solver::", where,
            ": velocity must be finite");
  }

  // ------------------------------------------------------------------ phases
  /// dU of one stage at time t: ghosts, primitives, the three inviscid sweeps, the
  /// coupling's face patches, the viscous pass, sources and sponge.
  template <class Patcher>
  void compute_rhs(double t, int stage, Patcher& patcher) {
    using detail::timed;
    const auto geo = detail::geometry(pose_);
    const auto U = detail::conserved_ptrs(U_);
    const auto dU = detail::conserved_ptrs(dU_);
    const auto W = detail::primitive_ptrs(std::as_const(W_));
    timed(times_.boundaries, [&] { detail::fill_ghosts(grid_, bc_, gas_, geo, t, U, threaded_); });
    timed(times_.primitives, [&] {
      detail::compute_primitives(grid_.total_cells(), gas_, detail::conserved_ptrs(std::as_const(U_)),
                                 detail::primitive_ptrs(W_), threaded_);
    });
    const detail::face_kernel<Flux, Recon> fk{flux_, recon_, gas_, grid_, W};
    timed(times_.fluxes, [&] {
      detail::ensure_row_buffers(bufs_, grid_.n(0));
      detail::sweep<0>(fk, geo, dU, bufs_, threaded_);
      detail::sweep<1>(fk, geo, dU, bufs_, threaded_);
      detail::sweep<2>(fk, geo, dU, bufs_, threaded_);
    });
    if (!patcher.patch_faces().empty())
      timed(times_.fluxes, [&] { detail::patch_faces(fk, geo, view(), stage, dU, patcher, blocked_); });
    if constexpr (is_viscous)
      timed(times_.viscous, [&] {
        detail::viscous_pass<Viscosity, Turbulence, viscous_storage, turbulence_storage>{visc_,       turb_,
                                                                                         gas_,        grid_,
                                                                                         visc_store_, turb_store_,
                                                                                         threaded_}(geo, W, dU);
      });
    if (sources_ || sponge_) timed(times_.sources, [&] { add_sources(); });
  }

  void add_sources() {
    const auto dU = detail::conserved_ptrs(dU_);
    const auto U = detail::conserved_ptrs(std::as_const(U_));
    detail::fields5<const double> src{};
    if (sources_)
      src = {sources_->template get<field::s_rho>(), sources_->template get<field::s_mx>(),
             sources_->template get<field::s_my>(), sources_->template get<field::s_mz>(),
             sources_->template get<field::s_E>()};
    const double* sig = sponge_ ? sponge_->template get<field::sponge_sigma>() : nullptr;
    if (sources_ && sponge_) detail::add_sources<true, true>(grid_, dU, U, src, sig, sponge_target_, threaded_);
    else if (sources_) detail::add_sources<true, false>(grid_, dU, U, src, sig, sponge_target_, threaded_);
    else if (sponge_) detail::add_sources<false, true>(grid_, dU, U, src, sig, sponge_target_, threaded_);
  }

  /// U ← a U0 + b (U + dt dU); on the last stage a non-physical state stops the run.
  void update(double a, double b, double dt, double t_new, bool last) {
    detail::timed(times_.update, [&] {
      const auto U = detail::conserved_ptrs(U_);
      const auto U0 = detail::conserved_ptrs(std::as_const(U0_));
      const auto dU = detail::conserved_ptrs(std::as_const(dU_));
      if (!last) {
        detail::update<false>(grid_, gas_, U, U0, dU, a, b, dt, bad_rows_.data(), threaded_);
        return;
      }
      detail::update<true>(grid_, gas_, U, U0, dU, a, b, dt, bad_rows_.data(), threaded_);
      detail::check_rows(grid_, gas_, pose_, detail::conserved_ptrs(std::as_const(U_)), bad_rows_.data(), t_new);
    });
  }

  rectilinear_grid grid_;
  std::vector<std::uint8_t> blocked_;  ///< faces blocked by one-sided patches (detail/patch_faces.hpp)
  boundary::set bc_;
  gas::ideal gas_;
  Flux flux_;
  Recon recon_;
  [[no_unique_address]] Turbulence turb_;
  [[no_unique_address]] Viscosity visc_;
  Frame frame_;
  frame::pose pose_{};
  double t_ = 0.0;
  long steps_ = 0;
  cons_storage U_, U0_, dU_;
  prim_storage W_;
  [[no_unique_address]] viscous_storage visc_store_;
  [[no_unique_address]] turbulence_storage turb_store_;
  std::optional<soa_of_t<source_fields>> sources_;
  std::optional<soa<field::sponge_sigma>> sponge_;
  cons<double> sponge_target_{1.18, {0, 0, 0}, 101325.0 / 0.4};
  std::vector<detail::row_buffers> bufs_;
  std::vector<char> bad_rows_;              ///< per interior row: non-physical state found
  mutable std::vector<double> rate_slots_;  ///< per-row maxima of stable_dt
  phase_times times_{};
  bool threaded_ = true;
};

/// Deduction guide: the policy of each kind among the arguments, defaults otherwise.
template <policy... Ps>
solver(rectilinear_grid, boundary::set, const Ps&...)
    -> solver<pick_t<kind::flux, flux::hllc_lm, Ps...>,
              pick_t<kind::reconstruction, recon::muscl<limiter::van_leer>, Ps...>,
              pick_t<kind::turbulence, turbulence::none, Ps...>, pick_t<kind::viscosity, viscosity::inviscid, Ps...>,
              pick_t<kind::frame, frame::fixed, Ps...>, pick_t<kind::time, time::ssp_rk2, Ps...>>;

}  // namespace parafsi::fluid
