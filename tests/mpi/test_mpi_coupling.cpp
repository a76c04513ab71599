// A coupled run on a distributed block mesh (mpi/block_halo.hpp with replicate_finest),
// run by CTest on 1, 2 and 4 processes: the tilted membrane patch of
// tests/test_coupling_blocks.cpp on three levels (the patch on the finest), with the
// penalty coupling and with the embedded coupling's one-sided faces. Every process computes
// the finest level (the coupling's region) and its share of the rest, steps the replicated
// structure with the loads it computed itself, and the run is bitwise the one-process run:
// node positions and velocities, every fluid cell, the coupling's impulse every step.
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
void compare_coupled(const std::string& name, Make make) {
  auto serial = ctu::blocks_patch(2, make());
  auto dist = ctu::blocks_patch(2, make());
  pf::mpi::halo_options o;
  o.replicate_finest = true;
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
  if (world_rank() == 0)
    MESSAGE(name, ", ", world_size(), " processes: ", blocks, " blocks (this process computes ", computed,
            "), 20 coupled steps: nodes differing ", node_differ, ", cells differing ", cell_differ);
  CHECK(dt_differ == 0);
  CHECK(impulse_differ == 0);
  CHECK(node_differ == 0);
  CHECK(cell_differ == 0);
  if (world_size() > 1) CHECK(computed < blocks);
  CHECK(serial.coupling().diagnostics().impulse_structure.norm() > 0.0);
}

}  // namespace

TEST_CASE("distributed block mesh with the penalty coupling: bitwise the one-process run") {
  compare_coupled("penalty", [] { return pf::coupling::penalty{pf::porosity::impermeable{}}; });
}

TEST_CASE("distributed block mesh with the embedded coupling (one-sided faces): bitwise the one-process run") {
  compare_coupled("embedded, one-sided", [] { return ctu::embedded_one_sided::make(pf::porosity::impermeable{}, 0); });
}

int main(int argc, char** argv) { return mpt::run_tests(argc, argv); }
