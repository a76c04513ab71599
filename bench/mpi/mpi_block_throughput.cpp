// Throughput of the block mesh over MPI processes (mpi/block_halo.hpp): a periodic unit box
// of N³ cells as (N/N_b)³ root blocks of N_b³ cells, optionally with the blocks near the
// centre refined once (--refine-sphere R), advancing a smooth field for --steps steps
// (SSP-RK2, HLLC-LM + van Leer). Prints, from rank 0, the whole mesh's cell-updates per
// second, and per rank and step the point-to-point messages and bytes the halo sent (its
// own counters), the seconds spent in the exchange and in the split (the partition and the
// exchange lists, as at every regrid, the slowest rank: the split construction, or
// set_halo with --whole-then-split); with --regrids K it then moves the
// refined sphere K times by one root block along x and prints the seconds per regrid (the
// slowest rank) and the bytes of state a rank received per regrid (halo::fetch_blocks);
// with --check it also runs the same steps on one process and counts the cells whose bits
// differ. It prints the resident and peak memory of the largest rank: each process builds
// only the blocks it computes (the solver made with the halo); --whole-then-split builds the
// whole mesh on every process first and splits it (set_halo).
//
//   mpirun -np 2 build/release/bench/mpi/mpi_block_throughput --cells 64 --block-size 16 --steps 20
#include <parafsi/fluid/block_solver.hpp>
#include <parafsi/mpi/block_halo.hpp>
#include <parafsi/parafsi.hpp>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

namespace pf = parafsi;

namespace {
pf::fluid::prim<double> smooth_field(const Eigen::Vector3d& x) {
  const double tp = 2.0 * std::numbers::pi;
  return {1.0 + 0.2 * std::sin(tp * x[0]) * std::cos(tp * x[1]),
          {0.3 * std::sin(tp * x[2]), 0.2 * std::cos(tp * x[0]), 0.1},
          1.0 + 0.1 * std::cos(tp * x[1])};
}
/// The state bytes a halo received for regrids (0 for a halo without that counter).
double fetched_bytes(const auto& c) {
  if constexpr (requires { c.fetched_bytes; }) return double(c.fetched_bytes);
  else return 0.0;
}
/// A memory line of /proc/self/status in MiB (−1 where there is none).
double status_mib(const char* key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key, 0) == 0) return std::stod(line.substr(std::strlen(key))) / 1024.0;  // kB
  return -1.0;
}
}  // namespace

