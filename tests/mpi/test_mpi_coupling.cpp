// A coupled run on a distributed block mesh (mpi/block_halo.hpp), run by CTest on 1, 2 and
// 4 processes: the tilted membrane patch of tests/test_coupling_blocks.cpp on three levels
// (the patch on the finest), bitwise the one-process run (node positions and velocities,
// every fluid cell, the coupling's impulse every step):
//   - with the finest level computed by every process (replicate_finest): the penalty
//     coupling and the embedded coupling's one-sided faces;
//   - with every level split over the processes: the embedded coupling (first-order and
//     one-sided faces, impermeable and porous, with the impedance term), whose faces' cells
//     come to every process each stage (block_solver::share_slots); each face is solved
//     by the process computing its high cell and its record replayed by every process in
//     list order, so the replicated structure gets the same loads everywhere;
//   - the penalty coupling on a split finest level stops with a message on every process.
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

#include <memory>
#include <string>
#include <vector>

#include <parafsi/mpi/block_halo.hpp>

#include "mpi_test_util.hpp"

#include "../coupling_test_util.hpp"

namespace pf = parafsi;
namespace st = pf::structure;
namespace fb = pf::fluid::blocks;
using pf::index_t;

using mpt::sum_over_processes;
using mpt::world_rank;
using mpt::world_size;

namespace {

template <class S>
std::vector<double> fluid_state(S& s) {
  std::vector<double> out;
  s.fluid().for_each_cell([&](const auto& b, index_t i, index_t j, index_t k) {
    for (int f = 0; f < 5; ++f) out.push_back(b.U.data(std::size_t(f))[b.grid.index(i, j, k)]);
  });
  return out;
}

template <class Make>
void compare_coupled(const std::string& name, Make make, bool replicate_finest) {
  auto serial = ctu::blocks_patch(2, make());
  auto dist = ctu::blocks_patch(2, make());
  pf::mpi::halo_options o;
  o.replicate_finest = replicate_finest;
  dist.fluid().set_halo(std::make_shared<pf::mpi::block_halo>(MPI_COMM_WORLD, o));
  long dt_differ = 0, node_differ = 0, impulse_differ = 0;
  for (int n = 0; n < 20; ++n) {
    const double a = serial.stable_dt(0.5), b = dist.stable_dt(0.5);
    dt_differ += a != b;
    serial.step(a);
    dist.step(b);
    impulse_differ += serial.coupling().diagnostics().impulse_structure !=
                      dist.coupling().diagnostics().impulse_structure;
  }
  const auto& x = serial.structure().node_set();
  const auto& y = dist.structure().node_set();
  for (index_t i = 0; i < x.size(); ++i)
    node_differ += (x.position(i) != y.position(i)) + (x.velocity(i) != y.velocity(i));
  dist.fluid().gather();
  const auto u = fluid_state(serial), v = fluid_state(dist);
  long cell_differ = u.size() == v.size() ? 0 : 1;
  for (std::size_t i = 0; cell_differ == 0 && i < u.size(); ++i) cell_differ += u[i] != v[i];
  const index_t computed = index_t(dist.fluid().computed_blocks().size()), blocks = dist.fluid().block_count();
  node_differ = sum_over_processes(node_differ);
  cell_differ = sum_over_processes(cell_differ);
  const auto counts = dist.fluid().halo()->counters();
  if (world_rank() == 0)
    MESSAGE(name, std::string(replicate_finest ? " (finest level on every process)" : " (every level split)"), ", ",
            world_size(), " processes: ", blocks, " blocks (this process computes ", computed,
            "), 20 coupled steps: nodes differing ", node_differ, ", cells differing ", cell_differ, "; ",
            counts.gathers, " all-gathers (faces' heads, the impedance term's cells) of ", counts.gathered_bytes,
            " bytes; ", counts.sparse_exchanges, " point-to-point exchanges (faces' cells and records) of ",
            counts.sparse_bytes, " bytes from rank 0");
  CHECK(dt_differ == 0);
  CHECK(impulse_differ == 0);
  CHECK(node_differ == 0);
  CHECK(cell_differ == 0);
  if (world_size() > 1) CHECK(computed < blocks);
  // Split finest level on several processes: the patch straddles the processes' ranges, so
  // its faces' cells must have travelled (each stage of each step).
  // The cells go only to the face's solver and the records only to the cells' owners: by
  // point-to-point exchanges (three per stage). The one-sided faces' stencils straddle the
  // processes' ranges on 2 and 4 processes, the first-order faces' on 4 (on 2 every face's
  // cells lie with its solver), so something travels there.
  if (world_size() > 1 && !replicate_finest) {
    CHECK(counts.gathers >= 20);
    CHECK(counts.sparse_exchanges >= 3 * 40);
    if (std::string(name).find("one-sided") != std::string::npos || world_size() >= 4)
      CHECK(sum_over_processes(long(counts.sparse_bytes)) > 0);
  }
  CHECK(serial.coupling().diagnostics().impulse_structure.norm() > 0.0);
}

}  // namespace

TEST_CASE("distributed block mesh with the penalty coupling: bitwise the one-process run") {
  compare_coupled(
      "penalty", [] { return pf::coupling::penalty{pf::porosity::impermeable{}}; }, true);
}

TEST_CASE("distributed block mesh with the embedded coupling (one-sided faces): bitwise the one-process run") {
  compare_coupled(
      "embedded, one-sided", [] { return ctu::embedded_one_sided::make(pf::porosity::impermeable{}, 0); }, true);
}

TEST_CASE("every level split: the embedded coupling's faces bring their cells to every process, bitwise") {
  const pf::porosity::ergun cloth{1e7, 1e5, 1e-4};  // a porous cloth (Δp = 1000 Pa per m/s): air crosses the faces
  pf::coupling::embedded_options with_impedance;
  with_impedance.impedance = 1.0;
  compare_coupled(
      "embedded, one-sided", [] { return ctu::embedded_one_sided::make(pf::porosity::impermeable{}, 0); }, false);
  compare_coupled(
      "embedded, first-order faces", [] { return ctu::embedded::make(pf::porosity::impermeable{}, 0); }, false);
  compare_coupled(
      "embedded, one-sided, porous, impedance 1",
      [&] {
    return pf::coupling::embedded<pf::porosity::ergun, true>{cloth, with_impedance};
      },
      false);
}

TEST_CASE("every level split: the penalty coupling stops on every process with a message") {
  if (world_size() == 1) return;  // one process computes every block
  auto dist = ctu::blocks_patch(2, pf::coupling::penalty{pf::porosity::impermeable{}});
  dist.fluid().set_halo(std::make_shared<pf::mpi::block_halo>(MPI_COMM_WORLD));
  CHECK_THROWS_WITH_AS(dist.step(dist.stable_dt(0.5)), doctest::Contains("replicate_finest"), pf::invalid_input);
}

int main(int argc, char** argv) { return mpt::run_tests(argc, argv); }
