// The couplings on the block mesh.
// - Penalty: on one level it reproduces the coupling on the box solver to round-off (the
//   same stencils, snapshot, spreading and sources); across levels (the membrane on the
//   finest) the air's momentum change equals minus the structure's every step and the
//   fluid's energy change equals the coupling work, to round-off.
// - Embedded: on one level it reproduces the box solver's run to round-off (faces found on
//   the finest level's index grid, patched across block boundaries); across levels the
//   air's momentum change equals minus the structure's and its energy change the work of
//   the membrane faces, to round-off. The piston and screen across level boundaries are in
//   test_coupling_blocks_duct.cpp.
// - Recorded faces: the embedded coupling's faces solved apart and replayed in list order
//   (fluid::recording_face_patcher) give the bits of the face-by-face patch.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <utility>

#include "coupling_test_util.hpp"

namespace pf = parafsi;
namespace st = pf::structure;
namespace fb = pf::fluid::blocks;

namespace {
using ctu::blocks_patch;
/// 30 steps of the box and block runs at the box's steps: the largest node-velocity
/// difference (of 4 m/s) and relative fluid-energy difference.
template <class Box, class Blocks>
std::pair<double, double> run_side_by_side(Box& box, Blocks& blk) {
  double worst_x = 0, worst_f = 0;
  for (int n = 0; n < 30; ++n) {
    const double dt = box.stable_dt(0.5);
    box.step(dt);
    blk.step(dt);
    const auto& a = box.structure().node_set();
    const auto& b = blk.structure().node_set();
    for (pf::index_t i = 0; i < a.size(); ++i)
      worst_x = std::max(worst_x, (a.velocity(i) - b.velocity(i)).norm() / 4.0);
    const auto ta = box.fluid().totals(), tb = blk.fluid().totals();
    worst_f = std::max(worst_f, std::fabs(ta.energy - tb.energy) / ta.energy);
  }
  return {worst_x, worst_f};
}

/// 30 coupled steps: the largest step impulse |J|, max |ΔP_fluid + ΔP_structure| / |J| and
/// max |ΔE_fluid − σ W| / E, with W the coupling's work_fluid and σ its sign convention
/// (+1: work done on the air, penalty; −1: energy the air gave, embedded).
struct exchange_balance {
  double impulse = 0, momentum = 0, energy = 0;
};
template <class S>
exchange_balance balance_every_step(S& s, double sigma) {
  auto momentum = [&] {
    const auto t = s.fluid().totals();
    return Eigen::Vector3d(t.momentum[0], t.momentum[1], t.momentum[2]);
  };
  exchange_balance r;
  for (int n = 0; n < 30; ++n) {
    const Eigen::Vector3d pf0 = momentum(), ps0 = s.structure().linear_momentum();
    const double e0 = s.fluid().totals().energy;
    s.step(s.stable_dt(0.5));
    const Eigen::Vector3d dpf = momentum() - pf0, dps = s.structure().linear_momentum() - ps0;
    const auto& d = s.coupling().diagnostics();
    r.impulse = std::max(r.impulse, d.impulse_structure.norm());
    r.momentum = std::max(r.momentum, (dpf + dps).norm() / std::max(d.impulse_structure.norm(), 1e-300));
    r.energy = std::max(r.energy, std::fabs(s.fluid().totals().energy - e0 - sigma * d.work_fluid) / e0);
  }
  return r;
}
}  // namespace

TEST_CASE("penalty coupling on one level of blocks reproduces the box solver's run to round-off") {
  pf::parallel::set_threads(1);
  auto box = ctu::tilted_patch(ctu::penalty::make(pf::porosity::impermeable{}, 0.1), 1.18, 0.5, 1e5);
  auto blk = blocks_patch(0);
  const auto [worst_x, worst_f] = run_side_by_side(box, blk);
  MESSAGE("30 coupled steps: max node-velocity difference ", worst_x, " (relative to 4 m/s), fluid energy ", worst_f,
          "; points ", blk.coupling().points().size(), " vs ", box.coupling().points().size());
  CHECK(blk.coupling().points().size() == box.coupling().points().size());
  CHECK(worst_x < 1e-12);
  CHECK(worst_f < 1e-14);
}

TEST_CASE("penalty coupling across levels: momentum and energy exchange to round-off every step") {
  pf::parallel::set_threads(1);
  auto s = blocks_patch(2);
  MESSAGE("mesh: ", s.fluid().block_count(), " blocks, finest level ", s.fluid().tree().finest_level());
  CHECK(s.fluid().tree().finest_level() == 2);
  const auto [scale, worst, worst_e] = balance_every_step(s, +1.0);
  MESSAGE("30 steps: max step impulse ", scale, " N s, max |dP_fluid + dP_structure| / |J| = ", worst,
          ", max |dE_fluid - W| / E = ", worst_e);
  CHECK(scale > 0);
  CHECK(worst < 1e-9);
  CHECK(worst_e < 1e-13);
}

