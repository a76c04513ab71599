// The embedded coupling's duct verifications (methods §4.9.1–2) on a block mesh whose
// membrane sits on a finer level than the rest of the duct (fluid::block_solver):
// - the piston: a plate driven at 2 m/s into still air; where its shock has run from the
//   fine level into the coarse one, the pressure rise is within 0.5 % of the exact piston
//   shock and the air moves with the plate (no leak), as on the box solver;
// - the porous screen: a pinned sheet of each Table 2 fabric in a steady duct flow (HLLC
//   flux); the air crosses a level boundary before and after the sheet, and the pressure
//   drop between probes on the coarse level is the Ergun law at the measured velocity
//   within 1 %, as on the box solver.
#include <doctest/doctest.h>

#include <parafsi/model/fabric_catalogue.hpp>

#include <cmath>
#include <cstdio>
#include <string>

#include "coupling_test_util.hpp"

namespace pf = parafsi;
namespace st = pf::structure;
namespace fb = pf::fluid::blocks;

namespace {
constexpr double rho0 = 1.18, p0 = 101325.0;

/// The duct of model/duct_screen.hpp (length L, `cells` cubic cells of h along it, 2 h square)
/// as a block mesh: root blocks of 4 cells along x (h each) and one across (h/2 cells),
/// refined once within `buffer` of the sheet, so the sheet lies on level 1.
template <class Coupling, class Assembly, class Flux = pf::flux::hllc_lm>
auto block_duct(const pf::model::duct_screen_scene& d, const pf::boundary::set& bc, double buffer, Coupling cpl,
                Assembly as, double u0, Flux flux = {}) {
  const auto nb = pf::index_t(d.cells[0] / 4);
  REQUIRE(nb * 4 == d.cells[0]);
  pf::fluid::block_layout lay{d.lo, d.hi, {nb, 1, 1}, 4};
  fb::tree t(lay.root_blocks, {false, false, false});
  t.refine_where(1, fb::near_points(lay, d.sheet.positions, buffer, 1));
  pf::fluid::block_solver fl{t, lay, bc, flux};
  fl.fill_uniform({rho0, {u0, 0, 0}, p0});
  return pf::explicit_stepper{std::move(fl), std::move(as), std::move(cpl)};
}

/// Volume means of p and u_x over the leaf cells with centres in a < x < b, and the finest
/// and coarsest level among them.
template <class S>
void block_window(const S& s, double a, double b, double& p, double& u, int& lmin, int& lmax) {
  double vol = 0;
  p = u = 0;
  lmin = 99;
  lmax = -1;
  s.fluid().for_each_cell([&](const auto& blk, pf::index_t i, pf::index_t j, pf::index_t k) {
    const double x = blk.grid.centre(0, i);
    if (x <= a || x >= b) return;
    const auto w = pf::fluid::to_prim(pf::fluid::detail::load_cons(pf::fluid::detail::conserved_ptrs(blk.U),
                                                                   blk.grid.index(i, j, k)),
                                      s.fluid().gas());
    const double v = blk.grid.cell_volume(i, j, k);
    p += w.p * v;
    u += w.u.x * v;
    vol += v;
    lmin = std::min(lmin, blk.where.level);
    lmax = std::max(lmax, blk.where.level);
  });
  REQUIRE(vol > 0);
  p /= vol;
  u /= vol;
}
}  // namespace

