// Laminar viscosity on the block mesh (fluid::block_solver with viscosity::constant): one
// level reproduces the box solver's viscous run to round-off (the viscous pass runs on each
// block with its ghost layers, and its stable step includes the viscous limit); across a
// level boundary the viscous fluxes are corrected with the inviscid ones, so mass,
// momentum and energy are conserved to round-off, and a shear wave u_y = U sin(kx), whose
// amplitude decays as exp(−ν k² t) (the transverse momentum diffuses; exact for the
// linearised compressible equations), decays at that rate through a band one level finer.
// Eddy viscosity (Smagorinsky; Prandtl's mixing length with a wall distance filled on each
// block's cells and ghosts): one level reproduces the box solver; across levels and a regrid
// (which carries μ_t over) mass, momentum and energy are conserved to round-off.
#include <doctest/doctest.h>

#include "approx.hpp"

#include <cmath>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include <parafsi/fluid/wall_distance.hpp>

#include "fluid_test_util.hpp"

using namespace parafsi;
namespace fb = parafsi::fluid::blocks;

namespace {
constexpr double rho0 = 1.0, p0 = 1.0;  // c ≈ 1.18 m/s: viscous and acoustic steps alike

/// The mixing length's wall distance from `pts` on a box solver and a block mesh, ghosts
/// included on both (the viscous pass computes μ_t on the first ghost layer).
template <class Box, class Blocks>
void fill_wall_distance(Box& box, Blocks& blk, const std::vector<Eigen::Vector3d>& pts, double reach) {
  const auto& g = box.grid();
  fluid::distance_to_points(g, pts, reach, std::span<double>(box.wall_distance(), std::size_t(g.total_cells())), true);
  for (index_t id = 0; id < blk.block_count(); ++id) {
    const auto& bg = blk.block_at(id).grid;
    fluid::distance_to_points(bg, pts, reach, std::span<double>(blk.wall_distance(id), std::size_t(bg.total_cells())),
                              true);
  }
}

/// `steps` steps of both at the box's stable step (checking the blocks' equals it); the
/// largest relative state difference met.
template <class Box, class Blocks>
double lockstep(Box& box, Blocks& blk, int steps) {
  double worst = 0;
  for (int n = 0; n < steps; ++n) {
    const double dt = box.stable_dt(0.5);
    CHECK(blk.stable_dt(0.5) == doctest::Approx(dt).epsilon(1e-12));
    box.step(dt);
    blk.step(dt);
    worst = std::max(worst, pft::max_block_box_difference(blk, box));
  }
  return worst;
}

}  // namespace

TEST_CASE("viscous block mesh: one level reproduces the box solver to round-off, viscous step limit included") {
  const double pi2 = 2.0 * std::numbers::pi;
  viscosity::constant mu;
  mu.mu_value = 0.05;  // the viscous step limit h²/(12 ν) binds on the 1/16 m cells
  const auto bc = boundary::set::all(boundary::periodic{});
  fluid::block_layout lay{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, 8};
  fluid::block_solver blk{fb::tree({2, 2, 2}, {true, true, true}), lay, bc, mu};
  fluid::solver box{fluid::rectilinear_grid::uniform({16, 16, 16}, lay.lo, lay.hi), bc, mu};
  auto field = [&](const Eigen::Vector3d& x) {
    return fluid::prim<double>{rho0 * (1.0 + 0.1 * std::sin(pi2 * (x[0] + x[2]))),
                               {0.05 * std::sin(pi2 * x[1]), 0.05 * std::sin(pi2 * x[2]), 0.05 * std::sin(pi2 * x[0])},
                               p0 * (1.0 + 0.05 * std::cos(pi2 * x[1]))};
  };
  blk.initialize(field);
  box.initialize(field);
  const double dt_blk = blk.stable_dt(0.5), dt_box = box.stable_dt(0.5);
  double worst = 0;
  for (int n = 0; n < 20; ++n) {
    const double dt = box.stable_dt(0.5);
    box.step(dt);
    blk.step(dt);
    worst = std::max(worst, pft::max_block_box_difference(blk, box));
  }
  // The inviscid step of the same state, to show the viscous limit is the one that binds.
  fluid::solver inv{fluid::rectilinear_grid::uniform({16, 16, 16}, lay.lo, lay.hi), bc};
  inv.initialize(field);
  MESSAGE("20 viscous steps (mu 0.05 Pa s): max relative state difference ", worst, "; stable dt blocks ", dt_blk,
          " s, box ", dt_box, " s, inviscid box ", inv.stable_dt(0.5), " s");
  CHECK(worst < 1e-14);
  CHECK(dt_blk == doctest::Approx(dt_box).epsilon(1e-14));
  CHECK(dt_box < 0.9 * inv.stable_dt(0.5));
}

