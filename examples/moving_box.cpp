// Free-stream preservation on a moving box.
//
//   moving_box [--steps N] [--cells N] [--flux F] [--limiter L] [--tolerance TOL]
//
// Uniform quiescent air (ρ = 1.18 kg/m³, p = 101325 Pa, u = 0) in the box
// [−1, 1]³ m (N³ cells, default 16³) that translates at 20 m/s along (2, 1, 2)/3 and
// rotates at 1 rad/s about (1, 2, 2)/3 (frame::rigid), with far-field boundaries
// (the same quiescent state) on all six faces, for N steps (default 10⁴) at the
// stable step. The solver carries absolute (inertial) velocities, so the exact
// solution stays at rest. After every step the maximum deviations
//   max |u| (m/s)  and  max |p − 101325| (Pa)
// over all cells are tracked; the relative values are max|u| / 20 m/s (the box
// speed) and max|p − p∞| / p∞. Prints
//   max_velocity_deviation=<m/s> max_pressure_deviation=<Pa>
//   relative_velocity_deviation=<-> relative_pressure_deviation=<->
// and exits with 1 if either relative value exceeds 1e-10 (round-off; --tolerance).
#include "example_common.hpp"

#include <cstdio>

namespace {

namespace pf = parafsi;

struct options {
  examples::common_options common;
  long steps = 10000;
  int cells = 16;
  double tolerance = 1e-10;
};

constexpr double rho_inf = 1.18, p_inf = 101325.0, box_speed = 20.0, spin = 1.0;

template <class Flux, class Recon>
int run(const options& o) {
  const pf::index_t N = o.cells;
  auto grid = pf::fluid::rectilinear_grid::uniform({N, N, N}, {-1.0, -1.0, -1.0}, {1.0, 1.0, 1.0});
  pf::boundary::far_field ff;
  ff.rho = rho_inf;
  ff.u = {0.0, 0.0, 0.0};
  ff.p = p_inf;
  pf::frame::rigid motion;
  motion.velocity = box_speed * Eigen::Vector3d(2.0, 1.0, 2.0) / 3.0;
  motion.angular_velocity = spin * Eigen::Vector3d(1.0, 2.0, 2.0) / 3.0;
  pf::fluid::solver s{grid, pf::boundary::set::all(ff), Flux{}, Recon{}, motion};
  s.fill_uniform({rho_inf, {0.0, 0.0, 0.0}, p_inf});

  double du = 0.0, dp = 0.0;
  auto measure = [&] {
    for (pf::index_t k = 0; k < N; ++k)
      for (pf::index_t j = 0; j < N; ++j)
        for (pf::index_t i = 0; i < N; ++i) {
          const auto w = s.primitive(i, j, k);
          du = std::max(du, std::sqrt(w.u.x * w.u.x + w.u.y * w.u.y + w.u.z * w.u.z));
          dp = std::max(dp, std::fabs(w.p - p_inf));
          if (!std::isfinite(w.p) || !std::isfinite(w.u.x)) du = dp = HUGE_VAL;
        }
  };

  // The stable step of the uniform state on this box (constant: the state stays at rest).
  const double dt = s.stable_dt(o.common.cfl);
  examples::progress prog("moving_box", dt * double(o.steps), o.common.quiet);
  const auto t0 = std::chrono::steady_clock::now();
  for (long n = 0; n < o.steps; ++n) {
    s.step(dt);
    measure();
    prog(s.time(), s.steps());
  }
  prog.finish(s.time(), s.steps());
  const double wall = examples::seconds_since(t0);

  const double c = std::sqrt(s.gas().gamma * p_inf / rho_inf);
  const double rel_u = du / box_speed, rel_p = dp / p_inf;
  const Eigen::Vector3d X = s.pose().X;
  std::printf("moving_box flux=%s limiter=%s cells=%d^3 steps=%ld dt=%.6e t=%.6f box_origin=(%.4f, %.4f, %.4f)\n",
              Flux::name(), Recon::name(), o.cells, s.steps(), dt, s.time(), X[0], X[1], X[2]);
  std::printf("max_velocity_deviation=%.3e max_pressure_deviation=%.3e\n", du, dp);
  std::printf("relative_velocity_deviation=%.3e relative_pressure_deviation=%.3e\n", rel_u, rel_p);
  std::printf("velocity_deviation_over_sound_speed=%.3e\n", du / c);
  std::printf("wall_seconds=%.3f\n", wall);
  const bool ok = rel_u <= o.tolerance && rel_p <= o.tolerance;
  std::printf("free_stream_preservation=%s (--tolerance %.0e relative)\n", ok ? "PASS" : "FAIL", o.tolerance);
  return ok ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Free-stream preservation: quiescent air in a box translating at 20 m/s and rotating at "
      "1 rad/s; exits non-zero if the velocity or pressure deviation exceeds 1e-10 (relative)."};
  options o;
  app.add_option("--steps", o.steps, "time steps")->check(CLI::Range(1L, 100000000L))->capture_default_str();
  examples::add_cells_option(app, o.cells, "cells per side of the cube", 2);
  app.add_option("--tolerance", o.tolerance, "pass/fail threshold on the relative deviations")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  examples::add_flux_option(app, o.common);
  examples::add_limiter_option(app, o.common);
  examples::add_run_options(app, o.common);
  int code = 0;
  if (!examples::parse(app, argc, argv, code)) return code;
  examples::apply_threads(o.common);
  return examples::guarded("moving_box", [&] {
    return examples::dispatch(o.common.flux, o.common.limiter,
                              [&](auto fl, auto rc) { return run<decltype(fl), decltype(rc)>(o); });
  });
}
