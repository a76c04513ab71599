// Communication model of the block mesh over P processes, without MPI: the same partition
// (blocks::partition) and transfer lists (blocks::plan_transfers) the MPI halo builds, counted
// for any P on one machine. The mesh: a box of N³ root-level cells in blocks of N_b³, the
// blocks within a sphere about the centre refined by L levels (a canopy's refined region;
// 2:1 balance grades it), far-field sides (or periodic, --periodic). For each P it prints, per process
// and stage, the blocks and cells it computes, the messages it sends (one per neighbouring
// process per exchange: the state, and the registers where coarse–fine faces cross) and the
// bytes, maximum and mean over processes, and the model's time per stage
//   t(P) = max_r [ cells_r / R + messages_r · α + bytes_r / β ],
// R the measured cell-updates per second and core (--rate), α the message latency (--latency)
// and β the bandwidth per process (--bandwidth), with the parallel efficiency t(1) / (P t(P)).
//
//   build/release/bench/halo_model --cells 256 --block-size 16 --levels 2 --sphere 0.15 --ranks 1,64,512,4096
#include <parafsi/fluid/blocks/exchange.hpp>
#include <parafsi/fluid/blocks/flux_correction.hpp>
#include <parafsi/fluid/blocks/halo.hpp>
#include <parafsi/fluid/blocks/tree.hpp>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <set>
#include <vector>

namespace pf = parafsi;
namespace fb = pf::fluid::blocks;

int main(int argc, char** argv) {
  CLI::App app{"Messages and bytes per process of the block mesh over P processes (model, no MPI)"};
  int n = 256, nb = 16, levels = 2;
  double sphere = 0.15, rate = 5.0e6, latency = 2e-6, bandwidth = 5e9;
  std::vector<int> ranks{1, 2, 4, 64, 512, 4096};
  bool viscous = false, periodic = false;
  app.add_option("--cells", n, "root-level cells per box edge N")->check(CLI::Range(8, 4096));
  app.add_option("--block-size", nb, "cells per block edge N_b (even, dividing N)")->check(CLI::Range(4, 256));
  app.add_option("--levels", levels, "refinement levels inside the sphere")->check(CLI::Range(0, 8));
  app.add_option("--sphere", sphere, "radius of the refined sphere about the centre (box edges)");
  app.add_option("--ranks", ranks, "process counts")->delimiter(',');
  app.add_option("--rate", rate, "cell-updates per second and core (bench/fluid_throughput)");
  app.add_option("--latency", latency, "seconds per message");
  app.add_option("--bandwidth", bandwidth, "bytes per second per process");
  app.add_flag("--viscous", viscous, "the viscous pass's plans (edge and corner ghosts too)");
  app.add_flag("--periodic", periodic, "periodic box (as bench/mpi/mpi_block_throughput) instead of far-field sides");
  CLI11_PARSE(app, argc, argv);
  if (n % nb != 0 || nb % 2 != 0) {
    std::fprintf(stderr, "halo_model: the block size must be even and divide --cells\n");
    return 2;
  }
  const pf::index_t roots = n / nb;
  fb::tree t({roots, roots, roots}, {periodic, periodic, periodic});
  t.refine_where(levels, [&](const fb::location& q) {
    double d2 = 0;
    for (int d = 0; d < 3; ++d) {
      const double w = 1.0 / double(roots << q.level), lo = w * double(q.l[std::size_t(d)]);
      const double c = std::clamp(0.5, lo, lo + w) - 0.5;
      d2 += c * c;
    }
    return d2 < sphere * sphere;
  });
  const auto plan = fb::build_plan(t, nb, viscous);
  const auto corr = fb::build_flux_corrections(t, nb);
  const double cells_per_block = double(nb) * nb * nb, blocks = double(t.size());
  std::printf(
      "# halo_model cells=%.0f blocks=%.0f block=%d levels=%d viscous=%d rate=%.3g latency=%.3g bandwidth=%.3g\n",
      blocks * cells_per_block, blocks, nb, t.finest_level() + 1, int(viscous), rate, latency, bandwidth);
  std::printf(
      "ranks,blocks_per_rank_max,cells_per_rank_max,messages_per_rank_stage_max,messages_per_rank_stage_mean,"
      "bytes_per_rank_stage_max,bytes_per_rank_stage_mean,sent_cells_over_owned_max,model_s_per_stage,efficiency\n");
  const double t1 = blocks * cells_per_block / rate;  // one process: no messages
  for (int P : ranks) {
    if (P < 1 || double(P) > blocks) {
      std::printf("# %d ranks: more ranks than blocks, skipped\n", P);
      continue;
    }
    const auto starts = fb::partition(std::vector<double>(std::size_t(t.size()), 1.0), P);
    const auto [state, regs] = fb::plan_transfers(plan, corr, nb, starts);
    std::vector<double> bytes(static_cast<std::size_t>(P), 0.0);
    std::vector<std::set<int>> peers_s(static_cast<std::size_t>(P)), peers_r(static_cast<std::size_t>(P));
    for (const auto& x : state) {
      bytes[std::size_t(x.from)] += 5 * sizeof(double);
      peers_s[std::size_t(x.from)].insert(x.to);
    }
    for (const auto& x : regs) {
      bytes[std::size_t(x.from)] += sizeof(double);
      peers_r[std::size_t(x.from)].insert(x.to);
    }
    double bmax = 0, bsum = 0, mmax = 0, msum = 0, tmax = 0, ratio = 0;
    pf::index_t most = 0;
    for (int r = 0; r < P; ++r) {
      const pf::index_t own = starts[std::size_t(r) + 1] - starts[std::size_t(r)];
      most = std::max(most, own);
      const double m = double(peers_s[std::size_t(r)].size() + peers_r[std::size_t(r)].size());
      const double b = bytes[std::size_t(r)], cells = double(own) * cells_per_block;
      bmax = std::max(bmax, b);
      bsum += b;
      mmax = std::max(mmax, m);
      msum += m;
      ratio = std::max(ratio, b / (5 * sizeof(double)) / cells);
      tmax = std::max(tmax, cells / rate + m * latency + b / bandwidth);
    }
    std::printf("%d,%ld,%.0f,%.0f,%.3g,%.4g,%.4g,%.3g,%.4g,%.3g\n", P, long(most), double(most) * cells_per_block, mmax,
                msum / P, bmax, bsum / P, ratio, tmax, t1 / (P * tmax));
  }
  return 0;
}
