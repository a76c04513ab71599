// Shock tube: Toro's 1-D Riemann problems on the 3-D solver along one box axis.
//
//   shock_tube --problem sod|lax|toro2|toro3 --flux hllc_lm|hllc|rusanov|ausm_plus_up
//              --limiter van_leer|minmod|mc|none --cells N --axis x|y|z [--t-end T]
//              --out FILE.csv
//
// Domain [0, 1] along the chosen axis with the diaphragm at x0 = 0.5, zero-gradient
// outflow at both ends (the waves do not reach them before the default end times),
// 2 x 2 transverse cells of width 0.5 with periodic faces. γ = 1.4.
// Writes `x,rho,u,p` (u = velocity along the axis), one row per cell along the axis,
// and prints the L1 errors of rho, u, p against the exact Riemann solution
// (sampled at cell centres, Σ |q_i − q_exact(x_i)| Δx_i) and the run time.
#include "example_common.hpp"

#include <array>
#include <cstdio>
#include <map>

namespace {

namespace pf = parafsi;
using examples::common_options;

struct problem {
  pf::fluid::riemann_state L, R;
  double t_end;
};

const std::map<std::string, problem> problems{
    {"sod", {{1.0, 0.0, 1.0}, {0.125, 0.0, 0.1}, 0.2}},
    {"lax", {{0.445, 0.698, 3.528}, {0.5, 0.0, 0.571}, 0.14}},
    {"toro2", {{1.0, -2.0, 0.4}, {1.0, 2.0, 0.4}, 0.15}},
    {"toro3", {{1.0, 0.0, 1000.0}, {1.0, 0.0, 0.01}, 0.012}},
};

struct options {
  common_options common;
  std::string problem = "sod";
  int cells = 200;
  std::string axis = "x";
  double t_end = -1.0;  // < 0: the problem's default
  std::string out;
};

constexpr double x0 = 0.5;

template <class Flux, class Recon>
int run(const options& o) {
  const problem& pb = problems.at(o.problem);
  const int d = o.axis == "x" ? 0 : (o.axis == "y" ? 1 : 2);
  const double t_end = o.t_end >= 0.0 ? o.t_end : pb.t_end;

  std::array<pf::index_t, 3> n{2, 2, 2};
  std::array<double, 3> lo{0, 0, 0}, hi{1, 1, 1};
  n[std::size_t(d)] = o.cells;
  auto grid = pf::fluid::rectilinear_grid::uniform(n, lo, hi);
  auto bc = pf::boundary::set::all(pf::boundary::periodic{});
  bc.axis(d, pf::boundary::outflow{});
  pf::fluid::solver s{grid, bc, Flux{}, Recon{}};

  auto state = [&](const pf::fluid::riemann_state& r) {
    pf::fluid::prim<double> w{r.rho, {0.0, 0.0, 0.0}, r.p};
    (d == 0 ? w.u.x : (d == 1 ? w.u.y : w.u.z)) = r.u;
    return w;
  };
  const auto wL = state(pb.L), wR = state(pb.R);
  s.initialize([&](const Eigen::Vector3d& xi) { return xi[d] < x0 ? wL : wR; });

  examples::progress prog("shock_tube", t_end, o.common.quiet);
  const auto t0 = std::chrono::steady_clock::now();
  if (t_end > 0.0) examples::run_to(s, t_end, o.common.cfl, prog);
  const double wall = examples::seconds_since(t0);

  const pf::fluid::exact_riemann exact(pb.L, pb.R, s.gas().gamma);
  examples::csv_writer csv(o.out, "x,rho,u,p");
  double e_rho = 0, e_u = 0, e_p = 0, min_rho = 1e300, min_p = 1e300;
  for (pf::index_t i = 0; i < o.cells; ++i) {
    // Mean over the 2 x 2 transverse cells (identical up to round-off).
    double rho = 0, u = 0, p = 0;
    for (pf::index_t b = 0; b < 2; ++b)
      for (pf::index_t a = 0; a < 2; ++a) {
        std::array<pf::index_t, 3> ijk{a, b, b};
        ijk[std::size_t(d)] = i;
        ijk[std::size_t((d + 1) % 3)] = a;
        ijk[std::size_t((d + 2) % 3)] = b;
        const auto w = s.primitive(ijk[0], ijk[1], ijk[2]);
        rho += 0.25 * w.rho;
        u += 0.25 * (d == 0 ? w.u.x : (d == 1 ? w.u.y : w.u.z));
        p += 0.25 * w.p;
        min_rho = std::min(min_rho, w.rho);
        min_p = std::min(min_p, w.p);
      }
    const double x = grid.centre(d, i), dx = grid.width(d, i);
    csv.row({x, rho, u, p});
    const auto ex = t_end > 0.0 ? exact.sample((x - x0) / t_end) : (x < x0 ? pb.L : pb.R);
    e_rho += std::fabs(rho - ex.rho) * dx;
    e_u += std::fabs(u - ex.u) * dx;
    e_p += std::fabs(p - ex.p) * dx;
  }
  csv.close();

  std::printf("shock_tube problem=%s flux=%s limiter=%s cells=%d axis=%s t_end=%g steps=%ld\n", o.problem.c_str(),
              Flux::name(), Recon::name(), o.cells, o.axis.c_str(), s.time(), s.steps());
  std::printf("l1_rho=%.6e l1_u=%.6e l1_p=%.6e\n", e_rho, e_u, e_p);
  std::printf("min_rho=%.6e min_p=%.6e\n", min_rho, min_p);
  std::printf("wall_seconds=%.3f\n", wall);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Toro's 1-D Riemann problems (Sod, Lax, 123, blast) along one axis of the 3-D fluid solver; "
      "writes x,rho,u,p and prints L1 errors against the exact solution."};
  options o;
  std::vector<std::string> problem_names;
  for (const auto& [k, v] : problems) problem_names.push_back(k);
  app.add_option("--problem", o.problem, "sod (t=0.2), lax (t=0.14), toro2 (123, t=0.15), toro3 (t=0.012)")
      ->check(CLI::IsMember(problem_names))
      ->capture_default_str();
  examples::add_flux_option(app, o.common);
  examples::add_limiter_option(app, o.common);
  examples::add_cells_option(app, o.cells, "cells along the axis", 2);
  app.add_option("--axis", o.axis, "box axis of the tube")
      ->check(CLI::IsMember({"x", "y", "z"}))
      ->capture_default_str();
  app.add_option("--t-end", o.t_end, "end time (default: the problem's)")->check(CLI::Range(0.0, 1e3));
  examples::add_out_option(app, o.out);
  examples::add_run_options(app, o.common);
  int code = 0;
  if (!examples::parse(app, argc, argv, code)) return code;
  examples::apply_threads(o.common);
  return examples::guarded("shock_tube", [&] {
    return examples::dispatch(o.common.flux, o.common.limiter,
                              [&](auto fl, auto rc) { return run<decltype(fl), decltype(rc)>(o); });
  });
}