TEST_CASE("viscous block mesh across a level boundary: conservation to round-off and the shear wave's decay") {
  const double pi2 = 2.0 * std::numbers::pi, U = 0.01, L = 1.0, k = pi2 / L;
  viscosity::constant mu;
  mu.mu_value = 0.01;
  const double nu = mu.mu_value / rho0;
  // A periodic 1 x 0.25 x 0.25 m box of 4 root blocks of 8^3 (h = 1/32 m); the second refined
  // once (x in [0.25, 0.5], h = 1/64 m), so the wave crosses two level boundaries.
  fluid::block_layout lay{{0, 0, 0}, {L, 0.25, 0.25}, {4, 1, 1}, 8};
  fb::tree t({4, 1, 1}, {true, true, true});
  t.refine_where(1, [](const fb::location& q) { return q.level == 0 && q.l[0] == 1; });
  fluid::block_solver s{t, lay, boundary::set::all(boundary::periodic{}), mu};
  s.initialize([&](const Eigen::Vector3d& x) {
    return fluid::prim<double>{rho0, {0.0, U * std::sin(k * x[0]), 0.0}, p0};
  });
  auto amplitude = [&] {  // projection of u_y on sin(kx) over the leaf cells
    double a = 0, b = 0;
    s.for_each_cell([&](const auto& blk, index_t i, index_t j, index_t kk) {
      const auto w = fluid::to_prim(fluid::detail::load_cons(fluid::detail::conserved_ptrs(blk.U),
                                                             blk.grid.index(i, j, kk)),
                                    s.gas());
      const double sn = std::sin(k * blk.grid.centre(0, i)), v = blk.grid.cell_volume(i, j, kk);
      a += w.u.y * sn * v;
      b += sn * sn * v;
    });
    return a / b;
  };
  const double a0 = amplitude();
  const auto t0 = s.totals();
  double worst_m = 0, worst_p = 0, worst_e = 0;
  const double t_end = 0.5;
  while (s.time() < t_end - 1e-12) {
    s.step(std::min(s.stable_dt(0.5), t_end - s.time()));
    const auto t1 = s.totals();
    worst_m = std::max(worst_m, std::fabs(t1.mass - t0.mass) / t0.mass);
    worst_e = std::max(worst_e, std::fabs(t1.energy - t0.energy) / t0.energy);
    for (int d = 0; d < 3; ++d)
      worst_p = std::max(worst_p, std::fabs(t1.momentum[std::size_t(d)] - t0.momentum[std::size_t(d)]) /
                                      (rho0 * U * t0.mass / rho0));
  }
  const double decay = amplitude() / a0, exact = std::exp(-nu * k * k * t_end);
  MESSAGE(s.block_count(), " blocks, levels 0-1, ", s.steps(), " steps to t = ", t_end, " s: amplitude ratio ", decay,
          ", exact exp(-nu k^2 t) = ", exact, " (error ", 100 * (decay / exact - 1), " %); conservation: mass ",
          worst_m, ", momentum ", worst_p, " (of rho U V), energy ", worst_e);
  CHECK(s.tree().finest_level() == 1);
  CHECK(decay == pft::rel(exact, 5e-3));
  CHECK(worst_m < 1e-13);
  CHECK(worst_p < 1e-12);
  CHECK(worst_e < 1e-13);
}

