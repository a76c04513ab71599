// The block-structured fluid mesh, convergence through coarse-fine interfaces (slow:
// about two minutes in the release build).
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "fluid_test_util.hpp"

using namespace parafsi;
namespace fb = parafsi::fluid::blocks;

namespace {
/// L1 and L-infinity norms of a density difference (against the exact solution, or
/// between two runs).
struct vortex_errors {
  double l1 = 0, linf = 0;
};
/// One mesh's results: the errors with one time step for all levels and with level
/// subcycling, and the difference between the two runs' densities.
struct band_run {
  vortex_errors one, sub, diff;
};

/// A flow in x and y on the periodic box [0, 10]^2 (one block of 4 cells deep in z) with a
/// band x in [3.75, 6.25] of blocks one level finer (with `levels` = 2 also a band x in
/// [4.375, 5.625] two levels finer, a block of the first band's level inside its edges),
/// from `exact(x, y, 0)` to t_end, on two meshes (root blocks of 4^3 cells: 32 and 64 coarse
/// cells across), each run with one time step for all levels and with level subcycling.
/// Norms of rho over the whole box, or with `finest_only` over the finest band's cells.
template <class Time = time::ssp_rk2, class Exact>
std::array<band_run, 2> through_bands(const Exact& exact, int levels, double t_end, const std::string& what,
                                      bool finest_only = false) {
  std::array<band_run, 2> out{};
  for (int g = 0; g < 2; ++g) {
    const index_t nb = index_t(8) << g;
    fluid::block_layout lay{{0, 0, 0}, {10, 10, 10.0 / double(nb)}, {nb, nb, 1}, 4};
    fb::tree t({nb, nb, 1}, {true, true, true});
    t.refine_where(levels, [&](const fb::location& q) {
      const double w = lay.block_width(0, q.level), a = w * double(q.l[0]);
      if (q.level == 0) return a >= 3.75 - 1e-12 && a + w <= 6.25 + 1e-12;
      return a >= 4.375 - 1e-12 && a + w <= 5.625 + 1e-12;
    });
    auto make = [&] {
      fluid::block_solver s{t, lay, boundary::set::all(boundary::periodic{}), recon::muscl<limiter::mc>{}, Time{}};
      s.initialize_averaged([&](const Eigen::Vector3d& x) { return exact(x[0], x[1], 0.0); }, 3);
      return s;
    };
    auto one = make();
    pft::run_to(one, t_end, 0.5);
    auto sub = make();
    while (sub.time() < t_end - 1e-14) sub.step_subcycled(std::min(sub.stable_dt_subcycled(0.5), t_end - sub.time()));
    // The same tree, so both runs list their cells in the same order.
    std::vector<double> rho_one;
    one.for_each_cell([&](const auto& b, index_t i, index_t j, index_t k) {
      if (finest_only && b.where.level != levels) return;
      rho_one.push_back(fluid::detail::load_cons(fluid::detail::conserved_ptrs(b.U), b.grid.index(i, j, k)).rho);
    });
    band_run& r = out[std::size_t(g)];
    double vol = 0;
    std::size_t n = 0;
    auto add = [](vortex_errors& e, double d, double cv) {
      e.l1 += std::fabs(d) * cv;
      e.linf = std::max(e.linf, std::fabs(d));
    };
    sub.for_each_cell([&](const auto& b, index_t i, index_t j, index_t k) {
      if (finest_only && b.where.level != levels) return;
      const double rho = fluid::detail::load_cons(fluid::detail::conserved_ptrs(b.U), b.grid.index(i, j, k)).rho;
      double ex = 0;  // cell average by 3x3 midpoint quadrature (2-D flow)
      for (int bb = 0; bb < 3; ++bb)
        for (int a = 0; a < 3; ++a)
          ex += exact(b.grid.face(0, i) + b.grid.width(0, i) * (a + 0.5) / 3,
                      b.grid.face(1, j) + b.grid.width(1, j) * (bb + 0.5) / 3, t_end)
                    .rho /
                9.0;
      const double cv = b.grid.cell_volume(i, j, k);
      const double rho1 = rho_one.at(n);  // throws, and fails the test, if the runs' cells differ
      add(r.one, rho1 - ex, cv);
      add(r.sub, rho - ex, cv);
      add(r.diff, rho - rho1, cv);
      ++n;
      vol += cv;
    });
    REQUIRE(n == rho_one.size());
    for (vortex_errors* e : {&r.one, &r.sub, &r.diff}) e->l1 /= vol;
    MESSAGE(what, ", ", 4 * nb, " coarse cells across (", sub.block_count(), " blocks, levels 0-", levels,
            "): L1(rho) = ", r.one.l1, " one step, ", r.sub.l1, " subcycled, ", r.diff.l1,
            " between the two; Linf(rho) = ", r.one.linf, ", ", r.sub.linf, ", ", r.diff.linf);
  }
  return out;
}

/// The isentropic vortex moving from x = 3.5 at unit speed along x: through the band by t = 3.
std::array<band_run, 2> vortex_through_band() {
  const fluid::reference::isentropic_vortex v{.u_inf = 1.0, .v_inf = 0.0, .cx = 3.5, .cy = 5.0, .period = 10.0};
  auto exact = [v](double x, double y, double t) {
    fluid::reference::isentropic_vortex ve = v;
    ve.cx = v.cx + v.u_inf * t;
    return ve(x, y);
  };
  return through_bands(exact, 1, 3.0, "vortex");
}

/// A sound wave of small amplitude eps travelling along +x in still air (rho0 = 1, c = 1):
/// rho = 1 + eps s, u = eps s, p = 1/gamma + eps s, s = sin(2 pi (x - t) / 5) (linear acoustics;
/// the nonlinear steepening moves rho by O(eps^2 t), far below the truncation errors).
struct sound_wave {
  double eps = 1e-5;
  fluid::prim<double> operator()(double x, double, double t) const {
    const double s = std::sin(2.0 * std::numbers::pi * (x - t) / 5.0);
    return {1.0 + eps * s, {eps * s, 0.0, 0.0}, 1.0 / 1.4 + eps * s};
  }
};

/// Observed order of one stepping's error between the two meshes.
double order(const std::array<band_run, 2>& r, vortex_errors band_run::*run, double vortex_errors::*norm) {
  return std::log2(r[0].*run.*norm / (r[1].*run.*norm));
}
}  // namespace

