// The block mesh over MPI (mpi/block_halo.hpp), run by CTest on 1, 2 and 4 processes:
// a distributed run gives the bits of the same run on one process without a halo,
// through coarse–fine faces, regrids, the viscous pass's edge ghosts, far-field
// boundaries, the sponge and an eddy-viscosity closure; a checkpoint written by some of
// the processes restarts on one and on all of them bit for bit.
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include <parafsi/fluid/block_solver.hpp>
#include <parafsi/fluid/reference/vortices.hpp>
#include <parafsi/io/block_vtk.hpp>
#include <parafsi/io/checkpoint.hpp>
#include <parafsi/mpi/block_halo.hpp>

#include <parafsi/parafsi.hpp>
#include "../fluid_test_util.hpp"
#include "mpi_test_util.hpp"

namespace pf = parafsi;
namespace fluid = pf::fluid;
namespace fb = pf::fluid::blocks;
using pf::index_t;

using mpt::sum_over_processes;
using mpt::world_rank;
using mpt::world_size;
using pft::refined_tree;

namespace {

/// Every leaf cell's 5 conserved values, blocks in tree order.
template <class S>
std::vector<double> state_of(S& s) {
  std::vector<double> out;
  s.for_each_cell([&](const auto& b, index_t i, index_t j, index_t k) {
    const index_t c = b.grid.index(i, j, k);
    for (int f = 0; f < 5; ++f) out.push_back(b.U.data(std::size_t(f))[c]);
  });
  return out;
}

/// Cells whose values differ in any bit, over all processes (the same count everywhere).
long mismatches(const std::vector<double>& a, const std::vector<double>& b) {
  long bad = a.size() == b.size() ? 0 : long(std::max(a.size(), b.size()));
  for (std::size_t i = 0; bad == 0 && i < a.size(); ++i) bad += a[i] != b[i] ? 1 : 0;
  long all = 0;
  MPI_Allreduce(&bad, &all, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  return all;
}

bool same_totals(const fluid::totals& a, const fluid::totals& b) {
  return a.mass == b.mass && a.momentum == b.momentum && a.energy == b.energy && a.kinetic == b.kinetic;
}

/// Entries in which the halo's exchange lists (built from this process's own blocks, the
/// sends by all-to-all) differ from this process's part of the whole mesh's transfers
/// (blocks::plan_transfers over every block's plan), summed over processes.
template <class S>
long list_mismatches(S& solver, const pf::mpi::block_halo& h) {
  const auto m = solver.mesh_view();
  const index_t nb = index_t(m.plan->size());
  const int P = world_size(), me = world_rank();
  std::vector<int> owner(std::size_t(nb), 0);
  std::vector<char> everywhere(std::size_t(nb), 0);
  for (int r = 0; r < P; ++r)
    for (index_t b : h.owned()[std::size_t(r)]) owner[std::size_t(b)] = r;
  for (index_t b = 0; b < nb; ++b) everywhere[std::size_t(b)] = P > 1 && h.everywhere(b);
  const auto [state, regs] = fb::plan_transfers(*m.plan, *m.corrections, m.n, owner, everywhere, P);
  // Lists on a split mesh are never all empty (else the comparison would be vacuous).
  long bad = P > 1 && state.empty() ? 1 : 0;
  auto compare = [&](const std::vector<fb::transfer>& all, const auto& send, const auto& recv) {
    const auto ranks = std::size_t(P);
    std::vector<std::vector<fb::cell_ref>> s(ranks), r(ranks);
    for (const auto& t : all) {
      if (t.from == me) s[std::size_t(t.to)].push_back(t.what);
      if (t.to == me) r[std::size_t(t.from)].push_back(t.what);
    }
    for (int q = 0; q < P; ++q) {
      bad += s[std::size_t(q)] != send[std::size_t(q)];
      bad += r[std::size_t(q)] != recv[std::size_t(q)];
    }
  };
  compare(state, h.state_sends(), h.state_receives());
  compare(regs, h.register_sends(), h.register_receives());
  long all = 0;
  MPI_Allreduce(&bad, &all, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  return all;
}

}  // namespace

TEST_CASE("partition: contiguous ranges of nearly equal weight, none empty") {
  const auto s = fb::partition(std::vector<double>(10, 1.0), 4);
  CHECK(s == std::vector<index_t>{0, 2, 5, 7, 10});  // cuts where the running weight passes 2.5, 5, 7.5
  const auto w = fb::partition({1, 1, 1, 1, 8, 1, 1, 1}, 2);
  CHECK(w == std::vector<index_t>{0, 4, 8});  // the heavy block's centre lies past half the total
  const auto few = fb::partition({1, 1}, 4);
  CHECK(few.front() == 0);
  CHECK(few.back() == 2);
  for (std::size_t r = 1; r < few.size(); ++r) CHECK(few[r] >= few[r - 1]);
  CHECK_THROWS_AS(fb::partition({1.0, 0.0}, 2), pf::invalid_input);
}

TEST_CASE("distributed block mesh: a vortex through three levels and moving regrids, bit for bit") {
  const int P = world_size();
  fluid::block_layout lay{{0, 0, 0}, {10, 10, 2.5}, {4, 4, 1}, 8};
  fluid::reference::isentropic_vortex v{};
  v.cx = 3.0;
  v.cy = 4.0;
  v.u_inf = 2.0;
  v.v_inf = 1.0;
  v.period = 10.0;
  const auto t0 = refined_tree({4, 4, 1}, {true, true, true}, lay, {3.0, 4.0, 1.25}, 1.2, 2);
  auto make = [&] {
    auto s = std::make_unique<fluid::block_solver<pf::flux::hllc_lm, pf::recon::muscl<pf::limiter::mc>>>(
        t0, lay, pf::boundary::set::all(pf::boundary::periodic{}));
    s->initialize([&](const Eigen::Vector3d& x) { return v(x[0], x[1]); });
    return s;
  };
  auto serial = make();
  auto dist = make();
  auto halo = std::make_shared<pf::mpi::block_halo>(MPI_COMM_WORLD);
  dist->set_halo(halo);
  long list_bad = list_mismatches(*dist, *halo);
  {
    // The same with the finest level computed by every process (replicated blocks read
    // nothing remote and are read without messages).
    auto repl = make();
    pf::mpi::halo_options o;
    o.replicate_finest = true;
    auto h = std::make_shared<pf::mpi::block_halo>(MPI_COMM_WORLD, o);
    repl->set_halo(h);
    list_bad += list_mismatches(*repl, *h);
  }
  const auto owned = index_t(dist->computed_blocks().size());
  CHECK(owned > 0);
  if (P > 1) CHECK(owned < dist->block_count());  // this process computes only its share
  if (P > 1) {
    // Each stage overlaps the register exchange with work (block_solver::compute_rhs): the
    // partition must give it blocks on both sides, or the bitwise check below would not
    // test the order: blocks whose registers leave, blocks swept while they travel (ghosts
    // read remote cells, registers stay), and corrections that wait for them.
    long kinds[3] = {0, 0, 0};
    for (index_t id : dist->computed_blocks()) {
      kinds[0] += halo->reads_remote(id) && halo->sends_registers(id);
      kinds[1] += halo->reads_remote(id) && !halo->sends_registers(id);
      kinds[2] += halo->corrects_remote(id);
    }
    MPI_Allreduce(MPI_IN_PLACE, kinds, 3, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
    CHECK(kinds[0] > 0);
    CHECK(kinds[1] > 0);
    CHECK(kinds[2] > 0);
  }
  // The refined region follows the vortex: level 2 within 1 of its centre, level 1 within 2.5.
  int regrids = 0, dt_differ = 0, indicator_differ = 0;
  const auto before = halo->counters();
  // The one-process run on one thread, the distributed one on two threads per process (the
  // block loops run threaded from 32 768 cells on): the same bits for any process and
  // thread count.
  const int threads0 = pf::parallel::max_threads();
  for (int n = 0; n < 32; ++n) {
    pf::parallel::set_threads(1);
    const double dts = serial->stable_dt(0.5);
    serial->step(dts);
    pf::parallel::set_threads(2);
    const double dtd = dist->stable_dt(0.5);
    dist->step(dtd);
    dt_differ += dts != dtd;
    if (n % 4 == 3) {
      // The vorticity criterion's values: each process its blocks', gathered.
      indicator_differ += serial->vorticity_indicator() != dist->vorticity_indicator();
      const bool a = serial->regrid(pft::moving_vortex_target(*serial, lay, v), 2);
      const bool b = dist->regrid(pft::moving_vortex_target(*dist, lay, v), 2);
      CHECK(a == b);
      regrids += a;
      if (b) list_bad += list_mismatches(*dist, *halo);
    }
  }
  const int threads = pf::parallel::max_threads();
  pf::parallel::set_threads(threads0);
  const auto after = halo->counters();
  dist->gather();
  const long bad = mismatches(state_of(*serial), state_of(*dist));
  if (world_rank() == 0)
    MESSAGE(P, " processes of ", threads, " threads: ", dist->cell_count(), " cells in ", dist->block_count(),
            " blocks (levels 0-", dist->tree().finest_level(), "), ", regrids, " regrids fetching ",
            after.fetched_blocks - before.fetched_blocks, " blocks to rank 0 (",
            after.state_gathers - before.state_gathers, " whole-state gathers), ",
            (after.messages - before.messages) / std::max<long>(1, after.exchanges - before.exchanges),
            " state+register messages and ",
            double(after.bytes - before.bytes) / double(std::max<long>(1, after.exchanges - before.exchanges)),
            " bytes per stage from rank 0; cells differing from one process: ", bad);
  CHECK(regrids >= 2);
  CHECK(indicator_differ == 0);
  // A regrid moves the blocks each process builds from, never the whole state.
  CHECK(after.state_gathers == before.state_gathers);
  long fetched = long(after.fetched_blocks - before.fetched_blocks);
  MPI_Allreduce(MPI_IN_PLACE, &fetched, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  if (P > 1) CHECK(fetched > 0);
  CHECK(list_bad == 0);  // the lists from own blocks are the whole mesh's, at the start and after every regrid
  CHECK(dt_differ == 0);
  CHECK(bad == 0);
  CHECK(same_totals(serial->totals(), dist->totals()));
  if (P > 1) CHECK(after.messages > before.messages);
}

TEST_CASE("distributed block mesh: viscous air, far field and sponge on a refined moving box, bit for bit") {
  const double rho0 = 1.18, p0 = 101325.0;
  fluid::block_layout box{{-1, -1, -1}, {1, 1, 1}, {2, 2, 2}, 8};
  const auto t0 = refined_tree({2, 2, 2}, {false, false, false}, box, {0.2, -0.1, 0.3}, 0.3, 2);
  pf::boundary::set bc = pf::boundary::set::all(pf::boundary::far_field{rho0, {30.0, 0.0, 0.0}, p0});
  bc.layer.cells = 3;
  pf::frame::rigid motion{Eigen::Vector3d(12.0, 16.0, 0.0), Eigen::Vector3d(0.6, 0.0, 0.8)};
  auto make = [&] {
    auto s = std::make_unique<fluid::block_solver<pf::flux::hllc_lm, pf::recon::muscl<pf::limiter::van_leer>,
                                                  pf::turbulence::none, pf::viscosity::constant, pf::frame::rigid>>(
        t0, box, bc, motion, pf::viscosity::constant{0.05, 0.72});
    // A warm, dense blob off the refined region's centre: it crosses the level boundaries.
    s->initialize([&](const Eigen::Vector3d& x) {
      const double r2 = (x - Eigen::Vector3d(0.1, 0.0, 0.2)).squaredNorm();
      return fluid::prim<double>{rho0 * (1.0 + 0.2 * std::exp(-r2 / 0.02)),
                                 {30.0, 0.0, 0.0},
                                 p0 * (1.0 + 0.3 * std::exp(-r2 / 0.02))};
    });
    return s;
  };
  auto serial = make();
  auto dist = make();
  dist->set_halo(std::make_shared<pf::mpi::block_halo>(MPI_COMM_WORLD));
  // Split from its construction: each process fills and initializes only its own blocks.
  using lean_solver = fluid::block_solver<pf::flux::hllc_lm, pf::recon::muscl<pf::limiter::van_leer>,
                                          pf::turbulence::none, pf::viscosity::constant, pf::frame::rigid>;
  auto lean = std::make_unique<lean_solver>(t0, box, bc, std::make_shared<pf::mpi::block_halo>(MPI_COMM_WORLD), motion,
                                            pf::viscosity::constant{0.05, 0.72});
  lean->initialize([&](const Eigen::Vector3d& x) {
    const double r2 = (x - Eigen::Vector3d(0.1, 0.0, 0.2)).squaredNorm();
    return fluid::prim<double>{rho0 * (1.0 + 0.2 * std::exp(-r2 / 0.02)),
                               {30.0, 0.0, 0.0},
                               p0 * (1.0 + 0.3 * std::exp(-r2 / 0.02))};
  });
  // Blocks holding any state on this process: split, only its own and those its ghost
  // plans read (the halo's), the rest zero; for the split solver the same after set_halo.
  auto holding = [](const auto& s) {
    long held = 0;
    for (index_t id = 0; id < s.block_count(); ++id) {
      const auto& b = s.block_at(id);
      const double* rho = b.U.data(0);
      bool any = false;
      for (index_t c = 0; c < s.stride() && !any; ++c) any = rho[c] != 0.0;
      held += any;
    }
    return held;
  };
  int dt_differ = 0;
  for (int n = 0; n < 12; ++n) {
    const double dts = serial->stable_dt(0.5), dtd = dist->stable_dt(0.5), dtl = lean->stable_dt(0.5);
    dt_differ += (dts != dtd) + (dts != dtl);
    serial->step(dts);
    dist->step(dtd);
    lean->step(dtl);
  }
  const long held_dist = holding(*dist), held_lean = holding(*lean);
  long held_most = std::max(held_dist, held_lean);
  MPI_Allreduce(MPI_IN_PLACE, &held_most, 1, MPI_LONG, MPI_MAX, MPI_COMM_WORLD);
  dist->gather();
  lean->gather();
  const long bad = mismatches(state_of(*serial), state_of(*dist));
  const long bad_lean = mismatches(state_of(*serial), state_of(*lean));
  if (world_rank() == 0)
    MESSAGE(world_size(), " processes, ", dist->block_count(), " blocks: cells differing from one process: ", bad,
            " (split after construction), ", bad_lean,
            " (split from construction); blocks holding state on a process: ", held_most);
  CHECK(dt_differ == 0);
  CHECK(bad == 0);
  CHECK(bad_lean == 0);
  CHECK(same_totals(serial->totals(), dist->totals()));
  CHECK(same_totals(serial->totals(), lean->totals()));
  // One process holds every block; split, a process holds fewer (the rest cost no memory).
  if (world_size() == 1) CHECK(held_most == serial->block_count());
  else CHECK(held_most < serial->block_count());
}

namespace {
/// The periodic vortex of the first case on three static levels, with `Policies`.
struct vortex_case {
  fluid::block_layout lay{{0, 0, 0}, {10, 10, 2.5}, {4, 4, 1}, 8};
  fluid::reference::isentropic_vortex v{};
  fb::tree t0;
  vortex_case() {
    v.cx = 3.0;
    v.cy = 4.0;
    v.u_inf = 2.0;
    v.v_inf = 1.0;
    v.period = 10.0;
    t0 = refined_tree({4, 4, 1}, {true, true, true}, lay, {3.0, 4.0, 1.25}, 1.2, 2);
  }
  template <class Solver, class... Ps>
  std::unique_ptr<Solver> make(const Ps&... ps) const {
    auto s = std::make_unique<Solver>(t0, lay, pf::boundary::set::all(pf::boundary::periodic{}), ps...);
    s->initialize([&](const Eigen::Vector3d& x) { return v(x[0], x[1]); });
    return s;
  }
  /// Level 2 on the blocks at the vortex's start, level 1 around: a regrid that changes the mesh.
  int target(const fb::location& q) const {
    const Eigen::Vector3d c(4.0, 4.5, 1.25);
    double d2 = 0;
    for (int d = 0; d < 2; ++d) {
      const double w = lay.block_width(d, q.level), a = w * double(q.l[std::size_t(d)]);
      const double e = std::clamp(c[d], a, a + w) - c[d];
      d2 += e * e;
    }
    return d2 < 1.0 ? 2 : (d2 < 6.25 ? 1 : 0);
  }
};
}  // namespace

TEST_CASE("distributed block mesh: Smagorinsky eddy viscosity through levels and a regrid, bit for bit") {
  using S = fluid::block_solver<pf::flux::hllc_lm, pf::recon::muscl<pf::limiter::van_leer>, pf::turbulence::smagorinsky,
                                pf::viscosity::constant>;
  const vortex_case vc;
  const pf::viscosity::constant air{0.02, 0.72};  // a viscous vortex: μ_t and μ both matter
  auto serial = vc.make<S>(pf::turbulence::smagorinsky{}, air);
  auto dist = vc.make<S>(pf::turbulence::smagorinsky{}, air);
  dist->set_halo(std::make_shared<pf::mpi::block_halo>(MPI_COMM_WORLD));
  int dt_differ = 0;
  for (int n = 0; n < 10; ++n) {
    const double dts = serial->stable_dt(0.5), dtd = dist->stable_dt(0.5);
    dt_differ += dts != dtd;
    serial->step(dts);
    dist->step(dtd);
    if (n == 4)
      CHECK(serial->regrid([&](const fb::location& q) { return vc.target(q); }, 2) ==
            dist->regrid([&](const fb::location& q) { return vc.target(q); }, 2));
    if (n == 7) {
      // A new cut of the mesh that stays: the blocks that change process bring their state
      // and eddy viscosity (the next stable step reads μ_t) from their old owners. Rank 0's
      // first block made expensive: it gets a process of its own, and the rest move.
      const auto before = dist->computed_blocks();
      if (world_rank() == 0 && !before.empty()) dist->add_block_cost(before.front(), 100.0);
      const auto g0 = dist->halo()->counters();
      dist->rebalance();
      const auto g1 = dist->halo()->counters();
      CHECK(g1.state_gathers == g0.state_gathers);
      // Every block this process now computes holds the one-process eddy viscosity.
      long mu_moved_bad = 0;
      for (index_t b : dist->computed_blocks())
        for (index_t k = 0; k < 8; ++k)
          for (index_t j = 0; j < 8; ++j)
            for (index_t i = 0; i < 8; ++i) {
              const index_t c = dist->block_at(b).grid.index(i, j, k);
              mu_moved_bad += serial->eddy_viscosity()[serial->global_index(b, c)] !=
                              dist->eddy_viscosity()[dist->global_index(b, c)];
            }
      CHECK(mu_moved_bad == 0);
      long moved = long(g1.fetched_blocks - g0.fetched_blocks);
      MPI_Allreduce(MPI_IN_PLACE, &moved, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
      if (world_size() > 1) CHECK(moved > 0);
    }
  }
  dist->gather();
  const long bad = mismatches(state_of(*serial), state_of(*dist));
  double mu_max = 0;
  long mu_bad = 0;
  for (index_t b = 0; b < serial->block_count(); ++b)
    for (index_t k = 0; k < 8; ++k)
      for (index_t j = 0; j < 8; ++j)
        for (index_t i = 0; i < 8; ++i) {
          const index_t c = serial->block_at(b).grid.index(i, j, k);
          const double a = serial->eddy_viscosity()[serial->global_index(b, c)];
          mu_max = std::max(mu_max, a);
          mu_bad += a != dist->eddy_viscosity()[dist->global_index(b, c)];
        }
  if (world_rank() == 0)
    MESSAGE(world_size(), " processes, Smagorinsky: cells differing ", bad, ", eddy viscosities differing ", mu_bad,
            " (max mu_t ", mu_max, " Pa s)");
  CHECK(dt_differ == 0);
  CHECK(bad == 0);
  CHECK(mu_bad == 0);
  CHECK(mu_max > 0.0);
}

TEST_CASE("distributed checkpoint: written by half the processes, restarted on one and on all, bit for bit") {
  using S = fluid::block_solver<pf::flux::hllc_lm, pf::recon::muscl<pf::limiter::mc>>;
  const int P = world_size(), writers = (P + 1) / 2;
  const vortex_case vc;
  const auto path = std::filesystem::temp_directory_path() / ("parafsi_test_mpi_np" + std::to_string(P) + ".ckpt");
  auto regrid = [&](S& s) { return s.regrid([&](const fb::location& q) { return vc.target(q); }, 2); };
  // The reference: one process, 6 steps, a regrid, 6 more.
  auto ref = vc.make<S>();
  for (int n = 0; n < 6; ++n) ref->step(ref->stable_dt(0.5));
  CHECK(regrid(*ref));
  // The writers: the first ⌈P/2⌉ processes run the first part distributed and write.
  MPI_Comm wcomm = MPI_COMM_NULL;
  MPI_Comm_split(MPI_COMM_WORLD, world_rank() < writers ? 0 : MPI_UNDEFINED, world_rank(), &wcomm);
  if (wcomm != MPI_COMM_NULL) {
    auto w = vc.make<S>();
    w->set_halo(std::make_shared<pf::mpi::block_halo>(wcomm));
    for (int n = 0; n < 6; ++n) w->step(w->stable_dt(0.5));
    regrid(*w);
    w->gather();
    int wrank = 0;
    MPI_Comm_rank(wcomm, &wrank);
    if (wrank == 0) pf::io::save_checkpoint(path, *w);
    // Not gathered since the last step: writing is refused with a message.
    w->step(w->stable_dt(0.5));
    CHECK_THROWS_AS(pf::io::save_checkpoint(path.string() + ".late", *w), pf::error);
    MPI_Comm_free(&wcomm);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  // The readers: one process (no halo), and all P processes.
  auto one = vc.make<S>();
  pf::io::load_checkpoint(path, *one);
  auto all = vc.make<S>();
  pf::io::load_checkpoint(path, *all);
  all->set_halo(std::make_shared<pf::mpi::block_halo>(MPI_COMM_WORLD));
  int dt_differ = 0;
  for (int n = 0; n < 6; ++n) {
    const double dt = ref->stable_dt(0.5);
    dt_differ += (one->stable_dt(0.5) != dt) + (all->stable_dt(0.5) != dt);
    ref->step(dt);
    one->step(dt);
    all->step(dt);
  }
  all->gather();
  const auto r = state_of(*ref);
  const long bad_one = mismatches(r, state_of(*one)), bad_all = mismatches(r, state_of(*all));
  if (world_rank() == 0)
    MESSAGE("written by ", writers, " of ", P, " processes (", ref->block_count(), " blocks), restarted on 1 and on ",
            P, ": cells differing ", bad_one, " and ", bad_all);
  CHECK(dt_differ == 0);
  CHECK(bad_one == 0);
  CHECK(bad_all == 0);
  CHECK(one->time() == ref->time());
  CHECK(all->steps() == ref->steps());
  MPI_Barrier(MPI_COMM_WORLD);
  if (world_rank() == 0) std::filesystem::remove(path);
}

TEST_CASE("distributed block mesh: a solver moved after set_halo attaches again and stays bitwise") {
  using S = fluid::block_solver<pf::flux::hllc_lm, pf::recon::muscl<pf::limiter::mc>>;
  const vortex_case vc;
  auto serial = vc.make<S>();
  auto before = vc.make<S>();
  before->set_halo(std::make_shared<pf::mpi::block_halo>(MPI_COMM_WORLD));
  S moved = std::move(*before);  // the halo's pointers named the old object
  before.reset();
  for (int n = 0; n < 6; ++n) {
    const double dt = serial->stable_dt(0.5);
    CHECK(moved.stable_dt(0.5) == dt);
    serial->step(dt);
    moved.step(dt);
  }
  moved.gather();
  CHECK(mismatches(state_of(*serial), state_of(moved)) == 0);
}

int main(int argc, char** argv) { return mpt::run_tests(argc, argv); }

namespace {
/// A recording face patcher that passes the regular flux through and fails on face `bad`.
struct failing_patcher {
  std::vector<fluid::patch_face> faces;
  std::size_t bad = 0;
  std::span<const fluid::patch_face> patch_faces() const noexcept { return faces; }
  double solve_patch(const fluid::face_context& fc, const fluid::view&, fluid::cons<double>&,
                     fluid::cons<double>&) const {
    if (fc.patch == bad) throw pf::numerical_failure("test face failed on purpose", long(fc.patch), 0.0);
    return 0.0;
  }
  void record_patch(const fluid::face_context&, const fluid::cons<double>&, const fluid::cons<double>&, double) {}
  void patch(const fluid::face_context& fc, const fluid::view& v, fluid::cons<double>& lo, fluid::cons<double>& hi) {
    record_patch(fc, lo, hi, solve_patch(fc, v, lo, hi));
  }
};
}  // namespace

TEST_CASE("a patched face that fails stops every process, the first failing face in list order") {
  // Faces are solved by the process computing their high cell; a failure there must reach
  // the others through the gathered records, not leave them waiting in a collective call.
  static_assert(fluid::recording_face_patcher<failing_patcher>);
  const int P = world_size();
  fluid::block_layout lay{{0, 0, 0}, {1, 1, 0.25}, {4, 4, 1}, 8};
  fb::tree t({4, 4, 1}, {true, true, true});
  auto make = [&] {
    auto s = std::make_unique<fluid::block_solver<pf::flux::hllc_lm, pf::recon::muscl<pf::limiter::mc>>>(
        t, lay, pf::boundary::set::all(pf::boundary::periodic{}));
    s->fill_uniform({1.2, {3, 0, 0}, 1e5});
    return s;
  };
  auto dist = make();
  dist->set_halo(std::make_shared<pf::mpi::block_halo>(MPI_COMM_WORLD));
  // One face (axis x, an interior cell) in every block; the failing one in the last block,
  // which the last process computes.
  failing_patcher p;
  const fb::block_index at{lay.block_cells};
  for (index_t id = 0; id < dist->block_count(); ++id) p.faces.push_back({dist->global_index(id, at(3, 4, 4)), 0});
  p.bad = p.faces.size() - 1;
  const index_t bad_block = dist->block_count() - 1;
  const auto& mine = dist->computed_blocks();
  const bool solves_bad = std::find(mine.begin(), mine.end(), bad_block) != mine.end();
  if (P > 1) CHECK(solves_bad == (world_rank() == P - 1));
  std::string what;
  try {
    dist->step(dist->stable_dt(0.5), p);
  } catch (const pf::numerical_failure& e) {
    what = e.what();
    CHECK(e.index == long(p.bad));
  }
  CHECK(!what.empty());  // every process stopped
  if (solves_bad) CHECK(what.find("on purpose") != std::string::npos);
  else CHECK(what.find("failed on the process solving it") != std::string::npos);
  // The processes are still in step: a collective call completes.
  long one = 1;
  CHECK(sum_over_processes(one) == P);
}

namespace {
/// The same weights on every process: each entry's minimum and maximum over the processes
/// are equal (the same count on every process first).
bool same_everywhere(const std::vector<double>& w) {
  long n[2] = {long(w.size()), -long(w.size())};
  MPI_Allreduce(MPI_IN_PLACE, n, 2, MPI_LONG, MPI_MIN, MPI_COMM_WORLD);
  if (n[0] != -n[1]) return false;
  std::vector<double> lo = w, hi = w;
  MPI_Allreduce(MPI_IN_PLACE, lo.data(), int(lo.size()), MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, hi.data(), int(hi.size()), MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return lo == hi;
}
}  // namespace

TEST_CASE("cost-weighted partition: measured block costs cut the mesh at regrids and rebalance(), bitwise") {
  // A block made expensive (add_block_cost, as the drop adds its wall distance) gets a
  // process of its own at the next partition; the weights are the same on every process,
  // a regrid carries them to the new leaves, and the state keeps the one-process bits.
  const int P = world_size();
  fluid::block_layout lay{{0, 0, 0}, {8, 8, 2}, {4, 4, 1}, 8};
  fluid::reference::isentropic_vortex v{};
  v.cx = 5.0;
  v.cy = 5.0;
  v.u_inf = 1.0;
  v.period = 8.0;
  const fb::tree t0({4, 4, 1}, {true, true, true});  // the root grid: the first regrid refines it
  auto make = [&] {
    auto s = std::make_unique<fluid::block_solver<pf::flux::hllc_lm, pf::recon::muscl<pf::limiter::mc>>>(
        t0, lay, pf::boundary::set::all(pf::boundary::periodic{}));
    s->initialize([&](const Eigen::Vector3d& x) { return v(x[0], x[1]); });
    return s;
  };
  auto serial = make();
  auto dist = make();
  const auto halo = std::make_shared<pf::mpi::block_halo>(MPI_COMM_WORLD);
  dist->set_halo(halo);
  CHECK(dist->partition_weights() == std::vector<double>(std::size_t(dist->block_count()), 1.0));
  const fb::location corner{0, {0, 0, 0}};  // a root block far from the refined region
  // A regrid that changes the mesh before any step (as the drop's first refinement does):
  // nothing is measured yet, so the weights stay uniform and the first cut by measured cost
  // is still to come.
  auto around = [&](double cx) {
    return [&lay, cx](const fb::location& q) {
      double d2 = 0;
      const double c[2] = {cx, 5.0};
      for (int d = 0; d < 2; ++d) {
        const double wd = lay.block_width(d, q.level), a = wd * double(q.l[std::size_t(d)]);
        const double e = std::clamp(c[d], a, a + wd) - c[d];
        d2 += e * e;
      }
      return d2 < 1.0 ? 2 : (d2 < 4.0 ? 1 : 0);
    };
  };
  REQUIRE(serial->regrid(around(5.0), 2));
  REQUIRE(dist->regrid(around(5.0), 2));
  CHECK(dist->partition_weights() == std::vector<double>(std::size_t(dist->block_count()), 1.0));
  auto computes = [&](index_t id) {
    const auto& m = dist->computed_blocks();
    return std::find(m.begin(), m.end(), id) != m.end();
  };
  auto steps = [&](int k) {
    for (int n = 0; n < k; ++n) {
      const double dt = serial->stable_dt(0.5);
      CHECK(dist->stable_dt(0.5) == dt);
      serial->step(dt);
      dist->step(dt);
    }
  };
  steps(4);
  const index_t heavy = dist->tree().id_of(corner);
  REQUIRE(heavy == 0);
  if (computes(heavy)) dist->add_block_cost(heavy, 100.0);
  // A regrid that keeps the mesh: the first one after set_halo cuts by the measured costs.
  const fb::tree mesh0 = dist->tree();
  auto same_mesh = [&](const fb::location& q) {
    const fb::cover c = mesh0.find(q);
    return c.kind == fb::cover::leaf ? c.level : q.level + 1;
  };
  CHECK_FALSE(serial->regrid(same_mesh, 2));
  CHECK_FALSE(dist->regrid(same_mesh, 2));
  const std::vector<double> w = dist->partition_weights();
  CHECK(same_everywhere(w));
  if (P > 1) {
    CHECK(w[std::size_t(heavy)] == doctest::Approx(25.0).epsilon(0.01));  // 100 s over 4 steps (+ its µs)
    for (std::size_t b = 1; b < w.size(); ++b) CHECK((w[b] > 0.0 && w[b] < 1.0));
    if (world_rank() == 0) CHECK(dist->computed_blocks() == std::vector<index_t>{heavy});
    CHECK(list_mismatches(*dist, *halo) == 0);  // the exchange lists of the uneven cut
  } else {
    CHECK(w == std::vector<double>(w.size(), 1.0));  // one process computes everything: nothing to weigh
  }
  steps(4);
  // A regrid that moves the refined region: the corner block stays a leaf and keeps its cost.
  if (computes(dist->tree().id_of(corner))) dist->add_block_cost(dist->tree().id_of(corner), 100.0);
  const bool a = serial->regrid(around(6.0), 2);
  const bool b = dist->regrid(around(6.0), 2);
  REQUIRE(a);
  REQUIRE(b);
  const std::vector<double> w2 = dist->partition_weights();
  CHECK(w2.size() == std::size_t(dist->block_count()));
  CHECK(same_everywhere(w2));
  if (P > 1) {
    CHECK(w2[std::size_t(dist->tree().id_of(corner))] == doctest::Approx(25.0).epsilon(0.01));
    if (world_rank() == 0) CHECK(dist->computed_blocks() == std::vector<index_t>{dist->tree().id_of(corner)});
  }
  steps(4);
  // rebalance() on a mesh that stays: the last block made expensive gets the last process.
  const index_t last = dist->block_count() - 1;
  if (computes(last)) dist->add_block_cost(last, 100.0);
  dist->rebalance();
  CHECK(same_everywhere(dist->partition_weights()));
  if (P > 1 && world_rank() == P - 1) CHECK(dist->computed_blocks() == std::vector<index_t>{last});
  CHECK(list_mismatches(*dist, *halo) == 0);
  steps(4);
  dist->gather();
  CHECK(mismatches(state_of(*serial), state_of(*dist)) == 0);
  CHECK(same_totals(serial->totals(), dist->totals()));
}

TEST_CASE("distributed output: a VTK piece and a checkpoint from the blocks fetched for them, as from a whole gather") {
  using S = fluid::block_solver<pf::flux::hllc_lm, pf::recon::muscl<pf::limiter::van_leer>, pf::turbulence::smagorinsky,
                                pf::viscosity::constant>;
  const vortex_case vc;
  const pf::viscosity::constant air{0.02, 0.72};
  auto s = vc.make<S>(pf::turbulence::smagorinsky{}, air);
  s->set_halo(std::make_shared<pf::mpi::block_halo>(MPI_COMM_WORLD));
  for (int n = 0; n < 4; ++n) s->step(s->stable_dt(0.5));
  const int r = world_rank(), P = world_size();
  const auto dir = std::filesystem::temp_directory_path() / ("parafsi_test_mpi_out_np" + std::to_string(P));
  if (r == 0) {
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir / "fetched");
    std::filesystem::create_directories(dir / "gathered");
  }
  MPI_Barrier(MPI_COMM_WORLD);
  auto bytes = [](const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  // A piece's blocks and their face neighbours (the vorticity reads those), then freed.
  const auto range = pf::io::piece_blocks(s->block_count(), r, P);
  std::vector<index_t> piece;
  for (index_t id = range.first; id < range.last; ++id) piece.push_back(id);
  s->fetch(s->with_face_neighbours(piece));
  pf::io::write_pvtu_piece(dir / "fetched" / "f.pvtu", *s, {}, r, P);
  s->release_fetched();
  // The checkpoint from the whole mesh on process 0 only.
  s->gather_to(0);
  if (r == 0) pf::io::save_checkpoint(dir / "fetched" / "c.ckpt", *s);
  s->release_fetched();
  // Blocks with state after the release: a split process holds fewer than the mesh.
  long held = 0;
  for (index_t id = 0; id < s->block_count(); ++id) {
    const double* rho = s->block_at(id).U.data(0);
    bool any = false;
    for (index_t c = 0; c < s->stride() && !any; ++c) any = rho[c] != 0.0;
    held += any;
  }
  MPI_Allreduce(MPI_IN_PLACE, &held, 1, MPI_LONG, MPI_MAX, MPI_COMM_WORLD);
  // The same files after a whole-state gather.
  s->gather();
  pf::io::write_pvtu_piece(dir / "gathered" / "f.pvtu", *s, {}, r, P);
  if (r == 0) pf::io::save_checkpoint(dir / "gathered" / "c.ckpt", *s);
  MPI_Barrier(MPI_COMM_WORLD);
  const std::string name = "f_" + std::to_string(r) + ".vtu";
  long differ = bytes(dir / "fetched" / name) != bytes(dir / "gathered" / name);
  if (r == 0) differ += bytes(dir / "fetched" / "c.ckpt") != bytes(dir / "gathered" / "c.ckpt");
  if (r == 0) differ += bytes(dir / "fetched" / "c.ckpt").empty();
  MPI_Allreduce(MPI_IN_PLACE, &differ, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  if (r == 0)
    MESSAGE(P, " processes, ", s->block_count(), " blocks: output files differing from the whole gather's: ", differ,
            "; blocks holding state on a process after release_fetched: ", held);
  CHECK(differ == 0);
  if (P == 1) CHECK(held == s->block_count());
  else CHECK(held < s->block_count());
  // Stepping on after the release stays bitwise (the serial reference).
  auto serial = vc.make<S>(pf::turbulence::smagorinsky{}, air);
  for (int n = 0; n < 4; ++n) serial->step(serial->stable_dt(0.5));
  for (int n = 0; n < 3; ++n) {
    s->release_fetched();
    s->step(s->stable_dt(0.5));
    serial->step(serial->stable_dt(0.5));
  }
  s->gather();
  CHECK(mismatches(state_of(*serial), state_of(*s)) == 0);
  MPI_Barrier(MPI_COMM_WORLD);
  if (r == 0) std::filesystem::remove_all(dir);
}

TEST_CASE("distributed storage: sources and the unfilled wall distance survive a split, a rebalance and a checkpoint") {
  // A mixing-length run (wall distance left unfilled: far, 1e30) with per-cell sources set on
  // every block: split, stepped, rebalanced by a measured cost, written from process 0 after
  // gather_to(0), restarted on one process: the bits of the one-process run throughout.
  using S = fluid::block_solver<pf::flux::hllc_lm, pf::recon::muscl<pf::limiter::van_leer>,
                                pf::turbulence::prandtl_mixing_length, pf::viscosity::constant>;
  const vortex_case vc;
  const pf::viscosity::constant air{0.02, 0.72};
  pf::turbulence::prandtl_mixing_length ml{};
  ml.ref_length = 2.0;
  auto make = [&] {
    auto s = vc.make<S>(ml, air);
    s->enable_sources();
    for (index_t id = 0; id < s->block_count(); ++id)  // a small heat source in every block
      s->source(id, 3)[s->block_at(id).grid.index(1, 2, 0)] = 50.0 + double(id);
    return s;
  };
  const int P = world_size(), r = world_rank();
  auto serial = make();
  auto dist = make();
  dist->set_halo(std::make_shared<pf::mpi::block_halo>(MPI_COMM_WORLD));
  const auto path = std::filesystem::temp_directory_path() / ("parafsi_test_mpi_src_np" + std::to_string(P) + ".ckpt");
  // Split, a process no longer holds every block: writing needs a gather first.
  if (r == 0 && P > 1) CHECK_THROWS_AS(pf::io::save_checkpoint(path, *dist), pf::error);
  auto steps = [&](int k) {
    int differ = 0;
    for (int n = 0; n < k; ++n) {
      const double dt = serial->stable_dt(0.5);
      differ += dist->stable_dt(0.5) != dt;
      serial->step(dt);
      dist->step(dt);
    }
    return differ;
  };
  CHECK(steps(3) == 0);
  const auto& mine = dist->computed_blocks();
  if (!mine.empty()) dist->add_block_cost(mine.front(), 50.0);  // every process's first block heavy
  dist->rebalance();
  CHECK(steps(3) == 0);
  dist->gather_to(0);
  if (r == 0) pf::io::save_checkpoint(path, *dist);
  dist->release_fetched();
  MPI_Barrier(MPI_COMM_WORLD);
  auto again = vc.make<S>(ml, air);
  pf::io::load_checkpoint(path, *again);
  for (int n = 0; n < 3; ++n) {
    const double dt = serial->stable_dt(0.5);
    CHECK(again->stable_dt(0.5) == dt);
    serial->step(dt);
    again->step(dt);
    dist->step(dt);
  }
  dist->gather();
  const auto ref = state_of(*serial);
  const long bad_dist = mismatches(ref, state_of(*dist)), bad_again = mismatches(ref, state_of(*again));
  if (r == 0)
    MESSAGE(P, " processes: cells differing from one process, split run ", bad_dist, ", restarted from its checkpoint ",
            bad_again);
  CHECK(bad_dist == 0);
  CHECK(bad_again == 0);
  MPI_Barrier(MPI_COMM_WORLD);
  if (r == 0) std::filesystem::remove(path);
}