TEST_CASE("eddy viscosity on blocks: one level reproduces the box solver (Smagorinsky, mixing length)") {
  const double pi2 = 2.0 * std::numbers::pi;
  viscosity::constant mu;
  mu.mu_value = 2e-4;
  const auto bc = boundary::set::all(boundary::periodic{});
  fluid::block_layout lay{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, 8};
  auto field = [&](const Eigen::Vector3d& x) {
    return fluid::prim<double>{rho0 * (1.0 + 0.1 * std::sin(pi2 * (x[0] + x[2]))),
                               {0.05 * std::sin(pi2 * x[1]), 0.05 * std::sin(pi2 * x[2]), 0.05 * std::sin(pi2 * x[0])},
                               p0 * (1.0 + 0.05 * std::cos(pi2 * x[1]))};
  };
  auto run = [&](auto closure, const char* label) {
    fluid::block_solver blk{fb::tree({2, 2, 2}, {true, true, true}), lay, bc, mu, closure};
    fluid::solver box{fluid::rectilinear_grid::uniform({16, 16, 16}, lay.lo, lay.hi), bc, mu, closure};
    blk.initialize(field);
    box.initialize(field);
    if constexpr (requires { box.wall_distance(); }) {
      // A plate of points in the middle of the box, > reach + 2 cells from its faces.
      std::vector<Eigen::Vector3d> pts;
      for (int a = 0; a <= 10; ++a)
        for (int b = 0; b <= 10; ++b) pts.emplace_back(0.3 + 0.04 * a, 0.3 + 0.04 * b, 0.5 + 0.01 * a);
      fill_wall_distance(box, blk, pts, closure.c_l * closure.ref_length / closure.kappa);
    }
    const double worst = lockstep(box, blk, 20);
    double mut = 0;
    const auto& g = box.grid();
    for (index_t c = 0; c < g.total_cells(); ++c) mut = std::max(mut, box.eddy_viscosity()[c]);
    MESSAGE(std::string(label), ": 20 steps, max relative state difference ", worst, "; largest mu_t ", mut,
            " Pa s (mu ", mu.mu_value, ")");
    CHECK(mut > 0.1 * mu.mu_value);  // the closure matters here
    CHECK(worst < 1e-13);
  };
  turbulence::smagorinsky sm;
  sm.cs = 0.17;
  sm.mu_cap = 1.0;
  run(sm, "Smagorinsky C_s 0.17");
  turbulence::prandtl_mixing_length ml;
  ml.ref_length = 1.0;
  ml.mu_cap = 1.0;
  run(ml, "mixing length, C_l D0 0.07 m");
}