TEST_CASE(
    "the isentropic vortex keeps second-order convergence through coarse-fine interfaces, with one step for both "
    "levels and with level subcycling") {
  const auto r = vortex_through_band();
  const double one = order(r, &band_run::one, &vortex_errors::l1), sub = order(r, &band_run::sub, &vortex_errors::l1);
  // Subcycled, the coarse level steps twice as long as the fine one: its time error is
  // larger, and the fine level's ghosts come from the coarse state interpolated in time.
  MESSAGE("observed order: ", one, " one step for both levels, ", sub,
          " subcycled; subcycled against one step: ", r[0].sub.l1 / r[0].one.l1, ", ", r[1].sub.l1 / r[1].one.l1);
  CHECK(one > 1.8);
  CHECK(sub > 1.8);
  CHECK(r[1].sub.l1 < 1.5 * r[1].one.l1);
}

// Three levels, each level's step half its coarser neighbour's, with SSP-RK2 and SSP-RK3 (the
// refluxing's stage weights are each scheme's): a sound wave crosses the interfaces at the
// signal speed that sets the step, and the error is measured in the finest band, which the
// wave reaches through two coarse-fine interfaces. Each is held against one step for all
// levels with the same scheme. Observed (finer grid, subcycled against one step): SSP-RK2 L1
// 1.06, Linf 0.96, L1 order 1.92; SSP-RK3 L1 0.98, Linf 1.02, order 1.97.
//
// The errors alone do not resolve the finer levels' ghosts' time interpolation: ghosts held
// at the end of the coarser level's step change them by at most 16 % (each level's step, CFL
// 0.5 on the three axes' rates, is a sixth of its cell's sound crossing). The difference
// between the subcycled and the one-step run on the same mesh does, as it leaves out the
// spatial error both share: observed 0.019 and 0.071 (SSP-RK2), 0.019 and 0.026 (SSP-RK3) of
// the one-step error on the two grids, against 0.26-0.27 on both with the ghosts held at the
// end of the coarser step and about 0.2 with them held at its start. The SSP-RK2 difference
// stalls between these two grids (6.8e-9, 6.5e-9) and falls at second order beyond them
// (1.4e-9 at 128 coarse cells across, 0.06 of the error there; measured once, not run here).
TEST_CASE(
    "three levels, subcycled: a sound wave through the interfaces keeps the one-step accuracy in the finest band") {
  const sound_wave w{};
  const auto rk2 = through_bands(w, 2, 3.0, "sound wave, finest band", true);
  const auto rk3 = through_bands<time::ssp_rk3>(w, 2, 3.0, "sound wave, finest band, SSP-RK3", true);
  for (const auto& [r, name] : {std::pair{rk2, std::string("SSP-RK2")}, std::pair{rk3, std::string("SSP-RK3")}}) {
    MESSAGE(name, ": observed order L1 ", order(r, &band_run::one, &vortex_errors::l1), " one step, ",
            order(r, &band_run::sub, &vortex_errors::l1), " subcycled; Linf ",
            order(r, &band_run::one, &vortex_errors::linf), ", ", order(r, &band_run::sub, &vortex_errors::linf),
            "; finer grid, subcycled against one step: L1 ", r[1].sub.l1 / r[1].one.l1, ", Linf ",
            r[1].sub.linf / r[1].one.linf,
            "; the two runs' difference over the one-step error, L1: ", r[0].diff.l1 / r[0].one.l1, " and ",
            r[1].diff.l1 / r[1].one.l1);
    CHECK(order(r, &band_run::one, &vortex_errors::l1) > 1.8);
    CHECK(order(r, &band_run::sub, &vortex_errors::l1) > 1.8);
    CHECK(r[1].sub.l1 < 1.5 * r[1].one.l1);
    CHECK(r[1].sub.linf < 1.5 * r[1].one.linf);
    CHECK(r[0].diff.l1 < 0.06 * r[0].one.l1);
    CHECK(r[1].diff.l1 < 0.13 * r[1].one.l1);
  }
}