int main(int argc, char** argv) {
  pf::mpi::environment env(argc, argv);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  CLI::App app{"Block-mesh throughput over MPI processes"};
  int n = 64, nb = 16, steps = 20;
  double sphere = 0.0;
  int regrids = 0;
  bool check = false, whole = false;
  app.add_option("--cells", n, "cells per box edge N (a multiple of the block size)")->check(CLI::Range(8, 1024));
  app.add_option("--block-size", nb, "cells per block edge N_b")->check(CLI::Range(4, 256));
  app.add_option("--steps", steps, "time steps to time")->check(CLI::Range(1, 100000));
  app.add_option("--refine-sphere", sphere, "refine the blocks meeting this sphere (box edges) about the centre once");
  app.add_option("--regrids", regrids, "then move the refined sphere this many times and time the regrids")
      ->check(CLI::Range(0, 1000));
  app.add_flag("--check", check, "also run on one process and count the cells that differ");
  app.add_flag("--whole-then-split", whole,
               "build and initialize the whole mesh on every process, then split it (set_halo); by default each "
               "process builds its own blocks only (the solver made with the halo)");
  CLI11_PARSE(app, argc, argv);
  if (n % nb != 0 || nb % 2 != 0) {
    if (rank == 0) std::fprintf(stderr, "mpi_block_throughput: the block size must be even and divide --cells\n");
    return 2;
  }
  pf::parallel::set_threads(1);
  const pf::index_t roots = n / nb;
  pf::fluid::blocks::tree tree({roots, roots, roots}, {true, true, true});
  // Whether root block q (or the root block holding q) meets the sphere about (cx, ½, ½),
  // periodic in x.
  auto meets = [&](const pf::fluid::blocks::location& q, double cx) {
    const double w = 1.0 / double(roots);
    double d2 = 0;
    for (int d = 0; d < 3; ++d) {
      const double lo = double(q.l[std::size_t(d)] >> q.level) * w;
      const double c0 = d == 0 ? cx : 0.5;
      double c = std::clamp(c0, lo, lo + w) - c0;
      if (d == 0)
        c = std::min({std::fabs(c), std::fabs(std::clamp(c0 + 1.0, lo, lo + w) - c0 - 1.0),
                      std::fabs(std::clamp(c0 - 1.0, lo, lo + w) - c0 + 1.0)});
      d2 += c * c;
    }
    return d2 < sphere * sphere;
  };
  if (sphere > 0.0)
    tree.refine_where(1, [&](const pf::fluid::blocks::location& q) { return q.level == 0 && meets(q, 0.5); });
  const pf::fluid::block_layout layout{{0, 0, 0}, {1, 1, 1}, {roots, roots, roots}, nb};
  auto make = [&](std::shared_ptr<pf::mpi::block_halo> h = {}) {
    auto s = std::make_unique<pf::fluid::block_solver<>>(tree, layout, pf::boundary::set::all(pf::boundary::periodic{}),
                                                         h);
    s->initialize(smooth_field);
    return s;
  };
  auto halo = std::make_shared<pf::mpi::block_halo>(MPI_COMM_WORLD);
  // The set-up timed: the split construction (the partition, the exchange lists as at every
  // regrid, each process's blocks filled and initialized), or with --whole-then-split the
  // set_halo of the whole mesh (the same, and the copy of what the process keeps).
  std::unique_ptr<pf::fluid::block_solver<>> s;
  if (whole) s = make();
  MPI_Barrier(MPI_COMM_WORLD);
  const auto h0 = std::chrono::steady_clock::now();
  if (whole) s->set_halo(halo);
  else s = make(halo);
  double setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - h0).count();
  MPI_Allreduce(MPI_IN_PLACE, &setup, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  s->step(s->stable_dt(0.5));  // warm-up: buffers sized, pages touched
  const auto c0 = halo->counters();
  const double x0 = s->timings().exchange;
  MPI_Barrier(MPI_COMM_WORLD);
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < steps; ++i) s->step(s->stable_dt(0.5));
  MPI_Barrier(MPI_COMM_WORLD);
  const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto c1 = halo->counters();
  const double msgs = double(c1.messages - c0.messages) / steps, bytes = double(c1.bytes - c0.bytes) / steps;
  const double xsec = (s->timings().exchange - x0) / steps;
  // Per-rank figures: maximum and mean over ranks.
  double mine[3] = {msgs, bytes, xsec}, mx[3], sum[3];
  MPI_Reduce(mine, mx, 3, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  MPI_Reduce(mine, sum, 3, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
  long owned = long(s->computed_blocks().size()), most = 0;
  MPI_Reduce(&owned, &most, 1, MPI_LONG, MPI_MAX, 0, MPI_COMM_WORLD);
  // Resident and peak memory of the process (Linux: /proc/self/status), the largest over ranks.
  double mem[2] = {status_mib("VmRSS:"), status_mib("VmHWM:")}, mem_max[2];
  MPI_Reduce(mem, mem_max, 2, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  // Regrids: the refined sphere one root block further along x each time.
  double regrid_s = 0.0, fetched = 0.0;
  if (regrids > 0 && sphere > 0.0) {
    const auto f0 = halo->counters();
    MPI_Barrier(MPI_COMM_WORLD);
    for (int k = 1; k <= regrids; ++k) {
      const double cx = 0.5 + double(k) / double(roots);
      const auto r0 = std::chrono::steady_clock::now();
      s->regrid([&](const pf::fluid::blocks::location& q) { return meets(q, cx) ? 1 : 0; }, 1);
      regrid_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
    }
    regrid_s /= regrids;
    MPI_Allreduce(MPI_IN_PLACE, &regrid_s, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    const auto f1 = halo->counters();
    fetched = (fetched_bytes(f1) - fetched_bytes(f0)) / regrids;
    MPI_Allreduce(MPI_IN_PLACE, &fetched, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  }
  long bad = -1;
  if (check) {
    s->gather();
    auto serial = make();
    serial->step(serial->stable_dt(0.5));
    for (int i = 0; i < steps; ++i) serial->step(serial->stable_dt(0.5));
    bad = 0;
    std::vector<double> a, z;
    auto grab = [](auto& solver, std::vector<double>& out) {
      solver.for_each_cell([&](const auto& blk, pf::index_t i, pf::index_t j, pf::index_t k) {
        for (int f = 0; f < 5; ++f) out.push_back(blk.U.data(std::size_t(f))[blk.grid.index(i, j, k)]);
      });
    };
    grab(*s, a);
    grab(*serial, z);
    for (std::size_t i = 0; i < a.size(); ++i) bad += a[i] != z[i];
  }
  if (rank == 0) {
    const double cells = double(s->cell_count());
    std::printf(
        "mpi_block_throughput ranks=%d cells=%.0f blocks=%ld block=%d levels=%d steps=%d seconds=%.4g "
        "cell_updates_per_s=%.4g blocks_per_rank_max=%ld messages_per_rank_step_max=%.3g "
        "messages_per_rank_step_mean=%.3g bytes_per_rank_step_max=%.4g bytes_per_rank_step_mean=%.4g "
        "exchange_s_per_step_max=%.4g halo_setup_s_max=%.4g resident_mib_per_rank_max=%.1f "
        "peak_mib_per_rank_max=%.1f resident_bytes_per_mesh_cell=%.1f",
        size, cells, long(s->block_count()), nb, s->tree().finest_level() + 1, steps, sec, cells * steps / sec, most,
        mx[0], sum[0] / size, mx[1], sum[1] / size, mx[2], setup, mem_max[0], mem_max[1],
        mem_max[0] * 1048576.0 / cells);
    if (regrids > 0 && sphere > 0.0)
      std::printf(" regrids=%d regrid_s_max=%.4g regrid_fetched_bytes_per_rank_max=%.4g", regrids, regrid_s, fetched);
    if (check) std::printf(" cells_differing=%ld", bad);
    std::printf("\n");
  }
  return 0;
}