TEST_CASE_TEMPLATE("embedded piston across a level boundary: the exact piston shock, no leak", C, ctu::embedded,
                   ctu::embedded_one_sided) {
  pf::parallel::set_threads(1);
  const double v = 2.0, t_end = 3e-3, x0 = 0.5;
  const auto d = pf::model::duct_screen(2.0, 100, x0);
  pf::boundary::set bc = pf::boundary::set::all(pf::boundary::slip_wall{});
  bc.axis(0, pf::boundary::far_field{});
  st::nodes nd;
  for (const auto& x : d.sheet.positions) nd.add(x, {v, 0, 0});
  for (pf::index_t i = 0; i < nd.size(); ++i) nd.prescribe_velocity(i, {v, 0, 0});
  st::membrane_tri mem{ctu::sheet_mesh(d), st::material::fabric<>::isotropic(1e6, 0.3, 1.0, 1e-3)};
  st::assembly as{std::move(nd), std::move(mem)};
  as.integrator().gravity = {0, 0, 0};
  // Level 1 (1 cm cells) within 0.25 m of the plate: x in [0.24, 0.8]; the shock runs to 1.53 m.
  auto s = block_duct(d, bc, 0.25, C::make(pf::porosity::impermeable{}, 0), std::move(as), 0.0);
  while (s.time() < t_end - 1e-15) s.step(std::min(s.stable_dt(0.5), t_end - s.time()));
  const double c = std::sqrt(1.4 * p0 / rho0), xp = x0 + v * t_end, xf = x0 + c * t_end;
  const double cs = rho0 * c * v, q = 2.4 * v / c / 4.0, exact = cs * (q + std::sqrt(1.0 + q * q));
  double p, u;
  int lmin, lmax;
  block_window(s, xp + 0.2 * (xf - xp), xp + 0.8 * (xf - xp), p, u, lmin, lmax);
  const double e_exact = (p - p0) / exact - 1.0;
  std::printf(
      "%s piston on blocks (levels %d-%d in the window): dp = %.2f Pa, exact shock %.2f Pa (%+.3f %%), "
      "u_air = %.5f m/s\n",
      C::name, lmin, lmax, p - p0, exact, 100 * e_exact, u);
  CHECK(lmin == 0);
  CHECK(lmax == 1);
  CHECK(std::fabs(e_exact) < 0.005);
  CHECK(std::fabs(u - v) < 1e-3 * v);
}

TEST_CASE_TEMPLATE("embedded porous screen across level boundaries: the pressure drop on the Ergun law", C,
                   ctu::embedded, ctu::embedded_one_sided) {
  pf::parallel::set_threads(1);
  const double xs = 0.5;
  const auto d = pf::model::duct_screen(1.0, 40, xs);
  double worst = 0;
  for (const auto& fab : pf::model::fabric_catalogue) {
    const pf::porosity::ergun law{fab.alpha, fab.beta, fab.thickness};
    const double V = law.through_velocity(120.0) * 1.05;
    pf::boundary::set bc = pf::boundary::set::all(pf::boundary::slip_wall{});
    bc.side(0, 0, pf::boundary::inflow{rho0, {V, 0, 0}, p0});
    bc.side(0, 1, pf::boundary::outflow{true, p0});
    // Level 1 within 5 cm of the sheet: x in [0.4, 0.6] (blocks of 0.1 m); the probes 0.1-0.2 m
    // either side are on level 0, so the air crosses a level boundary before and after the sheet.
    auto s = block_duct(d, bc, 0.05, C::make(law, 0), ctu::pinned_sheet(d), V, pf::flux::hllc{});
    while (s.time() < 0.06) s.step(s.stable_dt(0.5));
    double pu, uu, pd, ud;
    int l0, l1, m0, m1;
    block_window(s, xs - 0.2, xs - 0.1, pu, uu, l0, l1);
    block_window(s, xs + 0.1, xs + 0.2, pd, ud, m0, m1);
    const double dp = pu - pd, ergun = law.pressure_jump(uu), err = dp / ergun - 1.0;
    std::printf(
        "%s screen on blocks %-9s (probe levels %d-%d, %d-%d): through %.5g m/s, dp %7.2f Pa, Ergun %7.2f Pa, "
        "error %+.3f %%\n",
        C::name, std::string(fab.name).c_str(), l0, l1, m0, m1, uu, dp, ergun, 100 * err);
    CHECK(s.fluid().tree().finest_level() == 1);
    CHECK(l1 == 0);
    CHECK(m1 == 0);
    worst = std::max(worst, std::fabs(err));
  }
  CHECK(worst < 1e-2);
}
