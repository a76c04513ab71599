// Gresho vortex: a stationary, incompressible rotating flow in pressure balance,
// the standard probe of low-Mach dissipation (Gresho & Chan 1990; Miczek, Röpke &
// Edelmann 2015, A&A 576:A50).
//
//   gresho_vortex --mach M --cells N [--flux F] [--limiter L] [--t-end T] --out FILE.csv
//
// Domain [0, 1]² (N × N cells) × 2 cells in z, periodic everywhere; ρ = 1, γ = 1.4,
// centre (0.5, 0.5), azimuthal velocity
//   u_φ = 5r (r < 0.2),  2 − 5r (0.2 ≤ r < 0.4),  0 (r ≥ 0.4)   (peak 1 at r = 0.2),
// pressure p = p0 + 12.5 r²                              (r < 0.2)
//              p0 + 12.5 r² + 4 − 20 r + 4 ln(5r)          (0.2 ≤ r < 0.4)
//              p0 − 2 + 4 ln 2                              (r ≥ 0.4)
// with p0 = ρ/(γM²): the peak Mach number (peak speed over the sound speed at p0) is M.
// Cells are initialised with cell averages (4³-point midpoint quadrature).
// Prints kinetic_energy_ratio = E_k(T)/E_k(0), E_k = Σ ½ρ|u|² V, and writes
// `x,y,rho,u,v,p` (z-averaged), one row per x–y cell, at the final time (default T = 1).
#include "example_common.hpp"

#include <cstdio>

namespace {

namespace pf = parafsi;

struct options {
  examples::common_options common;
  double mach = 0.1;
  int cells = 64;
  double t_end = 1.0;
  std::string out;
};

constexpr double gamma_ = 1.4;

template <class Solver>
double kinetic_energy(const Solver& s) {
  return s.totals().kinetic;
}

template <class Flux, class Recon>
int run(const options& o) {
  const pf::index_t N = o.cells;
  const double p0 = 1.0 / (gamma_ * o.mach * o.mach);
  // z: 2 cells as wide as the domain, so the trivial z direction does not cut the step.
  auto grid = pf::fluid::rectilinear_grid::uniform({N, N, 2}, {0.0, 0.0, 0.0}, {1.0, 1.0, 2.0});
  pf::fluid::solver s{grid, pf::boundary::set::all(pf::boundary::periodic{}), Flux{}, Recon{}};
  const pf::fluid::reference::gresho_vortex vortex{o.mach, gamma_};
  s.initialize_averaged([&](const Eigen::Vector3d& xi) { return vortex(xi[0], xi[1]); }, 4);
  const double ek0 = kinetic_energy(s);

  examples::progress prog("gresho_vortex", o.t_end, o.common.quiet);
  const auto t0 = std::chrono::steady_clock::now();
  if (o.t_end > 0.0) examples::run_to(s, o.t_end, o.common.cfl, prog);
  const double wall = examples::seconds_since(t0);
  const double ek = kinetic_energy(s);

  examples::csv_writer csv(o.out, "x,y,rho,u,v,p");
  for (pf::index_t j = 0; j < N; ++j)
    for (pf::index_t i = 0; i < N; ++i) {
      const auto a = s.primitive(i, j, 0), b = s.primitive(i, j, 1);
      csv.row({grid.centre(0, i), grid.centre(1, j), 0.5 * (a.rho + b.rho), 0.5 * (a.u.x + b.u.x),
               0.5 * (a.u.y + b.u.y), 0.5 * (a.p + b.p)});
    }
  csv.close();

  std::printf("gresho_vortex flux=%s limiter=%s mach=%g cells=%d p0=%.6g t_end=%g steps=%ld\n", Flux::name(),
              Recon::name(), o.mach, o.cells, p0, s.time(), s.steps());
  std::printf("kinetic_energy_ratio=%.6f\n", ek / ek0);
  std::printf("wall_seconds=%.3f\n", wall);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Gresho vortex on [0,1]^2 x 2 cells in z at peak Mach number M; prints the kinetic-energy "
      "ratio E_k(T)/E_k(0)."};
  options o;
  app.add_option("--mach", o.mach, "peak Mach number M (background pressure p0 = 1/(gamma M^2))")
      ->check(CLI::Range(1e-5, 2.0))
      ->capture_default_str();
  examples::add_cells_option(app, o.cells, "cells per side of the x-y plane", 4);
  examples::add_flux_option(app, o.common);
  examples::add_limiter_option(app, o.common);
  app.add_option("--t-end", o.t_end, "end time")->check(CLI::Range(0.0, 1e4))->capture_default_str();
  examples::add_out_option(app, o.out);
  examples::add_run_options(app, o.common);
  int code = 0;
  if (!examples::parse(app, argc, argv, code)) return code;
  examples::apply_threads(o.common);
  return examples::guarded("gresho_vortex", [&] {
    return examples::dispatch(o.common.flux, o.common.limiter,
                              [&](auto fl, auto rc) { return run<decltype(fl), decltype(rc)>(o); });
  });
}
