// The block-structured fluid mesh, convergence through coarse-fine interfaces (slow:
// about two minutes in the release build).
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <tuple>
#include <utility>

#include "fluid_test_util.hpp"

using namespace parafsi;
namespace fb = parafsi::fluid::blocks;

namespace {
/// L1 and L-infinity errors of rho against the exact solution.
struct vortex_errors {
  double l1 = 0, linf = 0;
};

/// A flow in x and y on the periodic box [0, 10]^2 (one block of 4 cells deep in z) with a
/// band x in [3.75, 6.25] of blocks one level finer (with `levels` = 2 also a band x in
/// [4.375, 5.625] two levels finer, a block of the first band's level inside its edges),
/// from `exact(x, y, 0)` to t_end. Errors of rho against exact(x, y, t_end) on two meshes
/// (root blocks of 4^3 cells: 32 and 64 coarse cells across), with one time step for all
/// levels or with level subcycling; `finest_only`: over the cells of the finest band alone.
template <class Time = time::ssp_rk2, class Exact>
std::array<vortex_errors, 2> through_bands(const Exact& exact, bool subcycled, int levels, double t_end,
                                           const std::string& what, bool finest_only = false) {
  std::array<vortex_errors, 2> err{};
  for (int g = 0; g < 2; ++g) {
    const index_t nb = index_t(8) << g;
    fluid::block_layout lay{{0, 0, 0}, {10, 10, 10.0 / double(nb)}, {nb, nb, 1}, 4};
    fb::tree t({nb, nb, 1}, {true, true, true});
    t.refine_where(levels, [&](const fb::location& q) {
      const double w = lay.block_width(0, q.level), a = w * double(q.l[0]);
      if (q.level == 0) return a >= 3.75 - 1e-12 && a + w <= 6.25 + 1e-12;
      return a >= 4.375 - 1e-12 && a + w <= 5.625 + 1e-12;
    });
    fluid::block_solver s{t, lay, boundary::set::all(boundary::periodic{}), recon::muscl<limiter::mc>{}, Time{}};
    s.initialize_averaged([&](const Eigen::Vector3d& x) { return exact(x[0], x[1], 0.0); }, 3);
    if (subcycled)
      while (s.time() < t_end - 1e-14) s.step_subcycled(std::min(s.stable_dt_subcycled(0.5), t_end - s.time()));
    else pft::run_to(s, t_end, 0.5);
    double e = 0, vol = 0, emax = 0;
    s.for_each_cell([&](const auto& b, index_t i, index_t j, index_t k) {
      if (finest_only && b.where.level != levels) return;
      const auto q = fluid::detail::load_cons(fluid::detail::conserved_ptrs(b.U), b.grid.index(i, j, k));
      double ex = 0;  // cell average by 3x3 midpoint quadrature (2-D flow)
      for (int bb = 0; bb < 3; ++bb)
        for (int a = 0; a < 3; ++a)
          ex += exact(b.grid.face(0, i) + b.grid.width(0, i) * (a + 0.5) / 3,
                      b.grid.face(1, j) + b.grid.width(1, j) * (bb + 0.5) / 3, t_end)
                    .rho /
                9.0;
      const double cv = b.grid.cell_volume(i, j, k);
      e += std::fabs(q.rho - ex) * cv;
      emax = std::max(emax, std::fabs(q.rho - ex));
      vol += cv;
    });
    err[std::size_t(g)] = {e / vol, emax};
    MESSAGE(what, ", ", 4 * nb, " coarse cells across (", s.block_count(), " blocks, levels 0-", levels,
            std::string(subcycled ? ", subcycled" : ""), "): L1(rho) = ", err[std::size_t(g)].l1,
            ", Linf(rho) = ", err[std::size_t(g)].linf);
  }
  return err;
}

/// The isentropic vortex moving from x = 3.5 at unit speed along x: through the bands by t = 3.
std::array<vortex_errors, 2> vortex_through_band(bool subcycled, int levels = 1) {
  const fluid::reference::isentropic_vortex v{.u_inf = 1.0, .v_inf = 0.0, .cx = 3.5, .cy = 5.0, .period = 10.0};
  auto exact = [v](double x, double y, double t) {
    fluid::reference::isentropic_vortex ve = v;
    ve.cx = v.cx + v.u_inf * t;
    return ve(x, y);
  };
  return through_bands(exact, subcycled, levels, 3.0, "vortex");
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

double order(const std::array<vortex_errors, 2>& e, double vortex_errors::*norm) {
  return std::log2(e[0].*norm / e[1].*norm);
}
}  // namespace

TEST_CASE(
    "the isentropic vortex keeps second-order convergence through coarse-fine interfaces, with one step for both "
    "levels and with level subcycling") {
  const auto one = vortex_through_band(false);
  MESSAGE("one step for both levels: observed order ", order(one, &vortex_errors::l1));
  CHECK(order(one, &vortex_errors::l1) > 1.8);
  // Subcycled, the coarse level steps twice as long as the fine one: its time error is
  // larger, and the fine level's ghosts come from the coarse state interpolated in time.
  const auto sub = vortex_through_band(true);
  MESSAGE("subcycled: observed order ", order(sub, &vortex_errors::l1),
          "; error against one step for both levels: ", sub[0].l1 / one[0].l1, ", ", sub[1].l1 / one[1].l1);
  CHECK(order(sub, &vortex_errors::l1) > 1.8);
  CHECK(sub[1].l1 < 1.5 * one[1].l1);
}

// Three levels, each level's step half its coarser neighbour's, with SSP-RK2 and SSP-RK3 (the
// refluxing's stage weights are each scheme's): a sound wave crosses the interfaces at the
// signal speed that sets the step, and the error is measured in the finest band, which the
// wave reaches through two coarse-fine interfaces. Each is held against one step for all
// levels with the same scheme. Observed (finer grid, subcycled against one step): SSP-RK2 L1
// 1.06, Linf 0.96, L1 order 1.92; SSP-RK3 L1 0.98, Linf 1.02, order 1.97. What this does not resolve:
// ghosts held at the end of the coarser level's step instead of interpolated in time give
// errors within 16 % of these (each level's step, CFL 0.5 on the three axes' rates, is a
// sixth of its cell's sound crossing, so a coarse step moves the wave a sixth of a coarse
// cell): no test resolves the interpolation itself yet (a flow that a coarse step moves by a
// larger part of a cell would).
TEST_CASE(
    "three levels, subcycled: a sound wave through the interfaces keeps the one-step accuracy in the finest band") {
  const sound_wave w{};
  const auto one2 = through_bands(w, false, 2, 3.0, "sound wave, finest band", true);
  const auto sub2 = through_bands(w, true, 2, 3.0, "sound wave, finest band", true);
  const auto one3 = through_bands<time::ssp_rk3>(w, false, 2, 3.0, "sound wave, finest band, SSP-RK3", true);
  const auto sub3 = through_bands<time::ssp_rk3>(w, true, 2, 3.0, "sound wave, finest band, SSP-RK3", true);
  for (const auto& [one, sub, name] :
       {std::tuple{one2, sub2, std::string("SSP-RK2")}, std::tuple{one3, sub3, std::string("SSP-RK3")}}) {
    MESSAGE(name, ": observed order L1 ", order(one, &vortex_errors::l1), " one step, ", order(sub, &vortex_errors::l1),
            " subcycled; Linf ", order(one, &vortex_errors::linf), ", ", order(sub, &vortex_errors::linf),
            "; finer grid, subcycled against one step: L1 ", sub[1].l1 / one[1].l1, ", Linf ",
            sub[1].linf / one[1].linf);
    CHECK(order(one, &vortex_errors::l1) > 1.8);
    CHECK(order(sub, &vortex_errors::l1) > 1.8);
    CHECK(sub[1].l1 < 1.5 * one[1].l1);
    CHECK(sub[1].linf < 1.5 * one[1].linf);
  }
}
