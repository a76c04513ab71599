// Structure kernel throughput: element-updates/s of the membrane (CST triangle and
// Belytschko–Tsay quad) and cable force passes (compute + race-free scatter), 1 and 2
// threads, scalar vs SIMD instantiation.
//
//   structure_throughput [--rings 100] [--repeats 7]
//
// Prints one line per configuration:
//   structure_throughput part=<membrane_tri|membrane_quad|cable> elements=<n> threads=<t> simd=<scalar|simdW>
//     element_updates_per_s=<median> min=<..> max=<..>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <parafsi/core/parallel.hpp>
#include <parafsi/model/disk_mesh.hpp>
#include <parafsi/model/disk_quad_mesh.hpp>
#include <parafsi/structure/cable.hpp>
#include <parafsi/structure/membrane_quad.hpp>
#include <parafsi/structure/membrane_tri.hpp>

namespace st = parafsi::structure;
using parafsi::index_t;

template <class Part, class Run>
void measure(const char* name, Part& part, st::nodes& nd, int repeats, int threads, Run&& run_once, bool simd) {
  parafsi::parallel::set_threads(threads);
  const auto k = nd.kinematics();
  for (int w = 0; w < 3; ++w) run_once(k);  // warm-up
  std::vector<double> rate;
  for (int r = 0; r < repeats; ++r) {
    int reps = 0;
    const auto t0 = std::chrono::steady_clock::now();
    double el = 0;
    do {
      run_once(k);
      ++reps;
      el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    } while (el < 0.2);
    rate.push_back(double(part.size()) * reps / el);
  }
  std::sort(rate.begin(), rate.end());
  std::printf(
      "structure_throughput part=%s elements=%ld threads=%d simd=%s element_updates_per_s=%.4e min=%.4e "
      "max=%.4e\n",
      name, long(part.size()), threads, simd ? "simd" : "scalar", rate[rate.size() / 2], rate.front(), rate.back());
}

int main(int argc, char** argv) {
  CLI::App app{"Element-update throughput of the structural force kernels"};
  int rings = 100, repeats = 7;
  app.add_option("--rings", rings,
                 "disk mesh radial divisions (6 N^2 triangles; quads: O-grid of ~the same node count)")
      ->check(CLI::Range(2, 2000))
      ->capture_default_str();
  app.add_option("--repeats", repeats, "timed repeats (min/median/max)")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  std::printf("# command: structure_throughput --rings %d --repeats %d  (simd width %zu doubles, OpenMP %s)\n", rings,
              repeats, parafsi::simd::width, parafsi::parallel::enabled() ? "on" : "off");
  const auto d = parafsi::model::disk_mesh(1.0, rings);
  st::nodes nd;
  std::mt19937 g(1);
  std::uniform_real_distribution<double> u(-1e-3, 1e-3);
  for (const auto& p : d.positions) nd.add(1.001 * p + Eigen::Vector3d{u(g), u(g), u(g)});
  st::triangle_mesh m;
  m.triangles = d.triangles;
  m.reference = d.positions;
  st::membrane_tri mem{m, st::material::fabric<>{2e9, 1e9, 0.3, 0.3e9, 0.05, 1e-4}, st::membrane_options{0.05}};
  mem.set_pressure(100.0);
  // Cables: every mesh edge from a node to the next node id (a dense line set).
  st::line_mesh lm;
  for (const auto& t : d.triangles) lm.segments.push_back({t[0], t[1]});
  st::cable cab{lm, st::material::cable{1e4, 0.01, 0.1, 0.0}};
  nd.materialize();
  nd.reset_masses();
  mem.finalize(nd);
  cab.finalize(nd);
  nd.finalize_masses();
  cab.post_finalize(nd);
  // Quads: O-grid disk with about as many nodes as the triangle disk (3 N^2 quads),
  // same fabric, stiffness damping and hourglass control (r_hg = 0.05, r_w = 1).
  const int nq = std::max(2, 2 * ((rings + 1) / 2));  // (n+1)² + 4n·n/2 ≈ 3n² nodes
  const auto dq = parafsi::model::disk_quad_mesh(1.0, nq);
  st::nodes ndq;
  for (const auto& p : dq.positions) ndq.add(1.001 * p + Eigen::Vector3d{u(g), u(g), u(g)});
  st::quad_mesh qm;
  qm.quads = dq.quads;
  qm.reference = dq.positions;
  st::membrane_quad quad{qm, st::material::fabric<>{2e9, 1e9, 0.3, 0.3e9, 0.05, 1e-4}, st::quad_options{0.05}};
  quad.set_pressure(100.0);
  ndq.materialize();
  ndq.reset_masses();
  quad.finalize(ndq);
  ndq.finalize_masses();
  for (int threads : {1, 2}) {
    measure(
        "membrane_tri", mem, nd, repeats, threads,
        [&](const auto& k) {
      mem.compute_forces<false, false>(k);
      mem.scatter<false>(nd);
        },
        false);
    measure(
        "membrane_tri", mem, nd, repeats, threads,
        [&](const auto& k) {
      mem.compute_forces<false, true>(k);
      mem.scatter<false>(nd);
        },
        true);
    measure(
        "membrane_quad", quad, ndq, repeats, threads,
        [&](const auto& k) {
      quad.compute_forces<false, false>(k);
      quad.scatter<false>(ndq);
        },
        false);
    measure(
        "membrane_quad", quad, ndq, repeats, threads,
        [&](const auto& k) {
      quad.compute_forces<false, true>(k);
      quad.scatter<false>(ndq);
        },
        true);
    measure(
        "cable", cab, nd, repeats, threads,
        [&](const auto& k) {
      cab.compute_forces<false, false>(k);
      cab.scatter<false>(nd);
        },
        false);
    measure(
        "cable", cab, nd, repeats, threads,
        [&](const auto& k) {
      cab.compute_forces<false, true>(k);
      cab.scatter<false>(nd);
        },
        true);
  }
  return 0;
}
