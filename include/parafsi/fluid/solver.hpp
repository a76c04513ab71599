/// \file solver.hpp
/// Cell-centred finite-volume compressible Navier–Stokes on a rigidly moving
/// rectilinear box (ALE form, absolute inertial velocities as unknowns):
///   V_i dU_i/dt = −Σ_f A_f Ĝ_f + Σ_f A_f F̂_v,f + V_i S_i,
/// Ĝ_f the Galilean-shifted Riemann flux on the moving face (flux/ale.hpp), F̂_v the
/// viscous and heat flux with laminar + eddy viscosity, S the user/coupling sources
/// and the optional sponge. Time integration: SSP-RK2 (Heun), each stage with the
/// box pose at its own time. The geometric conservation law holds identically for
/// a rigid box (face-centroid grid velocities), so a uniform state stays uniform
/// to round-off.
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
/// References: Toro E.F. (2009) Riemann Solvers and Numerical Methods, 3rd ed.;
///   Gottlieb S., Shu C.-W. (1998) Math. Comp. 67:73 (SSP-RK2);
///   Thomas P.D., Lombard C.K. (1979) AIAA J. 17:1030 (geometric conservation law).
#pragma once
#include <array>
#include <chrono>
#include <functional>
#include <cmath>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/policy.hpp"
#include "../core/soa.hpp"
#include "boundary/condition.hpp"
#include "flux/ale.hpp"
#include "flux/hllc_lm.hpp"
#include "frame/fixed.hpp"
#include "gas.hpp"
#include "grid.hpp"
#include "reconstruction/muscl.hpp"
#include "time/ssp_rk2.hpp"
#include "time/ssp_rk3.hpp"
#include "turbulence/none.hpp"
#include "viscosity/inviscid.hpp"

namespace parafsi::fluid {

namespace field {
// Conserved variables.
struct rho { static constexpr const char* name = "rho"; };
struct mx { static constexpr const char* name = "mx"; };
struct my { static constexpr const char* name = "my"; };
struct mz { static constexpr const char* name = "mz"; };
struct E { static constexpr const char* name = "E"; };
// Primitive variables.
struct u { static constexpr const char* name = "u"; };
struct v { static constexpr const char* name = "v"; };
struct w { static constexpr const char* name = "w"; };
struct p { static constexpr const char* name = "p"; };
// Viscous scratch: box-frame velocity, temperature, transport coefficients, gradients.
struct ub0 {}; struct ub1 {}; struct ub2 {};
struct T {}; struct mu_eff {}; struct k_eff {};
struct g00 {}; struct g01 {}; struct g02 {};
struct g10 {}; struct g11 {}; struct g12 {};
struct g20 {}; struct g21 {}; struct g22 {};
struct gT0 {}; struct gT1 {}; struct gT2 {};
// Turbulence.
struct mu_t { static constexpr const char* name = "mu_t"; };
struct wall_distance { static constexpr const char* name = "wall_distance"; };
// Sources (per unit volume and time).
struct s_mx { static constexpr const char* name = "s_mx"; };
struct s_my { static constexpr const char* name = "s_my"; };
struct s_mz { static constexpr const char* name = "s_mz"; };
struct s_E { static constexpr const char* name = "s_E"; };
struct s_rho { static constexpr const char* name = "s_rho"; };
struct sponge_sigma {};
}  // namespace field

using conserved_fields = meta::list<field::rho, field::mx, field::my, field::mz, field::E>;
using primitive_fields = meta::list<field::rho, field::u, field::v, field::w, field::p>;
using viscous_fields = meta::list<field::ub0, field::ub1, field::ub2, field::T, field::mu_eff, field::k_eff,
                                  field::g00, field::g01, field::g02, field::g10, field::g11, field::g12,
                                  field::g20, field::g21, field::g22, field::gT0, field::gT1, field::gT2>;

struct empty_storage {};

/// Per-step phase timings (seconds, accumulated) for profiling.
struct phase_times {
  double boundaries = 0, primitives = 0, fluxes = 0, viscous = 0, sources = 0, update = 0;
  double total() const { return boundaries + primitives + fluxes + viscous + sources + update; }
};

/// A face whose flux the user (an embedded coupling) replaces: the face between the
/// cells `low` and `high` (flat indices, high = low + stride(axis)).
struct face_context {
  index_t low = 0, high = 0;
  int axis = 0;
  prim<double> L{}, R{};     ///< reconstructed states on the low and high side
  vec3<double> n{};          ///< unit normal (inertial), from low to high
  double wn = 0;             ///< grid normal speed of the face
  double area = 0;           ///< face area (m²)
  Eigen::Vector3d centre{};  ///< face centre in box coordinates ξ
};
/// Fluxes (per unit area, ALE form) through a patched face: `low_side` is what the
/// low cell sends through it, `high_side` what the high cell receives. They may differ
/// (a membrane in the face takes the difference as its load).
using face_handler = std::function<void(const face_context&, cons<double>& low_side, cons<double>& high_side)>;

/// Totals over interior cells (inertial frame): mass, momentum, total energy.
struct totals {
  double mass = 0;
  std::array<double, 3> momentum{};
  double energy = 0;
  double kinetic = 0;  ///< kinetic energy ½ ρ|u|² integrated (J)
};

template <class Flux = flux::hllc_lm, class Recon = recon::muscl<limiter::van_leer>,
          class Turbulence = turbulence::none, class Viscosity = viscosity::inviscid,
          class Frame = frame::fixed, class Time = time::ssp_rk2>
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

