// A cable chain under gravity between two pinned points at equal height, brought to
// rest by damped explicit dynamics; the check is the catenary
// (include/parafsi/structure/reference/catenary.hpp).
//
//   hanging_chain --links 40 --length 1.2 --span 1.0 --out chain.csv
//
// Writes `x,z` of the nodes (supports at z = 0, x from −S/2 to S/2) to --out, prints
// `max_deviation_over_span=<value>` against the catenary on stdout, progress on stderr.
#include <CLI/CLI.hpp>

#include "cli_checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include <parafsi/core/parallel.hpp>
#include <parafsi/io/checked_file.hpp>
#include <parafsi/structure/assembly.hpp>
#include <parafsi/structure/cable.hpp>
#include <parafsi/structure/reference/catenary.hpp>
#include <parafsi/structure/relax.hpp>

namespace st = parafsi::structure;

int main(int argc, char** argv) {
  CLI::App app{"Cable chain under gravity between two pinned points, relaxed to rest (catenary check)"};
  int links = 0, threads = 1;
  double L = 0, S = 0, EA = 1e4, rho_l = 0.1, xi = 0.2, tol = 1e-10;
  std::string out;
  app.add_option("--links", links, "number of cable elements N")->required()->check(CLI::Range(2, 100000));
  app.add_option("--length", L, "unstretched chain length L (m)")->required()->check(CLI::Range(1e-3, 1e4));
  app.add_option("--span", S, "distance S between the supports (m), S < L")->required()->check(CLI::Range(1e-3, 1e4));
  app.add_option("--EA", EA, "axial stiffness (N)")->check(CLI::Range(1e-3, 1e12))->capture_default_str();
  app.add_option("--mass-per-length", rho_l, "kg/m")->check(CLI::Range(1e-6, 1e4))->capture_default_str();
  app.add_option("--damping-ratio", xi, "axial damping ratio of each link")
      ->check(CLI::Range(0.0, 0.99))
      ->capture_default_str();
  app.add_option("--tolerance", tol, "stop when kinetic energy < tolerance x its peak")
      ->check(CLI::Range(1e-20, 1e-2))
      ->capture_default_str();
  app.add_option("--threads", threads, "OpenMP threads")->check(CLI::Range(1, 1024))->capture_default_str();
  app.add_option("--out", out, "CSV file (x,z)")->required();
  if (int rc = 0; !examples::parse(app, argc, argv, rc)) return rc;
  if (!(S < L)) {
    std::fprintf(stderr, "hanging_chain: --span %g must be smaller than --length %g\n", S, L);
    return 1;
  }
  try {
    parafsi::parallel::set_threads(threads);
    // Start: a V between the supports with the right link lengths (taut enough to hang).
    st::nodes nd;
    const double h = std::sqrt(std::max(0.0, 0.25 * L * L - 0.25 * S * S));
    for (int i = 0; i <= links; ++i) {
      const double s = double(i) / links;
      nd.add({-0.5 * S + S * s, 0.0, -2.0 * h * std::min(s, 1.0 - s)});
    }
    nd.pin(0);
    nd.pin(links);
    st::line_mesh lm;
    for (int i = 0; i < links; ++i) {
      lm.segments.push_back({i, i + 1});
      lm.rest_length.push_back(L / links);
    }
    st::assembly chain{std::move(nd), st::cable{lm, st::material::cable{EA, rho_l, xi, 0.0}}};
    const auto cat = st::reference::catenary(S, L);
    // Slowest pendulum mode ω ≈ √(g / sag); damp it near critically.
    const double omega1 = std::sqrt(9.81 / std::max(cat.sag(), 1e-3 * S));
    chain.integrator().mass_damping = 2.0 * omega1;
    std::fprintf(stderr, "hanging_chain: %d links, dt = %.3e s, catenary a = %.6g m, sag = %.6g m\n", links,
                 chain.stable_dt(), cat.a, cat.sag());
    st::relax_options ro;
    ro.tolerance = tol;
    ro.t_min = 4.0 * std::numbers::pi / omega1;
    ro.t_max = 2000.0 / omega1;
    ro.report_every = 20000;
    const auto r = st::relax(chain, ro, [&](double t, double k, double kp) {
      std::fprintf(stderr, "  t = %.4e s  mid z = %.6e m  K/Kpeak = %.3e\n", t,
                   chain.node_set().position(links / 2).z(), k / kp);
    });
    if (!r.converged) {
      std::fprintf(stderr, "hanging_chain: not at rest after t = %.3e s\n", r.time);
      return 2;
    }
    std::ostringstream f;  // written through io::checked_file below
    f.precision(10);
    f << "x,z\n";
    double dev = 0;
    for (int i = 0; i <= links; ++i) {
      const auto x = chain.node_set().position(i);
      f << x.x() << "," << x.z() << "\n";
      dev = std::max(dev, std::abs(x.z() - cat.z(x.x())));
    }
    parafsi::io::write_text_file(out, f.str());
    std::fprintf(stderr, "hanging_chain: at rest after %ld steps, t = %.4e s\n", r.steps, r.time);
    std::printf("mid_sag=%.10g\ncatenary_sag=%.10g\nmax_deviation_over_span=%.6e\n",
                -chain.node_set().position(links / 2).z(), cat.sag(), dev / S);
    return 0;
  } catch (const parafsi::error& e) {
    std::fprintf(stderr, "hanging_chain: %s\n", e.what());
    return 1;
  }
}