TEST_CASE("embedded coupling on one level of blocks reproduces the box solver's run to round-off") {
  pf::parallel::set_threads(1);
  auto box = ctu::tilted_patch(ctu::embedded::make(pf::porosity::impermeable{}, 0), 1.18, 0.5, 1e5);
  auto blk = blocks_patch(0, ctu::embedded::make(pf::porosity::impermeable{}, 0));
  const auto [worst_x, worst_f] = run_side_by_side(box, blk);
  MESSAGE("30 coupled steps: max node-velocity difference ", worst_x, " (relative to 4 m/s), fluid energy ", worst_f,
          "; faces ", blk.coupling().diagnostics().faces, " vs ", box.coupling().diagnostics().faces);
  CHECK(blk.coupling().diagnostics().faces == box.coupling().diagnostics().faces);
  CHECK(blk.coupling().diagnostics().faces > 10);
  CHECK(worst_x < 1e-12);
  CHECK(worst_f < 1e-14);
}

TEST_CASE_TEMPLATE("embedded coupling across levels: momentum and energy exchange to round-off every step", C,
                   ctu::embedded, ctu::embedded_one_sided) {
  pf::parallel::set_threads(1);
  auto s = blocks_patch(2, C::make(pf::porosity::impermeable{}, 0));
  CHECK(s.fluid().tree().finest_level() == 2);
  const auto [scale, worst, worst_e] = balance_every_step(s, -1.0);
  MESSAGE(std::string(C::name), ", 30 steps, ", s.coupling().diagnostics().faces, " faces: max step impulse ", scale,
          " N s, max |dP_fluid + dP_structure| / |J| = ", worst, ", max |dE_fluid + W_fluid| / E = ", worst_e);
  CHECK(scale > 0);
  CHECK(worst < 1e-9);
  CHECK(worst_e < 1e-13);
}

TEST_CASE("one-sided embedded coupling on one level of blocks reproduces the box solver's run to round-off") {
  // The one-sided stencils (two cells on the open side, the neighbouring faces' fluxes)
  // cross block boundaries of the 4^3 blocks; the blocks read them from their ghost layers.
  pf::parallel::set_threads(1);
  auto box = ctu::tilted_patch(ctu::embedded_one_sided::make(pf::porosity::impermeable{}, 0), 1.18, 0.5, 1e5);
  auto blk = blocks_patch(0, ctu::embedded_one_sided::make(pf::porosity::impermeable{}, 0));
  auto first = ctu::tilted_patch(ctu::embedded::make(pf::porosity::impermeable{}, 0), 1.18, 0.5, 1e5);
  const auto [worst_x, worst_f] = run_side_by_side(box, blk);
  // The one-sided run differs from the first-order one by far more than round-off, so the
  // agreement above is the one-sided path's, not the first-order patch's.
  double apart = 0;
  for (int n = 0; n < 30; ++n) first.step(first.stable_dt(0.5));
  for (pf::index_t i = 0; i < first.structure().node_set().size(); ++i)
    apart = std::max(apart,
                     (first.structure().node_set().velocity(i) - box.structure().node_set().velocity(i)).norm() / 4.0);
  MESSAGE("30 coupled steps: max node-velocity difference ", worst_x, " (relative to 4 m/s), fluid energy ", worst_f,
          "; faces ", blk.coupling().diagnostics().faces, " vs ", box.coupling().diagnostics().faces,
          "; one-sided vs first order on the box: ", apart);
  CHECK(blk.coupling().diagnostics().faces == box.coupling().diagnostics().faces);
  CHECK(blk.coupling().diagnostics().faces > 10);
  CHECK(worst_x < 1e-12);
  CHECK(worst_f < 1e-14);
  CHECK(apart > 1e-6);
}

namespace {
/// The embedded coupling without its solve/record split: the block solver then patches its
/// faces one by one through patch() (the path every other patcher takes).
template <class Porosity, bool OneSided>
struct per_face_embedded : pf::coupling::embedded<Porosity, OneSided> {
  using pf::coupling::embedded<Porosity, OneSided>::embedded;
  double solve_patch(const pf::fluid::face_context&, const pf::fluid::view&, pf::fluid::cons<double>&,
                     pf::fluid::cons<double>&) const = delete;
};
}  // namespace

