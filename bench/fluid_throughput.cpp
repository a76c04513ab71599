// Fluid throughput: cell-updates per second of one full SSP-RK2 step (both stages:
// ghosts, primitives, reconstruction, Riemann fluxes, update) for every flux ×
// reconstruction, on N³ periodic boxes with a smooth density/velocity field,
// for the requested thread counts. Prints min/median/max over repeats.
//
//   fluid_throughput [--cells 64,128] [--threads 1,2] [--repeats 5] [--steps 3]
//                    [--flux all|hllc_lm|...] [--recon all|van_leer|...]
#include <parafsi/parafsi.hpp>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace pf = parafsi;

template <class Flux, class Recon>
void run(const char* fname, const char* rname, int n, int threads, int repeats, int steps) {
  pf::parallel::set_threads(threads);
  auto grid = pf::fluid::rectilinear_grid::uniform({n, n, n}, {0, 0, 0}, {1, 1, 1});
  pf::fluid::solver s{grid, pf::boundary::set::all(pf::boundary::periodic{}), Flux{}, Recon{}};
  s.initialize([](const Eigen::Vector3d& x) {
    const double k = 2 * M_PI;
    return pf::fluid::prim<double>{1.0 + 0.2 * std::sin(k * x[0]) * std::cos(k * x[1]),
                                   {0.3 * std::sin(k * x[2]), 0.2 * std::cos(k * x[0]), 0.1},
                                   1.0 + 0.1 * std::cos(k * x[1])};
  });
  const double dt = s.stable_dt(0.4);
  s.step(dt);  // warm-up (allocations of row buffers, page faults)
  std::vector<double> rates;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < steps; ++k) s.step(dt);
    const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    rates.push_back(double(n) * n * n * steps / sec);
  }
  std::sort(rates.begin(), rates.end());
  std::printf(
      "fluid_throughput flux=%s recon=%s cells=%d threads=%d cell_updates_per_s=%.4g"
      " min=%.4g max=%.4g simd_width=%zu\n",
      fname, rname, n * n * n, threads, rates[rates.size() / 2], rates.front(), rates.back(), pf::simd::width);
  std::fflush(stdout);
}

template <class Flux>
void run_recons(const char* fname, const std::string& recon, int n, int t, int rep, int st) {
  if (recon == "all" || recon == "van_leer")
    run<Flux, pf::recon::muscl<pf::limiter::van_leer>>(fname, "van_leer", n, t, rep, st);
  if (recon == "all" || recon == "minmod")
    run<Flux, pf::recon::muscl<pf::limiter::minmod>>(fname, "minmod", n, t, rep, st);
  if (recon == "all" || recon == "mc") run<Flux, pf::recon::muscl<pf::limiter::mc>>(fname, "mc", n, t, rep, st);
  if (recon == "all" || recon == "none") run<Flux, pf::recon::first_order>(fname, "none", n, t, rep, st);
}

int main(int argc, char** argv) {
  CLI::App app{"Fluid solver throughput (cell-updates/s of full SSP-RK2 steps)"};
  std::vector<int> cells{64, 128}, threads{1, 2};
  int repeats = 5, steps = 3;
  std::string flux = "all", recon = "all";
  app.add_option("--cells", cells, "box sizes N (N^3 cells)")->delimiter(',')->check(CLI::Range(8, 512));
  app.add_option("--threads", threads, "thread counts")->delimiter(',')->check(CLI::Range(1, 256));
  app.add_option("--repeats", repeats, "timed repeats")->check(CLI::Range(1, 100));
  app.add_option("--steps", steps, "steps per repeat")->check(CLI::Range(1, 1000));
  app.add_option("--flux", flux)->check(CLI::IsMember({"all", "hllc_lm", "hllc", "rusanov", "ausm_plus_up"}));
  app.add_option("--recon", recon)->check(CLI::IsMember({"all", "van_leer", "minmod", "mc", "none"}));
  CLI11_PARSE(app, argc, argv);
  std::printf("# reproduce: %s", argv[0]);
  for (int i = 1; i < argc; ++i) std::printf(" %s", argv[i]);
  std::printf("\n# OpenMP %s, max threads %d, SIMD lanes %zu\n", pf::parallel::enabled() ? "on" : "off",
              pf::parallel::max_threads(), pf::simd::width);
  for (int n : cells)
    for (int t : threads) {
      if (flux == "all" || flux == "hllc_lm") run_recons<pf::flux::hllc_lm>("hllc_lm", recon, n, t, repeats, steps);
      if (flux == "all" || flux == "hllc") run_recons<pf::flux::hllc>("hllc", recon, n, t, repeats, steps);
      if (flux == "all" || flux == "rusanov") run_recons<pf::flux::rusanov>("rusanov", recon, n, t, repeats, steps);
      if (flux == "all" || flux == "ausm_plus_up")
        run_recons<pf::flux::ausm_plus_up>("ausm_plus_up", recon, n, t, repeats, steps);
    }
}
