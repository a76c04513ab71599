// Fluid throughput: cell-updates per second of one full SSP-RK2 step (both stages:
// ghosts, primitives, reconstruction, Riemann fluxes, update) for every flux ×
// reconstruction, on N³ periodic boxes with a smooth density/velocity field,
// for the requested thread counts. Prints min/median/max over repeats.
//
//   fluid_throughput [--cells 64,128] [--threads 1,2] [--repeats 5] [--steps 3]
//                    [--flux all|hllc_lm|...] [--recon all|van_leer|...]
//                    [--mesh tensor,blocks] [--block-size 8,16,32] [--refine-sphere R] [--phases]
//                    [--viscosity inviscid,constant] [--turbulence none,smagorinsky,mixing_length]
//
// --mesh tensor (the default) runs fluid::solver on the N³ box; --mesh blocks runs
// fluid::block_solver on the same cells as one level of (N/N_b)³ blocks of N_b³ cells
// (--block-size N_b, which must divide N); its lines carry `mesh=blocks block=N_b
// levels=L` at the end. --refine-sphere R refines the blocks that meet the sphere of
// radius R·(box edge) about the box centre by one level (two levels; `cells=` is then the
// leaf-cell count and the rate counts leaf cells). --phases adds a `# phases` line per
// run: seconds per step in each of the solver's timed phases.
// --viscosity (inviscid: the default; constant: air's μ, Pr = 0.72) and --turbulence (none: the
// default; smagorinsky; mixing_length: Prandtl's, no wall-distance field, so l_m = min(C_l L_ref, Δ))
// add the viscous pass; every combination listed runs, the viscous ones with HLLC-LM + van Leer
// only. Every line ends in `viscosity=... turbulence=...`.
#include <parafsi/parafsi.hpp>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <type_traits>
#include <vector>

namespace pf = parafsi;

namespace {
pf::fluid::prim<double> smooth_field(const Eigen::Vector3d& x) {
  const double k = 2 * M_PI;
  return pf::fluid::prim<double>{1.0 + 0.2 * std::sin(k * x[0]) * std::cos(k * x[1]),
                                 {0.3 * std::sin(k * x[2]), 0.2 * std::cos(k * x[0]), 0.1},
                                 1.0 + 0.1 * std::cos(k * x[1])};
}

struct settings {
  int repeats = 5, steps = 3;
  bool phases = false;
  double sphere = 0.0;  ///< refine-sphere radius (box edges); 0 = one level
};

/// Warm-up step, then `repeats` timed runs of `steps` steps; returns sorted rates.
template <class S>
std::vector<double> time_steps(S& s, double cells, const settings& o, pf::fluid::phase_times& per_step) {
  const double dt = s.stable_dt(0.4);
  s.step(dt);  // warm-up (allocations of row buffers, page faults)
  const pf::fluid::phase_times before = s.timings();
  std::vector<double> rates;
  for (int r = 0; r < o.repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < o.steps; ++k) s.step(dt);
    const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    rates.push_back(cells * o.steps / sec);
  }
  const pf::fluid::phase_times& after = s.timings();
  const double m = 1.0 / double(o.repeats * o.steps);
  per_step = {(after.boundaries - before.boundaries) * m, (after.primitives - before.primitives) * m,
              (after.fluxes - before.fluxes) * m,         (after.viscous - before.viscous) * m,
              (after.sources - before.sources) * m,       (after.update - before.update) * m};
  std::sort(rates.begin(), rates.end());
  return rates;
}

void print_phases(const pf::fluid::phase_times& p) {
  std::printf(
      "# phases s/step: boundaries=%.4g primitives=%.4g fluxes=%.4g update=%.4g total=%.4g viscous=%.4g "
      "sources=%.4g\n",
      p.boundaries, p.primitives, p.fluxes, p.update, p.total(), p.viscous, p.sources);
}

/// The physical models of a run: viscosity and turbulence policies and their names.
template <class Visc, class Turb>
struct models {
  const char* visc_name;
  const char* turb_name;
};

template <class Flux, class Recon, class Visc, class Turb>
void run_tensor(const char* fname, const char* rname, int n, int threads, const settings& o,
                const models<Visc, Turb>& md) {
  pf::parallel::set_threads(threads);
  auto grid = pf::fluid::rectilinear_grid::uniform({n, n, n}, {0, 0, 0}, {1, 1, 1});
  pf::fluid::solver s{grid, pf::boundary::set::all(pf::boundary::periodic{}), Flux{}, Recon{}, Visc{}, Turb{}};
  s.initialize(smooth_field);
  pf::fluid::phase_times ph;
  const auto rates = time_steps(s, double(n) * n * n, o, ph);
  std::printf(
      "fluid_throughput flux=%s recon=%s cells=%d threads=%d cell_updates_per_s=%.4g"
      " min=%.4g max=%.4g simd_width=%zu viscosity=%s turbulence=%s\n",
      fname, rname, n * n * n, threads, rates[rates.size() / 2], rates.front(), rates.back(), pf::simd::width,
      md.visc_name, md.turb_name);
  if (o.phases) print_phases(ph);
  std::fflush(stdout);
}