TEST_CASE("viscous block mesh at the box's boundaries: slip walls, far field, outflow and a sponge as the box solver") {
  // The viscous pass reads the face ghosts and the edge ghosts one cell deep; at the box's
  // boundaries these come from the boundary conditions (an edge where a wall meets the far
  // field, a block face meeting a box face), not from neighbours. One level of 3 x 2 x 2 blocks
  // with a slip wall on x-, the far field on x+ and y-, an outflow on y+, periodic z and a
  // 3-cell sponge, a shear flow with the mixing-length closure: the box solver's answer.
  const double pi2 = 2.0 * std::numbers::pi;
  viscosity::constant mu;
  mu.mu_value = 2e-3;
  boundary::set bc;
  bc.side(0, 0, boundary::slip_wall{})
      .side(0, 1, boundary::far_field{rho0, {0.02, 0, 0}, p0})
      .side(1, 0, boundary::far_field{rho0, {0.02, 0, 0}, p0})
      .side(1, 1, boundary::outflow{})
      .axis(2, boundary::periodic{});
  bc.layer = {3, 0.5};
  fluid::block_layout lay{{0, 0, 0}, {1.5, 1, 1}, {3, 2, 2}, 8};
  turbulence::prandtl_mixing_length ml;
  ml.ref_length = 1.0;
  ml.mu_cap = 1.0;
  fluid::block_solver blk{fb::tree({3, 2, 2}, {false, false, true}), lay, bc, mu, ml};
  fluid::solver box{fluid::rectilinear_grid::uniform({24, 16, 16}, lay.lo, lay.hi), bc, mu, ml};
  auto field = [&](const Eigen::Vector3d& x) {
    return fluid::prim<double>{rho0 * (1.0 +
                                       0.05 * std::exp(-((x - Eigen::Vector3d(0.2, 0.8, 0.5)).squaredNorm()) / 0.02)),
                               {0.02 + 0.05 * std::sin(pi2 * x[1]) * std::cos(pi2 * x[2]), 0.04 * std::sin(pi2 * x[2]),
                                0.05 * std::cos(pi2 * x[0] / 1.5) * std::sin(pi2 * x[1])},
                               p0 * (1.0 + 0.03 * std::cos(pi2 * x[2]))};
  };
  blk.initialize(field);
  box.initialize(field);
  // Points along the wall corner and across the middle: the wall distance reaches the edges.
  std::vector<Eigen::Vector3d> pts;
  for (int a = 0; a <= 20; ++a) {
    pts.emplace_back(0.02, 0.02, 0.05 * a);
    pts.emplace_back(0.75, 0.05 * a, 0.5);
  }
  // Ghosts included on both: the eddy viscosity of a ghost beside the wall corner reads its
  // own distance (left at "far", the box's ghost μ_t would take the full mixing length).
  fill_wall_distance(box, blk, pts, ml.c_l * ml.ref_length / ml.kappa);
  const double worst = lockstep(box, blk, 30);
  double mut = 0;
  const auto& g = box.grid();
  for (index_t c = 0; c < g.total_cells(); ++c) mut = std::max(mut, box.eddy_viscosity()[c]);
  MESSAGE(
      "walls, far field, outflow, sponge; 12 blocks vs the 24x16x16 box, 30 viscous steps: max relative state "
      "difference ",
      worst, "; largest mu_t ", mut, " Pa s (mu ", mu.mu_value, ")");
  CHECK(mut > 0.1 * mu.mu_value);
  CHECK(worst < 1e-13);
}

TEST_CASE("eddy viscosity across levels and regrids: conservation to round-off, mu_t carried") {
  const double pi2 = 2.0 * std::numbers::pi;
  viscosity::constant mu;
  mu.mu_value = 1e-3;
  turbulence::smagorinsky sm;
  sm.cs = 0.17;
  sm.mu_cap = 1.0;
  fluid::block_layout lay{{0, 0, 0}, {1, 0.25, 0.25}, {4, 1, 1}, 8};
  fb::tree t({4, 1, 1}, {true, true, true});
  t.refine_where(1, [](const fb::location& q) { return q.level == 0 && q.l[0] == 1; });
  fluid::block_solver s{t, lay, boundary::set::all(boundary::periodic{}), mu, sm};
  s.initialize([&](const Eigen::Vector3d& x) {
    return fluid::prim<double>{rho0, {0.02 * std::sin(pi2 * x[2] * 4), 0.05 * std::sin(pi2 * x[0]), 0.0}, p0};
  });
  const auto t0 = s.totals();
  double worst = 0;
  int regrids = 0;
  for (int n = 0; n < 40; ++n) {
    s.step(s.stable_dt(0.5));
    if (n == 19) {  // move the fine band one block along x
      regrids += s.regrid([](const fb::location& q) { return q.l[0] == (q.level == 0 ? 2 : 4) || q.l[0] == 5 ? 1 : 0; },
                          1);
      double mx = 0;
      for (index_t id = 0; id < s.block_count(); ++id) {
        const auto& b = s.block_at(id);
        for (index_t c = 0; c < b.grid.total_cells(); ++c) mx = std::max(mx, b.T.template get<fluid::field::mu_t>()[c]);
      }
      MESSAGE("after the regrid: largest mu_t carried over ", mx, " Pa s");
      CHECK(mx > 0);
    }
    const auto t1 = s.totals();
    worst = std::max({worst, std::fabs(t1.mass - t0.mass) / t0.mass, std::fabs(t1.energy - t0.energy) / t0.energy,
                      std::fabs(t1.momentum[0] - t0.momentum[0]) / (0.05 * t0.mass),
                      std::fabs(t1.momentum[1] - t0.momentum[1]) / (0.05 * t0.mass)});
  }
  MESSAGE(s.block_count(), " blocks, ", regrids, " regrid: worst relative change of mass, momentum, energy ", worst);
  CHECK(regrids == 1);
  CHECK(worst < 1e-13);
}