TEST_CASE_TEMPLATE("embedded faces solved apart and replayed in list order: the bits of the face-by-face patch", P,
                   pf::porosity::impermeable, pf::porosity::ergun) {
  // Three levels (the membrane on the finest), one-sided cells, 30 steps: every node
  // velocity, every cell and the coupling's sums equal bit for bit. The recorded run solves
  // its faces (and runs its block loops) on two threads, the face-by-face one on one.
  const int threads0 = pf::parallel::max_threads();
  const P por = [] {
    if constexpr (std::is_same_v<P, pf::porosity::ergun>) return pf::porosity::ergun{1e7, 1e4, 1e-4};
    else return P{};
  }();
  static_assert(pf::fluid::recording_face_patcher<pf::coupling::embedded<P, true>>);
  static_assert(!pf::fluid::recording_face_patcher<per_face_embedded<P, true>>);
  auto rec = blocks_patch(2, pf::coupling::embedded<P, true>{por});
  auto one = blocks_patch(2, per_face_embedded<P, true>{por});
  rec.fluid().set_threading(true);
  double moved = 0;
  for (int n = 0; n < 30; ++n) {
    pf::parallel::set_threads(2);
    const double dt = rec.stable_dt(0.5);
    rec.step(dt);
    pf::parallel::set_threads(1);
    one.step(dt);
  }
  pf::parallel::set_threads(threads0);
  long differ = 0;
  const auto& a = rec.structure().node_set();
  const auto& b = one.structure().node_set();
  for (pf::index_t i = 0; i < a.size(); ++i) {
    differ += a.velocity(i) != b.velocity(i) || a.position(i) != b.position(i);
    moved = std::max(moved, (a.velocity(i) - Eigen::Vector3d{4.0, 1.0, -0.5}).norm());
  }
  const auto va = rec.fluid().view(), vb = one.fluid().view();
  const fb::block_index at{rec.fluid().block_cells()};
  long cells = 0;
  for (pf::index_t id = 0; id < rec.fluid().block_count(); ++id)
    for (pf::index_t k = 0; k < at.n; ++k)
      for (pf::index_t j = 0; j < at.n; ++j)
        for (pf::index_t i = 0; i < at.n; ++i) {
          const pf::index_t c = rec.fluid().global_index(id, at(i, j, k));
          ++cells;
          differ += va.rho[c] != vb.rho[c] || va.mx[c] != vb.mx[c] || va.my[c] != vb.my[c] || va.mz[c] != vb.mz[c] ||
                    va.E[c] != vb.E[c];
        }
  const auto& da = rec.coupling().diagnostics();
  const auto& db = one.coupling().diagnostics();
  MESSAGE(da.faces, " faces, ", cells, " cells, nodes moved by up to ", moved, " m/s; values differing: ", differ);
  CHECK(da.faces >= 64);  // block_solver::threaded_faces: the threaded solve runs
  CHECK(cells > 0);
  CHECK(moved > 1e-3);  // the coupling acted
  CHECK(differ == 0);
  CHECK(da.work_fluid == db.work_fluid);
  CHECK(da.mass_defect == db.mass_defect);
  CHECK(da.through_flow == db.through_flow);
}

TEST_CASE_TEMPLATE(
    "embedded coupling with level subcycling: the membrane on the finest level, momentum exchanged to "
    "round-off every step",
    C, ctu::embedded, ctu::embedded_one_sided) {
  // Levels 1-2 (every root block holds the patch or its buffer): the finest level takes two
  // steps per coarse step, the faces are found and the structure advanced around each of
  // them. Periodic box: what the structure gains over the step, the air loses.
  pf::parallel::set_threads(1);
  auto s = blocks_patch(2, C::make(pf::porosity::impermeable{}, 0));
  REQUIRE(s.fluid().tree().finest_level() == 2);
  CHECK(s.fluid().finest_substeps() == 2);
  auto momentum = [&] {
    const auto t = s.fluid().totals();
    return Eigen::Vector3d(t.momentum[0], t.momentum[1], t.momentum[2]);
  };
  double worst = 0, scale = 0, ratio = 0;
  for (int n = 0; n < 15; ++n) {
    const Eigen::Vector3d pf0 = momentum(), ps0 = s.structure().linear_momentum();
    const double dt_one = s.stable_dt(0.5), dt = s.stable_dt_subcycled(0.5);
    ratio = std::max(ratio, dt / dt_one);
    s.step_subcycled(dt);
    CHECK(s.last_substeps() >= 2);
    const Eigen::Vector3d dpf = momentum() - pf0, dps = s.structure().linear_momentum() - ps0;
    scale = std::max(scale, dps.norm());
    worst = std::max(worst, (dpf + dps).norm() / std::max(dps.norm(), 1e-300));
  }
  MESSAGE(std::string(C::name), ", 15 subcycled steps (up to ", ratio, " times the one-rate step), ",
          s.coupling().diagnostics().faces, " faces: max |dP_structure| ", scale,
          " N s, max |dP_fluid + dP_structure| / |dP_structure| = ", worst);
  CHECK(scale > 0);
  CHECK(ratio > 1.5);
  CHECK(worst < 1e-9);
}