template <class Flux, class Recon, class Visc, class Turb>
void run_blocks(const char* fname, const char* rname, int n, int nb, int threads, const settings& o,
                const models<Visc, Turb>& md) {
  pf::parallel::set_threads(threads);
  const pf::index_t roots = n / nb;
  pf::fluid::blocks::tree tree({roots, roots, roots}, {true, true, true});
  if (o.sphere > 0.0)
    tree.refine_where(1, [&](const pf::fluid::blocks::location& q) {
      if (q.level > 0) return false;
      // Distance from the box centre to the block (box edge 1).
      double d2 = 0;
      for (int d = 0; d < 3; ++d) {
        const double lo = double(q.l[std::size_t(d)]) / double(roots), hi = lo + 1.0 / double(roots);
        const double c = std::clamp(0.5, lo, hi) - 0.5;
        d2 += c * c;
      }
      return d2 < o.sphere * o.sphere;
    });
  const pf::fluid::block_layout layout{{0, 0, 0}, {1, 1, 1}, {roots, roots, roots}, nb};
  pf::fluid::block_solver s{std::move(tree), layout, pf::boundary::set::all(pf::boundary::periodic{}), Flux{}, Recon{},
                            Visc{},          Turb{}};
  s.initialize(smooth_field);
  pf::fluid::phase_times ph;
  const auto rates = time_steps(s, double(s.cell_count()), o, ph);
  std::printf(
      "fluid_throughput flux=%s recon=%s cells=%lld threads=%d cell_updates_per_s=%.4g"
      " min=%.4g max=%.4g simd_width=%zu mesh=blocks block=%d levels=%d viscosity=%s turbulence=%s\n",
      fname, rname, static_cast<long long>(s.cell_count()), threads, rates[rates.size() / 2], rates.front(),
      rates.back(), pf::simd::width, nb, s.tree().finest_level() + 1, md.visc_name, md.turb_name);
  if (o.phases) print_phases(ph);
  std::fflush(stdout);
}

struct meshes {
  bool tensor = true, blocks = false;
  std::vector<int> block_sizes{16};
  std::vector<std::string> viscosity{"inviscid"}, turbulence{"none"};
  bool wants(const std::string& v, const std::string& t) const {
    return std::find(viscosity.begin(), viscosity.end(), v) != viscosity.end() &&
           std::find(turbulence.begin(), turbulence.end(), t) != turbulence.end();
  }
  bool any_viscous() const {
    return !(viscosity == std::vector<std::string>{"inviscid"} && turbulence == std::vector<std::string>{"none"});
  }
};

template <class Flux, class Recon, class Visc, class Turb>
void run_models(const char* fname, const char* rname, int n, int t, const meshes& m, const settings& o,
                const models<Visc, Turb>& md) {
  if (!m.wants(md.visc_name, md.turb_name)) return;
  if (m.tensor) run_tensor<Flux, Recon>(fname, rname, n, t, o, md);
  if (m.blocks)
    for (int nb : m.block_sizes) run_blocks<Flux, Recon>(fname, rname, n, nb, t, o, md);
}

template <class Flux, class Recon>
void run(const char* fname, const char* rname, int n, int t, const meshes& m, const settings& o) {
  namespace vi = pf::viscosity;
  namespace tu = pf::turbulence;
  run_models<Flux, Recon>(fname, rname, n, t, m, o, models<vi::inviscid, tu::none>{"inviscid", "none"});
  // The viscous pass with the default scheme only (each model is a solver instantiation).
  if constexpr (std::is_same_v<Flux, pf::flux::hllc_lm> &&
                std::is_same_v<Recon, pf::recon::muscl<pf::limiter::van_leer>>) {
    run_models<Flux, Recon>(fname, rname, n, t, m, o, models<vi::constant, tu::none>{"constant", "none"});
    run_models<Flux, Recon>(fname, rname, n, t, m, o, models<vi::constant, tu::smagorinsky>{"constant", "smagorinsky"});
    run_models<Flux, Recon>(fname, rname, n, t, m, o,
                            models<vi::constant, tu::prandtl_mixing_length>{"constant", "mixing_length"});
    run_models<Flux, Recon>(fname, rname, n, t, m, o, models<vi::inviscid, tu::smagorinsky>{"inviscid", "smagorinsky"});
    run_models<Flux, Recon>(fname, rname, n, t, m, o,
                            models<vi::inviscid, tu::prandtl_mixing_length>{"inviscid", "mixing_length"});
  }
}