TEST_CASE("wall_distance_from: each block's reach gives the mixing length of the unbounded search") {
  // Two levels (cells of 1/16 and 1/32 m) and L_ref = 1 m: the closure's cap C_l L_ref =
  // 0.07 m exceeds both grid caps C_Δ Δ, so a block searches only min(C_l L_ref, C_Δ Δ)/κ
  // (0.152 and 0.076 m) of the unbounded C_l L_ref/κ = 0.171 m. Where it stops, κ d_w is
  // not the smallest length, so l_m = min(κ d_w, C_l L_ref, C_Δ Δ) is the same double.
  viscosity::constant mu;
  turbulence::prandtl_mixing_length ml;
  ml.ref_length = 1.0;
  fluid::block_layout lay{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, 8};
  fb::tree t({2, 2, 2}, {false, false, false});
  t.refine_where(1, [](const fb::location& q) { return q.level == 0 && q.l[0] == 1 && q.l[1] == 0 && q.l[2] == 0; });
  fluid::block_solver blk{t, lay, boundary::set::all(boundary::outflow{}), mu, ml};
  std::vector<Eigen::Vector3d> pts;
  for (int a = 0; a <= 12; ++a) {
    pts.emplace_back(0.3 + 0.05 * a, 0.2, 0.25);
    pts.emplace_back(0.5, 0.08 * a, 0.6);
  }
  blk.wall_distance_from(pts);
  const double full = ml.c_l * ml.ref_length / ml.kappa;
  int cut = 0, near = 0, mismatched = 0;
  for (index_t id = 0; id < blk.block_count(); ++id) {
    const auto& g = blk.block_at(id).grid;
    std::vector<double> d(std::size_t(g.total_cells()));
    fluid::distance_to_points(g, pts, full, d, true);
    const double delta = std::cbrt(g.width(0, 0) * g.width(1, 0) * g.width(2, 0));
    const double* dw = blk.wall_distance(id);
    auto lm = [&](double dist) {
      return std::min(std::min(ml.kappa * dist, ml.c_l * ml.ref_length), ml.c_delta * delta);
    };
    for (index_t c = 0; c < g.total_cells(); ++c) {
      const auto ijk = g.ijk(c);
      if (ijk[0] < -2 || ijk[0] >= 10 || ijk[1] < -2 || ijk[1] >= 10 || ijk[2] < -2 || ijk[2] >= 10) continue;
      if (dw[c] > 1e29 && d[std::size_t(c)] < 1e29) ++cut;
      if (d[std::size_t(c)] < 1e29) ++near;
      if (lm(dw[c]) != lm(d[std::size_t(c)])) ++mismatched;
    }
  }
  MESSAGE(near, " cells within the unbounded reach, ", cut, " of them beyond their block's");
  CHECK(cut > 0);  // the bounded search did skip cells
  CHECK(near > cut);
  CHECK(mismatched == 0);

  // The box solver: one reach for every cell, the unbounded one.
  fluid::solver box{fluid::rectilinear_grid::uniform({16, 16, 16}, lay.lo, lay.hi),
                    boundary::set::all(boundary::outflow{}), mu, ml};
  box.wall_distance_from(pts);
  std::vector<double> d(std::size_t(box.grid().total_cells()));
  fluid::distance_to_points(box.grid(), pts, full, d, true);
  CHECK(std::equal(d.begin(), d.end(), box.wall_distance()));
}
