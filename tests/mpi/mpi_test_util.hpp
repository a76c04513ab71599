// Shared by the MPI tests (tests/mpi/): rank and size of MPI_COMM_WORLD, a sum over the
// processes, and the doctest main that starts MPI and agrees on the exit status.
#pragma once
#include <doctest/doctest.h>

#include <parafsi/mpi/block_halo.hpp>

namespace mpt {

inline int world_rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}
inline int world_size() {
  int n = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n;
}
inline long sum_over_processes(long v) {
  long all = 0;
  MPI_Allreduce(&v, &all, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  return all;
}

/// Run the doctest suite on every process (quiet but for rank 0); the worst status of all.
inline int run_tests(int argc, char** argv) {
  parafsi::mpi::environment env(argc, argv);
  doctest::Context ctx(argc, argv);
  if (world_rank() != 0) ctx.setOption("minimal", true);
  const int res = ctx.run();
  int worst = 0;
  MPI_Allreduce(&res, &worst, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return worst;
}

}  // namespace mpt