template <class Flux>
void run_recons(const char* fname, const std::string& recon, int n, int t, const meshes& m, const settings& o) {
  if (recon == "all" || recon == "van_leer")
    run<Flux, pf::recon::muscl<pf::limiter::van_leer>>(fname, "van_leer", n, t, m, o);
  if (recon == "all" || recon == "minmod")
    run<Flux, pf::recon::muscl<pf::limiter::minmod>>(fname, "minmod", n, t, m, o);
  if (recon == "all" || recon == "mc") run<Flux, pf::recon::muscl<pf::limiter::mc>>(fname, "mc", n, t, m, o);
  if (recon == "all" || recon == "none") run<Flux, pf::recon::first_order>(fname, "none", n, t, m, o);
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Fluid solver throughput (cell-updates/s of full SSP-RK2 steps)"};
  std::vector<int> cells{64, 128}, threads{1, 2};
  std::vector<std::string> mesh{"tensor"};
  settings o;
  meshes m;
  std::string flux = "all", recon = "all";
  app.add_option("--cells", cells, "box sizes N (N^3 cells)")->delimiter(',')->check(CLI::Range(8, 512));
  app.add_option("--threads", threads, "thread counts")->delimiter(',')->check(CLI::Range(1, 256));
  app.add_option("--repeats", o.repeats, "timed repeats")->check(CLI::Range(1, 100));
  app.add_option("--steps", o.steps, "steps per repeat")->check(CLI::Range(1, 1000));
  app.add_option("--flux", flux)->check(CLI::IsMember({"all", "hllc_lm", "hllc", "rusanov", "ausm_plus_up"}));
  app.add_option("--recon", recon)->check(CLI::IsMember({"all", "van_leer", "minmod", "mc", "none"}));
  app.add_option("--mesh", mesh, "tensor (the box solver) and/or blocks (block_solver, one level)")
      ->delimiter(',')
      ->check(CLI::IsMember({"tensor", "blocks"}));
  app.add_option("--block-size", m.block_sizes, "cells per block edge N_b (even, 4..256, dividing N)")
      ->delimiter(',')
      ->check(CLI::Range(4, 256));
  app.add_option("--refine-sphere", o.sphere,
                 "blocks: refine the blocks meeting the sphere of this radius (box edges) about the centre by one "
                 "level")
      ->check(CLI::Range(0.0, 1.0));
  app.add_flag("--phases", o.phases, "print seconds per step of each timed phase");
  app.add_option("--viscosity", m.viscosity, "inviscid and/or constant (air's mu, Pr 0.72)")
      ->delimiter(',')
      ->check(CLI::IsMember({"inviscid", "constant"}));
  app.add_option("--turbulence", m.turbulence, "none, smagorinsky and/or mixing_length (Prandtl's)")
      ->delimiter(',')
      ->check(CLI::IsMember({"none", "smagorinsky", "mixing_length"}));
  CLI11_PARSE(app, argc, argv);
  if (m.any_viscous() && (flux != "hllc_lm" || recon != "van_leer")) {
    std::fprintf(stderr,
                 "fluid_throughput: --viscosity/--turbulence other than inviscid/none run with --flux hllc_lm "
                 "--recon van_leer only; got --flux %s --recon %s\n",
                 flux.c_str(), recon.c_str());
    return 1;
  }
  m.tensor = std::find(mesh.begin(), mesh.end(), "tensor") != mesh.end();
  m.blocks = std::find(mesh.begin(), mesh.end(), "blocks") != mesh.end();
  if (m.blocks)
    for (int n : cells)
      for (int nb : m.block_sizes)
        if (nb % 2 != 0 || n % nb != 0 || n / nb > pf::index_t(pf::fluid::blocks::tree::max_root)) {
          std::fprintf(stderr,
                       "fluid_throughput: --mesh blocks needs an even block size N_b that divides N with at most %lld "
                       "blocks per axis; got N = %d, N_b = %d\n",
                       static_cast<long long>(pf::fluid::blocks::tree::max_root), n, nb);
          return 1;
        }
  std::printf("# reproduce: %s", argv[0]);
  for (int i = 1; i < argc; ++i) std::printf(" %s", argv[i]);
  std::printf("\n# OpenMP %s, max threads %d, SIMD lanes %zu\n", pf::parallel::enabled() ? "on" : "off",
              pf::parallel::max_threads(), pf::simd::width);
  for (int n : cells)
    for (int t : threads) {
      if (flux == "all" || flux == "hllc_lm") run_recons<pf::flux::hllc_lm>("hllc_lm", recon, n, t, m, o);
      if (flux == "all" || flux == "hllc") run_recons<pf::flux::hllc>("hllc", recon, n, t, m, o);
      if (flux == "all" || flux == "rusanov") run_recons<pf::flux::rusanov>("rusanov", recon, n, t, m, o);
      if (flux == "all" || flux == "ausm_plus_up")
        run_recons<pf::flux::ausm_plus_up>("ausm_plus_up", recon, n, t, m, o);
    }
}