  using cons_storage = soa_of_t<conserved_fields>;
  using prim_storage = soa_of_t<primitive_fields>;
  using viscous_storage = std::conditional_t<is_viscous, soa_of_t<viscous_fields>, empty_storage>;
  using turbulence_storage =
      std::conditional_t<has_eddy_viscosity,
                         std::conditional_t<needs_wall_distance, soa<field::mu_t, field::wall_distance>,
                                            soa<field::mu_t>>,
                         empty_storage>;

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
                   (count_kind_v<kind::reconstruction, Ps...> <= 1) &&
                   (count_kind_v<kind::turbulence, Ps...> <= 1) &&
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
    require(bc_.layer.cells >= 0, "fluid::solver: sponge cells must be >= 0");
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
    setup_sponge();
    threaded_ = grid_.interior_cells() >= 32768;
    // Ambient default state everywhere (ghosts and padding included).
    fill_uniform({1.18, {0.0, 0.0, 0.0}, 101325.0});
  }

  // ------------------------------------------------------------------ set-up
  /// Set every cell to one primitive state.
  void fill_uniform(const prim<double>& w) {
    validate_state(w, "fill_uniform");
    const cons<double> q = to_cons(w, gas_);
    for (index_t c = 0; c < grid_.total_cells() + index_t(simd::width); ++c) store_cons(U_, c, q);
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
          store_cons(U_, grid_.index(i, j, k), to_cons(w, gas_));
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
          store_cons(U_, grid_.index(i, j, k), acc * (1.0 / double(n * n * n)));
        }
  }

  void set_time(double t) { t_ = t; }
  frame::pose& pose() noexcept { return pose_; }
  const frame::pose& pose() const noexcept { return pose_; }
  Frame& frame() noexcept { return frame_; }
  const Frame& frame() const noexcept { return frame_; }
  boundary::set& boundaries() noexcept { return bc_; }
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
    return std::string("fluid::solver<") + Flux::name() + ", recon:" + Recon::name() + ", " +
           Turbulence::name() + ", " + Viscosity::name() + ", " + Frame::name() + ", " + Time::name() + ">";
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
  /// Replace the Riemann flux on a set of faces (cell index of the high side, axis)
  /// by `handler` from the next stage on; the regular flux is computed first and
  /// corrected, so the faces cost a scalar recomputation each. Cleared by passing {}.
  void set_face_patches(std::vector<std::pair<index_t, int>> faces, face_handler handler) {
    for (const auto& [c, d] : faces)
      require(d >= 0 && d < 3 && c >= grid_.stride(d) && c < grid_.total_cells(),
              "fluid::solver::set_face_patches: bad face (cell ", c, ", axis ", d, ")");
    patches_ = std::move(faces);
    patch_handler_ = std::move(handler);
  }
  std::size_t face_patch_count() const noexcept { return patches_.size(); }

  /// Distance to the nearest body per cell (mixing-length closure); +∞ by default.
  double* wall_distance() requires needs_wall_distance {
    return turb_store_.template get<field::wall_distance>();
  }

  // ------------------------------------------------------------------ access
  index_t index(index_t i, index_t j, index_t k) const noexcept { return grid_.index(i, j, k); }
  cons<double> conserved(index_t i, index_t j, index_t k) const noexcept {
    return load_cons(U_, grid_.index(i, j, k));
  }
  prim<double> primitive(index_t i, index_t j, index_t k) const noexcept {
    return to_prim(conserved(i, j, k), gas_);
  }
  void set_primitive(index_t i, index_t j, index_t k, const prim<double>& w) {
    validate_state(w, "set_primitive");
    store_cons(U_, grid_.index(i, j, k), to_cons(w, gas_));
  }
  const cons_storage& conserved_storage() const noexcept { return U_; }
  cons_storage& conserved_storage() noexcept { return U_; }
  /// Eddy viscosity field (after the last stage).
  const double* eddy_viscosity() const requires has_eddy_viscosity {
    return turb_store_.template get<field::mu_t>();
  }
  /// Sums over interior cells, in a fixed order (bit-reproducible).
  fluid::totals totals() const {
    fluid::totals t;
    for (index_t k = 0; k < grid_.n(2); ++k)
      for (index_t j = 0; j < grid_.n(1); ++j)
        for (index_t i = 0; i < grid_.n(0); ++i) {
          const double vol = grid_.cell_volume(i, j, k);
          const auto q = conserved(i, j, k);
          t.mass += q.rho * vol;
          t.momentum[0] += q.m.x * vol;
          t.momentum[1] += q.m.y * vol;
          t.momentum[2] += q.m.z * vol;
          t.energy += q.E * vol;
          t.kinetic += 0.5 * dot(q.m, q.m) / q.rho * vol;
        }
    return t;
  }

  // ------------------------------------------------------------------ stepping
  /// Largest stable step: min(CFL / max Σ_d (|u_d − w_d| + c)/h_d, viscous limit).
  double stable_dt(double cfl = 0.5) const {
    require(cfl > 0.0 && cfl <= 1.0, "fluid::solver::stable_dt: CFL must be in (0, 1], got ", cfl);
    const Eigen::Matrix3d Rt = pose_.R.transpose();
    const Eigen::Vector3d vh = Rt * pose_.V, oh = Rt * pose_.Omega;
    const index_t nx = grid_.n(0), ny = grid_.n(1), nz = grid_.n(2);
    const double* h0 = grid_.widths(0);
    const double* h1 = grid_.widths(1);
    const double* h2 = grid_.widths(2);
    const double* x0 = grid_.centres(0);
    const double* x1 = grid_.centres(1);
    const double* x2 = grid_.centres(2);
    auto row_max = [&](index_t r) {
      const index_t j = r % ny, k = r / ny;
      double lam = 0.0;
      for (index_t i = 0; i < nx; ++i) {
        const auto w = to_prim(load_cons(U_, grid_.index(i, j, k)), gas_);
        const double c = gas_.sound_speed(w.rho, w.p);
        const Eigen::Vector3d ub = Rt * Eigen::Vector3d(w.u.x, w.u.y, w.u.z);
        const Eigen::Vector3d xi{x0[i], x1[j], x2[k]};
        const Eigen::Vector3d wb = vh + oh.cross(xi);
        double l = (std::fabs(ub[0] - wb[0]) + c) / h0[i] + (std::fabs(ub[1] - wb[1]) + c) / h1[j] +
                   (std::fabs(ub[2] - wb[2]) + c) / h2[k];
        if constexpr (is_viscous) {
          double mu_l = visc_.mu(gas_.temperature(w.rho, w.p));
          double mut = 0.0;
          if constexpr (has_eddy_viscosity) mut = turb_store_.template get<field::mu_t>()[grid_.index(i, j, k)];
          const double nu = std::max((mu_l + mut) / w.rho,
                                     gas_.gamma * (mu_l / visc_.prandtl + mut / turb_.prandtl_t) / w.rho);
          const double lv = 2.0 * nu * (1.0 / (h0[i] * h0[i]) + 1.0 / (h1[j] * h1[j]) + 1.0 / (h2[k] * h2[k]));
          // Δt_v = 0.5/lv must hold; expressed against cfl: cfl/l_eff ≤ 0.5/lv.
          l = std::max(l, lv * cfl / 0.5);
        }
        lam = std::max(lam, l);
      }
      return lam;
    };
    const double lam = parallel::reduce(index_t(0), ny * nz, 0.0, row_max,
                                        [](double a, double b) { return std::max(a, b); }, threaded_);
    require(std::isfinite(lam) && lam > 0.0, "fluid::solver::stable_dt: non-finite wave speed");
    return cfl / lam;
  }

  /// One Runge–Kutta step of size dt (SSP-RK2 or SSP-RK3 in Shu–Osher form). The
  /// frame plans the box motion for the step first; every stage uses the box pose at
  /// its own time tⁿ + c_s Δt.
  void step(double dt) {
    require(dt > 0.0 && std::isfinite(dt), "fluid::solver::step: dt must be positive and finite, got ", dt);
    frame_.plan(pose_, t_, dt);
    copy_state(U0_, U_);
    double pose_time = 0.0;  // offset of the current pose from tⁿ
    for (int s = 0; s < Time::stages; ++s) {
      const double c = Time::c[std::size_t(s)];
      if (c != pose_time) {
        pose_.advance((c - pose_time) * dt);  // exact for the step's rigid motion
        pose_time = c;
      }
      compute_rhs(t_ + c * dt);
      update(Time::a[std::size_t(s)], Time::b[std::size_t(s)], dt, t_ + dt, /*check=*/s + 1 == Time::stages);
    }
    if (pose_time != 1.0) pose_.advance((1.0 - pose_time) * dt);
    t_ += dt;
    ++steps_;
  }

  /// Plan and apply only the box motion (used by the coupled stepper and tests).
  void advance_pose_only(double dt) {
    frame_.plan(pose_, t_, dt);
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
                   return detail::concat("grid axis ", d, " has ", index_t(file.size()) - 1,
                                         " cells in the file but ", index_t(mine.size()) - 1, " in this solver");
                 for (std::size_t i = 0; i < file.size(); ++i)
                   if (file[i] != mine[i])
                     return detail::concat("grid axis ", d, " face ", i, " is at ", file[i], " in the file but ",
                                           mine[i], " in this solver");
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
  // ------------------------------------------------------------------ helpers
  /// Parallel loop over disjoint work; serial for small grids (below ~32k cells a
  /// parallel region costs more than it saves, and far more on a loaded machine).
  template <class F>
  void par_for(index_t b, index_t e, F&& f) const {
    parallel::for_range(b, e, std::forward<F>(f), threaded_);
  }
  static PARAFSI_INLINE void store_cons(cons_storage& s, index_t c, const cons<double>& q) noexcept {
    s.template get<field::rho>()[c] = q.rho;
    s.template get<field::mx>()[c] = q.m.x;
    s.template get<field::my>()[c] = q.m.y;
    s.template get<field::mz>()[c] = q.m.z;
    s.template get<field::E>()[c] = q.E;
  }
  static PARAFSI_INLINE cons<double> load_cons(const cons_storage& s, index_t c) noexcept {
    return {s.template get<field::rho>()[c],
            {s.template get<field::mx>()[c], s.template get<field::my>()[c], s.template get<field::mz>()[c]},
            s.template get<field::E>()[c]};
  }
  void copy_state(cons_storage& dst, const cons_storage& src) const {
    for (std::size_t f = 0; f < cons_storage::field_count; ++f) {
      double* d = dst.data(f);
      const double* s = src.data(f);
      par_for(0, src.size(), [&](index_t c) { d[c] = s[c]; });
    }
  }
  void validate_state(const prim<double>& w, const char* where) const {
    require(std::isfinite(w.rho) && w.rho > 0.0, "fluid::solver::", where, ": density must be > 0, got ", w.rho);
    require(std::isfinite(w.p) && w.p > 0.0, "fluid::solver::", where, ": pressure must be > 0, got ", w.p);
    require(std::isfinite(w.u.x) && std::isfinite(w.u.y) && std::isfinite(w.u.z),
            "fluid::solver::", where, ": velocity must be finite");
  }

  struct stage_geometry {
    std::array<vec3<double>, 3> n;  // face normals (inertial) of the three box axes
    Eigen::Vector3d vh, oh;         // box-frame velocity and angular velocity
    Eigen::Matrix3d R;
  };
  stage_geometry geometry() const {
    stage_geometry g;
    for (int d = 0; d < 3; ++d) g.n[std::size_t(d)] = {pose_.R(0, d), pose_.R(1, d), pose_.R(2, d)};
    g.vh = pose_.R.transpose() * pose_.V;
    g.oh = pose_.R.transpose() * pose_.Omega;
    g.R = pose_.R;
    return g;
  }

  // ------------------------------------------------------------------ phases
  void compute_rhs(double t) {
    const auto geo = geometry();
    timed(times_.boundaries, [&] { fill_ghosts(geo, t); });
    timed(times_.primitives, [&] { compute_primitives(); });
    timed(times_.fluxes, [&] {
      sweep<0>(geo);
      sweep<1>(geo);
      sweep<2>(geo);
    });
    if (!patches_.empty()) timed(times_.fluxes, [&] { patch_faces(geo); });
    if constexpr (is_viscous) timed(times_.viscous, [&] { viscous_fluxes(geo); });
    if (sources_ || sponge_) timed(times_.sources, [&] { add_sources(); });
  }

  template <class F>
  static void timed(double& acc, F&& f) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    acc += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }

  /// Ghost cells of every face: x faces over interior (j, k); y faces over all i
  /// (ghosts included) and interior k; z faces over all (i, j): corners get filled.
  void fill_ghosts(const stage_geometry& geo, double t) {
    const index_t n[3] = {grid_.n(0), grid_.n(1), grid_.n(2)};
    for (int d = 0; d < 3; ++d) {
      const int a = (d + 1) % 3, b = (d + 2) % 3;
      // Ranges of the two transverse axes.
      auto range = [&](int axis) -> std::pair<index_t, index_t> {
        if (axis < d) return {-ng, n[axis] + ng};  // already filled axes: include ghosts
        return {0, n[axis]};
      };
      const auto ra = range(a), rb = range(b);
      for (int hi = 0; hi < 2; ++hi) {
        const auto& bc = bc_.face[std::size_t(2 * d + hi)];
        const vec3<double> nout = geo.n[std::size_t(d)] * (hi ? 1.0 : -1.0);
        std::visit([&](const auto& cond) {
          using C = std::decay_t<decltype(cond)>;
          par_for(rb.first, rb.second, [&](index_t q) {
            for (index_t pidx = ra.first; pidx < ra.second; ++pidx) {
              for (index_t g = 1; g <= ng; ++g) {
                index_t ijk_g[3], ijk_m[3], ijk_a[3];
                ijk_g[a] = ijk_m[a] = ijk_a[a] = pidx;
                ijk_g[b] = ijk_m[b] = ijk_a[b] = q;
                ijk_g[d] = hi ? n[d] - 1 + g : -g;
                if constexpr (std::is_same_v<C, boundary::periodic>) {
                  ijk_m[d] = hi ? g - 1 : n[d] - g;
                  const index_t cg = grid_.index(ijk_g[0], ijk_g[1], ijk_g[2]);
                  const index_t cm = grid_.index(ijk_m[0], ijk_m[1], ijk_m[2]);
                  store_cons(U_, cg, load_cons(U_, cm));
                } else {
                  ijk_m[d] = hi ? n[d] - g : g - 1;  // mirror image of the ghost
                  ijk_a[d] = hi ? n[d] - 1 : 0;      // boundary (adjacent) interior cell
                  const index_t cg = grid_.index(ijk_g[0], ijk_g[1], ijk_g[2]);
                  const auto wm = to_prim(load_cons(U_, grid_.index(ijk_m[0], ijk_m[1], ijk_m[2])), gas_);
                  const auto wa = to_prim(load_cons(U_, grid_.index(ijk_a[0], ijk_a[1], ijk_a[2])), gas_);
                  // Grid normal speed at the boundary face centre (outward normal).
                  Eigen::Vector3d xi{grid_.centre(0, ijk_a[0]), grid_.centre(1, ijk_a[1]),
                                     grid_.centre(2, ijk_a[2])};
                  xi[d] = hi ? grid_.face(d, n[d]) : grid_.face(d, 0);
                  const double wn = (hi ? 1.0 : -1.0) * (geo.vh[d] + geo.oh.cross(xi)[d]);
                  store_cons(U_, cg, to_cons(cond.ghost(wm, wa, nout, wn, gas_, t), gas_));
                }
              }
            }
          });
        }, bc);
      }
    }
  }

  void compute_primitives() {
    const index_t N = grid_.total_cells();
    const double* r = U_.template get<field::rho>();
    const double* mx = U_.template get<field::mx>();
    const double* my = U_.template get<field::my>();
    const double* mz = U_.template get<field::mz>();
    const double* E = U_.template get<field::E>();
    double* wr = W_.template get<field::rho>();
    double* wu = W_.template get<field::u>();
    double* wv = W_.template get<field::v>();
    double* ww = W_.template get<field::w>();
    double* wp = W_.template get<field::p>();
    const index_t chunk = 4096;
    const index_t nchunks = (N + chunk - 1) / chunk;
    const gas::ideal g = gas_;
    par_for(0, nchunks, [&](index_t ch) {
      const index_t b = ch * chunk, e = std::min(N, b + chunk);
      simd::for_each_pack(b, e, [&](auto tag, index_t c) {
        using V = typename decltype(tag)::type;
        const V rho = simd::load<V>(r + c);
        const V inv = V(1.0) / rho;
        const V u = simd::load<V>(mx + c) * inv, v = simd::load<V>(my + c) * inv,
                w = simd::load<V>(mz + c) * inv;
        simd::store(wr + c, rho);
        simd::store(wu + c, u);
        simd::store(wv + c, v);
        simd::store(ww + c, w);
        simd::store(wp + c, V(g.gamma - 1.0) * (simd::load<V>(E + c) - V(0.5) * rho * (u * u + v * v + w * w)));
      });
    });
  }

  /// Thread-local row buffers for the flux sweeps: face values of a row of cells
  /// (lo: at the cell's low face, hi: at its high face; hi of the previous row for
  /// the y/z sweeps) and two rolling rows of face fluxes.
  struct row_buffers {
    std::array<simd::aligned_vector<double>, 5> lo, hi, hi_prev, fa, fb;
  };
  std::vector<row_buffers>& buffers() {
    const std::size_t nt = std::size_t(parallel::max_threads());
    const std::size_t len = std::size_t(grid_.n(0)) + 2 * simd::width + 4;
    if (bufs_.size() < nt || (bufs_.size() && bufs_[0].lo[0].size() < len)) {
      bufs_.assign(nt, {});
      for (auto& rb : bufs_)
        for (auto* arr : {&rb.lo, &rb.hi, &rb.hi_prev, &rb.fa, &rb.fb})
          for (auto& v : *arr) v.assign(len, 0.0);
    }
    return bufs_;
  }
  static int thread_id() noexcept {
#if defined(_OPENMP)
    return omp_get_thread_num();
#else
    return 0;
#endif
  }

  /// MUSCL face values of the cells starting at c (lanes along x) along axis D:
  /// W_c ∓ (Δx_c/2)·limiter(a, b) with per-unit-length gradients a, b. Each cell's
  /// slope is computed once per sweep. Where a face value would have ρ ≤ 0 or p ≤ 0,
  /// the cell falls back to first order (both faces take the cell value).
  template <int D, class V>
  PARAFSI_INLINE void cell_faces(index_t c, index_t s, index_t ia, double* const* lo, double* const* hi,
                                 index_t o) const noexcept {
    const double* W[5] = {W_.template get<field::rho>(), W_.template get<field::u>(), W_.template get<field::v>(),
                          W_.template get<field::w>(), W_.template get<field::p>()};
    if constexpr (Recon::second_order) {
      const double* idc = grid_.inv_centre_gaps(D);
      const double* hdx = grid_.half_widths(D);
      V idc_c, idc_p, h_c;
      if constexpr (D == 0) {
        idc_c = simd::load<V>(idc + ia);
        idc_p = simd::load<V>(idc + ia + 1);
        h_c = simd::load<V>(hdx + ia);
      } else {
        idc_c = V(idc[ia]);
        idc_p = V(idc[ia + 1]);
        h_c = V(hdx[ia]);
      }
      V q[5], l[5], r[5];
      for (int f = 0; f < 5; ++f) {
        const V qm = simd::load<V>(W[f] + c - s);
        q[f] = simd::load<V>(W[f] + c);
        const V qp = simd::load<V>(W[f] + c + s);
        const V d = recon_.slope((q[f] - qm) * idc_c, (qp - q[f]) * idc_p) * h_c;
        l[f] = q[f] - d;
        r[f] = q[f] + d;
      }
      const auto bad = (l[0] <= V(0.0)) || (r[0] <= V(0.0)) || (l[4] <= V(0.0)) || (r[4] <= V(0.0));
      if (simd::any(bad))
        for (int f = 0; f < 5; ++f) {
          l[f] = simd::select(bad, q[f], l[f]);
          r[f] = simd::select(bad, q[f], r[f]);
        }
      for (int f = 0; f < 5; ++f) {
        simd::store(lo[f] + o, l[f]);
        simd::store(hi[f] + o, r[f]);
      }
    } else {
      (void)s;
      (void)ia;
      for (int f = 0; f < 5; ++f) {
        const V q = simd::load<V>(W[f] + c);
        simd::store(lo[f] + o, q);
        simd::store(hi[f] + o, q);
      }
    }
  }

  /// ALE Riemann flux from face values L (left/low side) and R at lane offsets.
  template <class V>
  PARAFSI_INLINE cons<V> face_flux(const double* const* L, index_t oL, const double* const* R, index_t oR,
                                   const V& wn, const vec3<double>& n) const noexcept {
    const prim<V> wl{simd::load<V>(L[0] + oL), {simd::load<V>(L[1] + oL), simd::load<V>(L[2] + oL),
                     simd::load<V>(L[3] + oL)}, simd::load<V>(L[4] + oL)};
    const prim<V> wr{simd::load<V>(R[0] + oR), {simd::load<V>(R[1] + oR), simd::load<V>(R[2] + oR),
                     simd::load<V>(R[3] + oR)}, simd::load<V>(R[4] + oR)};
    return flux::ale_flux(flux_, wl, wr, n, wn, gas_);
  }

  static PARAFSI_INLINE void store_flux(double* const* out, index_t o, const auto& F) noexcept {
    simd::store(out[0] + o, F.rho);
    simd::store(out[1] + o, F.m.x);
    simd::store(out[2] + o, F.m.y);
    simd::store(out[3] + o, F.m.z);
    simd::store(out[4] + o, F.E);
  }

  /// Inviscid fluxes along axis D accumulated into dU (D = 0 initialises dU).
  /// Lanes run along x in every direction. x: face values of a whole row (cells −1…n)
  /// then its n+1 face fluxes, then the update; y and z: rows are walked along the
  /// axis with the previous row's high-face values and face fluxes kept, so every
  /// slope is computed once and every cell is written once per axis.
  template <int D>
  void sweep(const stage_geometry& geo) {
    const index_t nx = grid_.n(0), ny = grid_.n(1), nz = grid_.n(2);
    const vec3<double> n = geo.n[D];
    double* dU[5] = {dU_.template get<field::rho>(), dU_.template get<field::mx>(), dU_.template get<field::my>(),
                     dU_.template get<field::mz>(), dU_.template get<field::E>()};
    auto& bufs = buffers();
    const double* x0 = grid_.centres(0);
    const double* x1 = grid_.centres(1);
    const double* x2 = grid_.centres(2);
    auto ptrs = [](std::array<simd::aligned_vector<double>, 5>& a) {
      return std::array<double*, 5>{a[0].data(), a[1].data(), a[2].data(), a[3].data(), a[4].data()};
    };
    if constexpr (D == 0) {
      const double* idx = grid_.inv_widths(0);
      par_for(0, ny * nz, [&](index_t r) {
        const index_t j = r % ny, k = r / ny;
        auto& rb = bufs[std::size_t(thread_id())];
        const auto lo = ptrs(rb.lo), hi = ptrs(rb.hi), fb = ptrs(rb.fa);
        const index_t base = grid_.index(0, j, k);
        // Face values of cells −1 … n_x, stored at offset i + 1.
        simd::for_each_pack(-1, nx + 1, [&](auto tag, index_t i) {
          using V = typename decltype(tag)::type;
          cell_faces<0, V>(base + i, 1, i, lo.data(), hi.data(), i + 1);
        });
        // ŵ_x on x faces: v̂_x + ω̂_y z − ω̂_z y (constant along the row).
        const double wn = geo.vh[0] + geo.oh[1] * x2[k] - geo.oh[2] * x1[j];
        simd::for_each_pack(0, nx + 1, [&](auto tag, index_t i) {  // face i: cells i−1 | i
          using V = typename decltype(tag)::type;
          store_flux(fb.data(), i, face_flux<V>(hi.data(), i, lo.data(), i + 1, V(wn), n));
        });
        simd::for_each_pack(0, nx, [&](auto tag, index_t i) {
          using V = typename decltype(tag)::type;
          const V id = simd::load<V>(idx + i);
          for (int f = 0; f < 5; ++f)
            simd::store(dU[f] + base + i, (simd::load<V>(fb[f] + i) - simd::load<V>(fb[f] + i + 1)) * id);
        });
      });
    } else {
      constexpr int T = (D == 1) ? 2 : 1;  // the other transverse axis (parallelised)
      const index_t nD = grid_.n(D), nT = grid_.n(T);
      const index_t s = grid_.stride(D);
      const double* idx = grid_.inv_widths(D);
      par_for(0, nT, [&](index_t q) {
        auto& rb = bufs[std::size_t(thread_id())];
        auto lo = ptrs(rb.lo), hi = ptrs(rb.hi), hi_prev = ptrs(rb.hi_prev);
        auto cur = ptrs(rb.fa), prev = ptrs(rb.fb);
        for (index_t row = -1; row <= nD; ++row) {  // cells along D; face `row` is row−1 | row
          const index_t j = D == 1 ? row : q, k = D == 1 ? q : row;
          const index_t base = grid_.index(0, j, k);
          simd::for_each_pack(0, nx, [&](auto tag, index_t i) {
            using V = typename decltype(tag)::type;
            cell_faces<D, V>(base + i, s, row, lo.data(), hi.data(), i);
          });
          if (row >= 0) {
            // ŵ on y faces: v̂_y + ω̂_z x − ω̂_x z;  on z faces: v̂_z + ω̂_x y − ω̂_y x.
            const double wconst = D == 1 ? geo.vh[1] - geo.oh[0] * x2[k] : geo.vh[2] + geo.oh[0] * x1[j];
            const double wslope = D == 1 ? geo.oh[2] : -geo.oh[1];
            simd::for_each_pack(0, nx, [&](auto tag, index_t i) {
              using V = typename decltype(tag)::type;
              const V wn = V(wconst) + V(wslope) * simd::load<V>(x0 + i);
              store_flux(cur.data(), i, face_flux<V>(hi_prev.data(), i, lo.data(), i, wn, n));
            });
            if (row >= 1) {
              const index_t cbase = base - s;  // cell row−1 receives F_{row−1/2} − F_{row+1/2}
              const double id = idx[row - 1];
              simd::for_each_pack(0, nx, [&](auto tag, index_t i) {
                using V = typename decltype(tag)::type;
                for (int c = 0; c < 5; ++c)
                  simd::store(dU[c] + cbase + i,
                              simd::load<V>(dU[c] + cbase + i) +
                                  (simd::load<V>(prev[c] + i) - simd::load<V>(cur[c] + i)) * V(id));
              });
            }
            std::swap(cur, prev);
          }
          std::swap(hi, hi_prev);
        }
      });
    }
  }

  /// Patched faces: recompute the regular flux, ask the handler for the two one-sided
  /// fluxes, and correct the two cells' rates. Serial, in list order (deterministic).
  void patch_faces(const stage_geometry& geo) {
    double* dU[5] = {dU_.template get<field::rho>(), dU_.template get<field::mx>(), dU_.template get<field::my>(),
                     dU_.template get<field::mz>(), dU_.template get<field::E>()};
    const index_t sy = grid_.stride(1), sz = grid_.stride(2);
    for (const auto& [c, d] : patches_) {
      const index_t s = grid_.stride(d), m = c - s;
      // Axis indices of the high cell.
      const index_t k = c / sz - ng, j = (c % sz) / sy - ng, i = c % sy - ng;
      const index_t ijk[3] = {i, j, k};
      double lo_m[5], hi_m[5], lo_c[5], hi_c[5];
      double* pl[5] = {&lo_m[0], &lo_m[1], &lo_m[2], &lo_m[3], &lo_m[4]};
      double* ph[5] = {&hi_m[0], &hi_m[1], &hi_m[2], &hi_m[3], &hi_m[4]};
      double* ql[5] = {&lo_c[0], &lo_c[1], &lo_c[2], &lo_c[3], &lo_c[4]};
      double* qh[5] = {&hi_c[0], &hi_c[1], &hi_c[2], &hi_c[3], &hi_c[4]};
      auto faces_of = [&](index_t cell, index_t ia, double** lo, double** hi) {
        if (d == 0) cell_faces<0, double>(cell, s, ia, lo, hi, 0);
        else if (d == 1) cell_faces<1, double>(cell, s, ia, lo, hi, 0);
        else cell_faces<2, double>(cell, s, ia, lo, hi, 0);
      };
      faces_of(m, ijk[d] - 1, pl, ph);
      faces_of(c, ijk[d], ql, qh);
      face_context fc;
      fc.low = m;
      fc.high = c;
      fc.axis = d;
      fc.L = {hi_m[0], {hi_m[1], hi_m[2], hi_m[3]}, hi_m[4]};
      fc.R = {lo_c[0], {lo_c[1], lo_c[2], lo_c[3]}, lo_c[4]};
      fc.n = geo.n[std::size_t(d)];
      fc.centre = {grid_.centre(0, i), grid_.centre(1, j), grid_.centre(2, k)};
      fc.centre[d] = grid_.face(d, ijk[d]);
      fc.wn = geo.vh[d] + geo.oh.cross(fc.centre)[d];
      const int a = (d + 1) % 3, b = (d + 2) % 3;
      fc.area = grid_.width(a, ijk[a]) * grid_.width(b, ijk[b]);
      const cons<double> F = flux::ale_flux(flux_, fc.L, fc.R, fc.n, fc.wn, gas_);
      cons<double> Flo = F, Fhi = F;
      patch_handler_(fc, Flo, Fhi);
      const double idm = grid_.inv_widths(d)[ijk[d] - 1], idc = grid_.inv_widths(d)[ijk[d]];
      const double dlo[5] = {F.rho - Flo.rho, F.m.x - Flo.m.x, F.m.y - Flo.m.y, F.m.z - Flo.m.z, F.E - Flo.E};
      const double dhi[5] = {F.rho - Fhi.rho, F.m.x - Fhi.m.x, F.m.y - Fhi.m.y, F.m.z - Fhi.m.z, F.E - Fhi.E};
      const bool m_interior = ijk[d] - 1 >= 0, c_interior = ijk[d] < grid_.n(d);
      for (int q = 0; q < 5; ++q) {
        if (m_interior) dU[q][m] += dlo[q] * idm;
        if (c_interior) dU[q][c] -= dhi[q] * idc;
      }
    }
  }

  /// Viscous and heat fluxes (laminar + eddy viscosity), in box components:
  /// τ̂ = μ_eff(∇û + ∇ûᵀ − ⅔ ∇·û I), q̂ = −k_eff ∇T, face-normal derivatives from
  /// two-point differences, tangential ones from the average of the two cells'
  /// central differences; momentum fluxes rotated back to inertial components.
  void viscous_fluxes(const stage_geometry& geo) requires is_viscous {
    const index_t nx = grid_.n(0), ny = grid_.n(1), nz = grid_.n(2);
    auto& vs = visc_store_;
    double* ub[3] = {vs.template get<field::ub0>(), vs.template get<field::ub1>(), vs.template get<field::ub2>()};
    double* Tc = vs.template get<field::T>();
    double* mu = vs.template get<field::mu_eff>();
    double* kk = vs.template get<field::k_eff>();
    double* G[3][3] = {{vs.template get<field::g00>(), vs.template get<field::g01>(), vs.template get<field::g02>()},
                       {vs.template get<field::g10>(), vs.template get<field::g11>(), vs.template get<field::g12>()},
                       {vs.template get<field::g20>(), vs.template get<field::g21>(), vs.template get<field::g22>()}};
    double* GT[3] = {vs.template get<field::gT0>(), vs.template get<field::gT1>(), vs.template get<field::gT2>()};
    const double* Wr = W_.template get<field::rho>();
    const double* Wu[3] = {W_.template get<field::u>(), W_.template get<field::v>(), W_.template get<field::w>()};
    const double* Wp = W_.template get<field::p>();
    const Eigen::Matrix3d Rt = geo.R.transpose();
    const double cp = gas_.cp();
    // 1. Box-frame velocity and temperature on every cell (ghosts included).
    const index_t N = grid_.total_cells();
    par_for(0, N, [&](index_t c) {
      const Eigen::Vector3d u = Rt * Eigen::Vector3d(Wu[0][c], Wu[1][c], Wu[2][c]);
      ub[0][c] = u[0];
      ub[1][c] = u[1];
      ub[2][c] = u[2];
      Tc[c] = gas_.temperature(Wr[c], Wp[c]);
    });
    // 2. Cell gradients (central differences) and transport coefficients on cells
    //    [−1, n] in every direction.
    const double* xcs[3] = {grid_.centres(0), grid_.centres(1), grid_.centres(2)};
    par_for(-1, nz + 1, [&](index_t k) {
      for (index_t j = -1; j < ny + 1; ++j)
        for (index_t i = -1; i < nx + 1; ++i) {
          const index_t c = grid_.index(i, j, k);
          const index_t ijk[3] = {i, j, k};
          for (int d = 0; d < 3; ++d) {
            const index_t s = grid_.stride(d);
            const double inv = 1.0 / (xcs[d][ijk[d] + 1] - xcs[d][ijk[d] - 1]);
            for (int a = 0; a < 3; ++a) G[a][d][c] = (ub[a][c + s] - ub[a][c - s]) * inv;
            GT[d][c] = (Tc[c + s] - Tc[c - s]) * inv;
          }
          double mu_l = visc_.mu(Tc[c]);
          double mut = 0.0;
          if constexpr (has_eddy_viscosity) {
            double S2 = 0.0;
            for (int a = 0; a < 3; ++a)
              for (int b = 0; b < 3; ++b) {
                const double sab = 0.5 * (G[a][b][c] + G[b][a][c]);
                S2 += sab * sab;
              }
            const double delta = std::cbrt(grid_.width(0, i) * grid_.width(1, j) * grid_.width(2, k));
            double dw = 1e30;
            if constexpr (needs_wall_distance) dw = turb_store_.template get<field::wall_distance>()[c];
            mut = turb_.eddy_viscosity(Wr[c], std::sqrt(2.0 * S2), delta, dw);
            turb_store_.template get<field::mu_t>()[c] = mut;
          }
          mu[c] = mu_l + mut;
          kk[c] = cp * (mu_l / visc_.prandtl + mut / turb_.prandtl_t);
        }
    });
    // 3. Face fluxes, accumulated per cell (each cell gathers its own six faces:
    //    race-free and independent of the thread count).
    double* dU[5] = {dU_.template get<field::rho>(), dU_.template get<field::mx>(), dU_.template get<field::my>(),
                     dU_.template get<field::mz>(), dU_.template get<field::E>()};
    auto face = [&](int d, index_t cm, index_t cc, double idc, double out[4]) {
      // Gradient at the face: normal from the two cells, tangential averaged.
      double g[3][3], gT[3];
      for (int e = 0; e < 3; ++e) {
        if (e == d) {
          for (int a = 0; a < 3; ++a) g[a][e] = (ub[a][cc] - ub[a][cm]) * idc;
          gT[e] = (Tc[cc] - Tc[cm]) * idc;
        } else {
          for (int a = 0; a < 3; ++a) g[a][e] = 0.5 * (G[a][e][cm] + G[a][e][cc]);
          gT[e] = 0.5 * (GT[e][cm] + GT[e][cc]);
        }
      }
      const double muf = 0.5 * (mu[cm] + mu[cc]), kf = 0.5 * (kk[cm] + kk[cc]);
      const double div = g[0][0] + g[1][1] + g[2][2];
      double tau[3];
      for (int a = 0; a < 3; ++a) tau[a] = muf * (g[a][d] + g[d][a] - (a == d ? 2.0 / 3.0 * div : 0.0));
      double work = 0.0;
      for (int a = 0; a < 3; ++a) work += tau[a] * 0.5 * (ub[a][cm] + ub[a][cc]);
      const Eigen::Vector3d ti = geo.R * Eigen::Vector3d(tau[0], tau[1], tau[2]);
      out[0] = ti[0];
      out[1] = ti[1];
      out[2] = ti[2];
      out[3] = work + kf * gT[d];
    };
    par_for(0, nz, [&](index_t k) {
      for (index_t j = 0; j < ny; ++j)
        for (index_t i = 0; i < nx; ++i) {
          const index_t c = grid_.index(i, j, k);
          const index_t ijk[3] = {i, j, k};
          double acc[4] = {0, 0, 0, 0};
          for (int d = 0; d < 3; ++d) {
            const index_t s = grid_.stride(d);
            const double* idc = grid_.inv_centre_gaps(d);
            const double inv_h = grid_.inv_widths(d)[ijk[d]];
            double lo[4], hi[4];
            face(d, c - s, c, idc[ijk[d]], lo);
            face(d, c, c + s, idc[ijk[d] + 1], hi);
            for (int q = 0; q < 4; ++q) acc[q] += (hi[q] - lo[q]) * inv_h;
          }
          dU[1][c] += acc[0];
          dU[2][c] += acc[1];
          dU[3][c] += acc[2];
          dU[4][c] += acc[3];
        }
    });
  }

  void setup_sponge() {
    if (bc_.layer.cells <= 0) return;
    sponge_.emplace(grid_.total_cells(), 0.0);
    double* sig = sponge_->template get<field::sponge_sigma>();
    const index_t L = bc_.layer.cells;
    double cinf = 340.0;
    for (const auto& f : bc_.face)
      if (auto* ff = std::get_if<boundary::far_field>(&f)) {
        cinf = gas_.sound_speed(ff->rho, ff->p);
        break;
      }
    for (index_t k = 0; k < grid_.n(2); ++k)
      for (index_t j = 0; j < grid_.n(1); ++j)
        for (index_t i = 0; i < grid_.n(0); ++i) {
          const index_t ijk[3] = {i, j, k};
          double s = 0.0;
          for (int d = 0; d < 3; ++d)
            for (int hi = 0; hi < 2; ++hi) {
              if (!std::holds_alternative<boundary::far_field>(bc_.face[std::size_t(2 * d + hi)])) continue;
              const index_t dist = hi ? grid_.n(d) - 1 - ijk[d] : ijk[d];  // cells from the face
              if (dist >= L) continue;
              double thick = 0.0;
              for (index_t q = 0; q < L && q < grid_.n(d); ++q) thick += grid_.width(d, hi ? grid_.n(d) - 1 - q : q);
              const double xi = double(L - dist) / double(L);
              s = std::max(s, bc_.layer.strength * cinf / thick * xi * xi * xi);
            }
          sig[grid_.index(i, j, k)] = s;
        }
    // Target state: the first far-field face's state.
    for (const auto& f : bc_.face)
      if (auto* ff = std::get_if<boundary::far_field>(&f)) {
        sponge_target_ = to_cons(ff->state(), gas_);
        break;
      }
  }

  void add_sources() {
    double* dU[5] = {dU_.template get<field::rho>(), dU_.template get<field::mx>(), dU_.template get<field::my>(),
                     dU_.template get<field::mz>(), dU_.template get<field::E>()};
    const double* U[5] = {U_.template get<field::rho>(), U_.template get<field::mx>(), U_.template get<field::my>(),
                          U_.template get<field::mz>(), U_.template get<field::E>()};
    const index_t nx = grid_.n(0), ny = grid_.n(1), nz = grid_.n(2);
    const double tgt[5] = {sponge_target_.rho, sponge_target_.m.x, sponge_target_.m.y, sponge_target_.m.z,
                           sponge_target_.E};
    par_for(0, ny * nz, [&](index_t r) {
      const index_t base = grid_.index(0, r % ny, r / ny);
      for (index_t i = 0; i < nx; ++i) {
        const index_t c = base + i;
        if (sources_) {
          dU[0][c] += sources_->template get<field::s_rho>()[c];
          dU[1][c] += sources_->template get<field::s_mx>()[c];
          dU[2][c] += sources_->template get<field::s_my>()[c];
          dU[3][c] += sources_->template get<field::s_mz>()[c];
          dU[4][c] += sources_->template get<field::s_E>()[c];
        }
        if (sponge_) {
          const double s = sponge_->template get<field::sponge_sigma>()[c];
          if (s > 0.0)
            for (int f = 0; f < 5; ++f) dU[f][c] -= s * (U[f][c] - tgt[f]);
        }
      }
    });
  }

  /// U ← a U0 + b (U + dt dU) on interior cells; with `check`, a non-finite or
  /// non-positive density/pressure stops the run naming the cell, time and values.
  void update(double a, double b, double dt, double t_new, bool check) {
    timed(times_.update, [&] {
      const index_t nx = grid_.n(0), ny = grid_.n(1), nz = grid_.n(2);
      double* U[5] = {U_.template get<field::rho>(), U_.template get<field::mx>(), U_.template get<field::my>(),
                      U_.template get<field::mz>(), U_.template get<field::E>()};
      const double* U0[5] = {U0_.template get<field::rho>(), U0_.template get<field::mx>(),
                             U0_.template get<field::my>(), U0_.template get<field::mz>(),
                             U0_.template get<field::E>()};
      const double* dU[5] = {dU_.template get<field::rho>(), dU_.template get<field::mx>(),
                             dU_.template get<field::my>(), dU_.template get<field::mz>(),
                             dU_.template get<field::E>()};
      std::vector<char> bad(std::size_t(ny * nz), 0);
      const gas::ideal g = gas_;
      par_for(0, ny * nz, [&](index_t r) {
        const index_t base = grid_.index(0, r % ny, r / ny);
        bool row_bad = false;
        simd::for_each_pack(0, nx, [&](auto tag, index_t i) {
          using V = typename decltype(tag)::type;
          const index_t c = base + i;
          V q[5];
          for (int f = 0; f < 5; ++f) {
            q[f] = V(a) * simd::load<V>(U0[f] + c) + V(b) * (simd::load<V>(U[f] + c) + V(dt) * simd::load<V>(dU[f] + c));
            simd::store(U[f] + c, q[f]);
          }
          if (check) {
            const V p = g.pressure(q[0], q[1], q[2], q[3], q[4]);
            const auto ok = (q[0] > V(0.0)) && (p > V(0.0));
            row_bad = row_bad || !simd::all(ok) || !simd::all_finite(p);
          }
        });
        bad[std::size_t(r)] = row_bad;
      });
      if (!check) return;
      for (index_t r = 0; r < ny * nz; ++r) {
        if (!bad[std::size_t(r)]) continue;
        const index_t j = r % ny, k = r / ny;
        for (index_t i = 0; i < nx; ++i) {
          const auto q = load_cons(U_, grid_.index(i, j, k));
          const double p = g.pressure(q.rho, q.m.x, q.m.y, q.m.z, q.E);
          if (!(q.rho > 0.0) || !(p > 0.0) || !std::isfinite(p)) {
            const Eigen::Vector3d x = pose_.to_inertial({grid_.centre(0, i), grid_.centre(1, j), grid_.centre(2, k)});
            throw numerical_failure(
                detail::concat("fluid::solver: non-physical state in cell (", i, ", ", j, ", ", k, ") at x = (", x[0],
                               ", ", x[1], ", ", x[2], ") m, t = ", t_new, " s: rho = ", q.rho, " kg/m^3, p = ", p,
                               " Pa, momentum = (", q.m.x, ", ", q.m.y, ", ", q.m.z, "); reduce the time step "
                               "(CFL) or check the set-up"),
                grid_.index(i, j, k), t_new);
          }
        }
      }
    });
  }

  rectilinear_grid grid_;
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
  std::optional<soa<field::s_mx, field::s_my, field::s_mz, field::s_E, field::s_rho>> sources_;
  std::optional<soa<field::sponge_sigma>> sponge_;
  cons<double> sponge_target_{1.18, {0, 0, 0}, 101325.0 / 0.4};
  std::vector<row_buffers> bufs_;
  std::vector<std::pair<index_t, int>> patches_;
  face_handler patch_handler_;
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
