// Porous screen and leak box (methods §4.9.2–3), typed over the coupling list; the sheet
// across the duct is model/duct_screen.hpp (40 cells on 1 m, sheet at 0.5 m, all nodes
// pinned, 2 × 2 cells across):
// - a flat porous sheet in a slip-wall duct: the steady pressure drop between probe
//   windows 0.1–0.2 m up- and downstream against the fabric's Ergun law at the measured
//   upstream velocity, for mat544, mat59225 and mat509. Embedded: within 10 % from ~20 to
//   ~500 Pa (default HLLC-LM flux) and within 1 % with the HLLC flux (whose upstream flow
//   carries no odd–even velocity mode). Penalty (PFAC 1): within the 10 % bound at ~20
//   and ~500 Pa, and its error at the embedded inflow speeds reported beside it;
// - an impermeable membrane in a closed box with 50 Pa across: the penalty wall leaks, by
//   an amount of the order of mat544's Ergun through-flow at 50 Pa; the embedded wall's
//   leak is below 10 % of it (it is zero: no mass flux crosses a resting embedded wall)
//   and below the penalty wall's;
// - (embedded) a nearly impermeable and a nearly transparent screen run stably and give
//   the limits (wall; undisturbed stream).
#include <doctest/doctest.h>

#include <parafsi/model/fabric_catalogue.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "coupling_test_util.hpp"

namespace pf = parafsi;
namespace st = pf::structure;

namespace {
constexpr double rho0 = 1.18, p0 = 101325.0, xs = 0.5;
/// The inclined screens' centre, 0.3 of a cell (of the 40-cell duct) past xs: at xs itself the
/// 45° cloth passes through cell centres on the diagonals between its triangles, a degenerate
/// crossing whose face is decided by round-off (16 to 32 faces for 16, and the through-flow
/// with them); off the centres every x-line crosses it once.
constexpr double xs_inclined = xs + 0.3 / 40.0;

/// The duct with the pinned screen (E = 0.3 GPa, ν 0.3, 54 g/m², t = 0.11 mm), air at rest
/// or moving at u0.
template <class Coupling, class Flux = pf::flux::hllc_lm>
auto make_duct(Coupling cpl, const pf::boundary::set& bc, int cells, double u0, Flux flux = {},
               double incline_deg = 0.0, int width_cells = 2, double x_sheet = xs) {
  const auto d = pf::model::duct_screen(1.0, cells, x_sheet, 2, incline_deg, width_cells);
  pf::fluid::solver fl{ctu::duct_grid(d), bc, flux};
  fl.fill_uniform({rho0, {u0, 0, 0}, p0});
  return pf::explicit_stepper{std::move(fl), ctu::pinned_sheet(d), std::move(cpl)};
}

pf::boundary::set duct_bc(double V) {
  pf::boundary::set bc = pf::boundary::set::all(pf::boundary::slip_wall{});
  bc.side(0, 0, pf::boundary::inflow{rho0, {V, 0, 0}, p0});
  bc.side(0, 1, pf::boundary::outflow{true, p0});
  return bc;
}

/// Steady screen (0.06 s): the relative error of Δp against Ergun at the probe velocity.
template <class Coupling, class Flux>
double screen_error(Coupling cpl, const pf::porosity::ergun& law, double V, Flux flux, const char* label,
                    const char* fab, double* dp_out = nullptr) {
  auto s = make_duct(std::move(cpl), duct_bc(V), 40, V, flux);
  while (s.time() < 0.06) s.step(s.stable_dt(0.5));
  double pu, uu, m, pd, ud;
  ctu::window_means(s, xs - 0.2, xs - 0.1, pu, uu, m);
  ctu::window_means(s, xs + 0.1, xs + 0.2, pd, ud, m);
  const double dp = pu - pd, ergun = law.pressure_jump(uu), err = dp / ergun - 1.0;
  std::printf("screen %-8s %-9s %-7s V_in %.4g m/s: through %.5g m/s, dp %7.2f Pa, Ergun %7.2f Pa, error %+.3f %%\n",
              label, fab, Flux::name(), V, uu, dp, ergun, 100 * err);
  CHECK(std::isfinite(dp));
  if (dp_out) *dp_out = dp;
  return err;
}

/// Inflow speeds giving about 20, 120 and 500 Pa across each fabric with the embedded
/// coupling (the inflow face is not rigid: the through-velocity settles below V_in).
constexpr double V_in[3][3] = {{0.06, 0.35, 1.4}, {0.14, 0.7, 2.3}, {0.37, 1.55, 4.4}};

/// What each coupling runs and asserts in the screen and leak-box tests.
template <class C>
struct screen;

template <>
struct screen<ctu::penalty> {
  struct tally {
    double worst = 0, worst_reported = 0;
  };
  /// Inflow speeds giving roughly 20 and 500 Pa across the fabric (asserted: worst < 10 %),
  /// then the embedded test's speeds (reported).
  static void run_fabric(tally& t, std::size_t fi, const pf::porosity::ergun& law, const char* name) {
    for (double dp_target : {20.0, 500.0}) {
      const double V = law.through_velocity(dp_target) * 1.05;
      const double e = screen_error(ctu::penalty::make(law, 1.0), law, V, pf::flux::hllc_lm{}, "penalty", name);
      t.worst = std::max(t.worst, std::fabs(e));
    }
    for (double V : V_in[fi]) {
      const double e = screen_error(ctu::penalty::make(law, 1.0), law, V, pf::flux::hllc_lm{}, "penalty", name);
      t.worst_reported = std::max(t.worst_reported, std::fabs(e));
    }
  }
  static void finish(const tally& t) {
    std::printf(
        "porous screen, penalty (PFAC 1): worst |error| over 3 fabrics x {20, 500} Pa = %.2f %%; at the "
        "embedded inflow speeds %.2f %%\n",
        100 * t.worst, 100 * t.worst_reported);
    CHECK(t.worst < 0.10);
  }

  static constexpr int leak_cells[] = {20, 40};
  /// The penalty wall leaks (collocated-flux numerical porosity) ... by an amount of the
  /// order of mat544's permeability.
  static void check_leak(double leak, double u544, int) {
    CHECK(leak > 0.0);
    CHECK(leak < 1.5 * u544);
  }
};

template <class Leak>
double leak_of(Leak cpl, int cells);

template <bool OS>
struct screen<ctu::embedded_t<OS>> {
  struct tally {
    double worst_lm = 0, worst_hllc = 0, dp_min = 1e300, dp_max = 0;
  };
  static void run_fabric(tally& t, std::size_t fi, const pf::porosity::ergun& law, const char* name) {
    for (double V : V_in[fi]) {
      double dp = 0;
      const double e_lm = screen_error(ctu::embedded_t<OS>::make(law, 0), law, V, pf::flux::hllc_lm{},
                                       ctu::embedded_t<OS>::name, name, &dp);
      const double e_h = screen_error(ctu::embedded_t<OS>::make(law, 0), law, V, pf::flux::hllc{},
                                      ctu::embedded_t<OS>::name, name);
      CHECK(std::fabs(e_lm) < 0.10);
      CHECK(std::fabs(e_h) < 1e-2);
      t.worst_lm = std::max(t.worst_lm, std::fabs(e_lm));
      t.worst_hllc = std::max(t.worst_hllc, std::fabs(e_h));
      t.dp_min = std::min(t.dp_min, dp);
      t.dp_max = std::max(t.dp_max, dp);
    }
  }
  static void finish(const tally& t) {
    std::printf("porous screen over %.1f-%.1f Pa: worst |error| %s/hllc_lm %.2f %%, %s/hllc %.4f %%\n", t.dp_min,
                t.dp_max, ctu::embedded_t<OS>::name, 100 * t.worst_lm, ctu::embedded_t<OS>::name, 100 * t.worst_hllc);
    CHECK(t.dp_min < 22.0);
    CHECK(t.dp_min > 15.0);
    CHECK(t.dp_max > 450.0);
    CHECK(t.dp_max < 550.0);
    CHECK(t.worst_lm < 0.10);
  }

  static constexpr int leak_cells[] = {20, 40, 80};
  /// Below 10 % of mat544's through-flow; in fact none (no mass crosses a resting embedded
  /// wall); less than the penalty wall (PFAC 1) at the same resolution.
  static void check_leak(double leak, double u544, int cells) {
    const double lp = leak_of(ctu::penalty::make(pf::porosity::impermeable{}, 1.0), cells);
    std::printf(
        "leak box %d cells: %s leak %.3e m/s (%.4f %% of mat544's %.4f m/s), penalty (PFAC 1) leak "
        "%.3e m/s (%.1f %%)\n",
        cells, ctu::embedded_t<OS>::name, leak, 100 * std::fabs(leak) / u544, u544, lp, 100 * lp / u544);
    CHECK(std::fabs(leak) < 0.1 * u544);
    CHECK(std::fabs(leak) < 1e-12);
    CHECK(lp > std::fabs(leak));
  }
};

/// Closed box, +25 Pa left and −25 Pa right of the sheet: the mean leak velocity over the
/// first 2 ms (the jump is still ~50 Pa), from the mass gained by the right half.
template <class Leak>
double leak_of(Leak cpl, int cells) {
  auto s = make_duct(std::move(cpl), pf::boundary::set::all(pf::boundary::slip_wall{}), cells, 0.0);
  s.fluid().initialize([&](const Eigen::Vector3d& xi) {
    return pf::fluid::prim<double>{rho0, {0, 0, 0}, xi.x() < xs ? p0 + 25.0 : p0 - 25.0};
  });
  const double A = pf::model::duct_screen(1.0, cells, xs).area();
  double p, u, mr0, mr1, pl, ml;
  ctu::window_means(s, xs, 1.0, p, u, mr0);
  while (s.time() < 2e-3) s.step(s.stable_dt(0.5));
  ctu::window_means(s, xs, 1.0, p, u, mr1);
  ctu::window_means(s, 0.0, xs, pl, u, ml);
  const double leak = (mr1 - mr0) / (rho0 * A * s.time());
  std::printf("  %d cells: pressure jump after %.1f ms %.2f Pa, mean leak %.5f m/s\n", cells, 1e3 * s.time(), pl - p,
              leak);
  return leak;
}
}  // namespace

TEST_CASE_TEMPLATE_DEFINE("porous screen: steady pressure drop vs the Ergun law, three fabrics, 20-500 Pa", C, ergun) {
  pf::parallel::set_threads(1);
  typename screen<C>::tally t;
  for (std::size_t fi = 0; fi < 3; ++fi) {
    const auto& fab = pf::model::fabric_catalogue[fi];
    const pf::porosity::ergun law{fab.alpha, fab.beta, fab.thickness};
    screen<C>::run_fabric(t, fi, law, std::string(fab.name).c_str());
  }
  screen<C>::finish(t);
}
TEST_CASE_TEMPLATE_APPLY(ergun, ctu::couplings);

/// The screen inclined by θ about z in a duct 8 cells wide (0.2 m): the cloth crosses x- and
/// y-faces as a staircase of S = cos θ + sin θ times its area. The air crosses the cloth at
/// the normal velocity u_n = U cos θ (U the mean duct velocity upstream, mass conservation),
/// and the steady pressure drop should be the Ergun law at u_n (not at U). The penalty
/// coupling applies the law to the cloth's normal by construction; so does the embedded
/// coupling by default (law_on = cloth_normal: u_p = c u_n + σ per face); both asserted within
/// 5 %. With the law on each face's velocity (law_on = face_velocity) the staircase of faces
/// an inclined cloth crosses passes too much air (−6.0 % and −7.5 % at 30° and 45°, asserted
/// below 0 and within 10 %; docs/coupling.md §7).
TEST_CASE_TEMPLATE_DEFINE(
    "inclined porous screen: the Ergun law against the cloth's normal velocity at 0, 30 and 45 degrees", C, inclined) {
  pf::parallel::set_threads(1);
  const auto& fab = pf::model::fabric_catalogue[2];  // mat509: the most permeable
  const pf::porosity::ergun law{fab.alpha, fab.beta, fab.thickness};
  for (double deg : {0.0, 30.0, 45.0}) {
    const double th = deg * M_PI / 180.0, reach = 0.1 * std::tan(th);
    const double V = law.through_velocity(100.0) / std::cos(th);  // about 100 Pa across
    auto s = make_duct(C::make(law, 1.0), duct_bc(V), 40, V, pf::flux::hllc{}, deg, 8, xs_inclined);
    while (s.time() < 0.08) s.step(s.stable_dt(0.5));
    double pu, uu, m, pd, ud;
    ctu::window_means(s, xs_inclined - reach - 0.2, xs_inclined - reach - 0.1, pu, uu, m);
    ctu::window_means(s, xs_inclined + reach + 0.1, xs_inclined + reach + 0.2, pd, ud, m);
    const double un = uu * std::cos(th), dp = pu - pd, err = dp / law.pressure_jump(un) - 1.0;
    const double un_cpl = s.coupling().total_through_flow() / s.coupling().coupled_area();
    std::printf(
        "inclined screen %-8s %4.0f deg: U %.4f m/s, u_n %.4f m/s (coupling's own %.4f), dp %.2f Pa, Ergun(u_n) "
        "%.2f Pa, error %+.2f %% (Ergun at U: %.2f Pa)\n",
        C::name, deg, uu, un, un_cpl, dp, law.pressure_jump(un), 100 * err, law.pressure_jump(uu));
    CHECK(std::fabs(err) < 0.05);
    CHECK(std::fabs(un_cpl / un - 1.0) < 0.05);  // relative (Approx would add its scale of 1)
    if constexpr (requires { s.coupling().cloth_sides(Eigen::Vector3d::UnitX()); }) {
      // The cloth seen along the stream: its projection is the duct's cross-section (every
      // x-line of cell centres crosses it once, off the cell centres: xs_inclined), its
      // wall pressures give the load the duct's momentum balance puts on it (the probes' dp on
      // the cross-section: slip walls, the same U on both sides), and the air crossing it is
      // the duct's flow U A: exactly when the cloth is normal to the stream, and within the
      // staircase's count of faces when inclined (the y-faces of a cloth 4.6 and 8 cells long
      // in x come in whole faces: Σ c_f A_f = A Σ_d m_d² up to a face).
      const auto d = pf::model::duct_screen(1.0, 40, xs_inclined, 2, deg, 8);
      const auto cs = s.coupling().cloth_sides(Eigen::Vector3d::UnitX());
      const double dp_wall = cs.windward_pressure - cs.leeward_pressure, Q = uu * d.area();
      const double e_area = cs.projected_area / d.area() - 1.0;
      const double e_load = dp_wall * cs.projected_area / (dp * d.area()) - 1.0, e_q = cs.through_flow / Q - 1.0;
      std::printf(
          "  cloth sides along the stream: projected %.6f m2 (duct %.6f), wall dp %.2f Pa (probes %.2f, Ergun(u_n) "
          "%.2f), load error %+.3f %%, through-flow %.5f m3/s (U A %.5f, %+.2f %%), %ld faces\n",
          cs.projected_area, d.area(), dp_wall, dp, law.pressure_jump(un), 100 * e_load, cs.through_flow, Q, 100 * e_q,
          long(cs.faces));
      CHECK(std::fabs(e_area) < 1e-9);
      CHECK(std::fabs(e_load) < 1e-4);
      if (deg == 0.0) CHECK(std::fabs(e_q) < 1e-6);
      if (deg == 30.0) CHECK((e_q < 0 && e_q > -0.05));  // the staircase's y-faces: 8 for 9.2
      if (deg == 45.0) CHECK((e_q < 0 && e_q > -0.10));  // measured −6.25 %
      // Seen against the stream the sides swap; the flow along the cloth's normal stays.
      const auto back = s.coupling().cloth_sides(-Eigen::Vector3d::UnitX());
      CHECK(back.windward_pressure == cs.leeward_pressure);
      CHECK(back.leeward_pressure == cs.windward_pressure);
      CHECK(back.through_flow == cs.through_flow);
      CHECK(back.projected_area == doctest::Approx(cs.projected_area).epsilon(1e-12));
      CHECK_THROWS_WITH_AS(s.coupling().cloth_sides(Eigen::Vector3d(1, 1, 0)), doctest::Contains("unit vector"),
                           pf::invalid_input);
    }
  }
}
TEST_CASE_TEMPLATE_APPLY(inclined, ctu::couplings);

TEST_CASE("inclined porous screen, the law on each face's velocity: too permeable by the staircase") {
  pf::parallel::set_threads(1);
  const auto& fab = pf::model::fabric_catalogue[2];
  const pf::porosity::ergun law{fab.alpha, fab.beta, fab.thickness};
  pf::coupling::embedded_options eo;
  eo.law_on = pf::coupling::through_flow_law::face_velocity;
  for (double deg : {30.0, 45.0}) {
    const double th = deg * M_PI / 180.0, reach = 0.1 * std::tan(th);
    const double V = law.through_velocity(100.0) / std::cos(th);
    auto s = make_duct(pf::coupling::embedded{law, eo}, duct_bc(V), 40, V, pf::flux::hllc{}, deg, 8);
    while (s.time() < 0.08) s.step(s.stable_dt(0.5));
    double pu, uu, m, pd, ud;
    ctu::window_means(s, xs - reach - 0.2, xs - reach - 0.1, pu, uu, m);
    ctu::window_means(s, xs + reach + 0.1, xs + reach + 0.2, pd, ud, m);
    const double un = uu * std::cos(th), err = (pu - pd) / law.pressure_jump(un) - 1.0;
    std::printf("inclined screen, law on the face velocity, %2.0f deg: error %+.2f %%\n", deg, 100 * err);
    CHECK(err < -0.03);
    CHECK(err > -0.10);
  }
}

TEST_CASE_TEMPLATE_DEFINE("leak box: an impermeable membrane with 50 Pa across", C, leak_box) {
  pf::parallel::set_threads(1);
  const auto& f544 = pf::model::fabric_catalogue[0];
  const pf::porosity::ergun mat544{f544.alpha, f544.beta, f544.thickness};
  const double u544 = mat544.through_velocity(50.0);
  for (int cells : screen<C>::leak_cells) {
    const double leak = leak_of(C::make(pf::porosity::impermeable{}, 1.0), cells);
    std::printf(
        "leak box, %s, %d cells: mean leak over 2 ms = %.5f m/s = %.0f %% of mat544's Ergun through-flow "
        "at 50 Pa (%.3f m/s)\n",
        C::name, cells, leak, 100 * leak / u544, u544);
    screen<C>::check_leak(leak, u544, cells);
  }
}
TEST_CASE_TEMPLATE_APPLY(leak_box, ctu::couplings);

TEST_CASE("embedded screen: near-zero permeability and a nearly transparent screen are stable") {
  pf::parallel::set_threads(1);
  const double V = 1.0;
  // Nearly impermeable: Darcy resistance 1e9 Pa s/m (through-velocity ~ 1e-7 m/s at 100 Pa).
  {
    auto s = make_duct(pf::coupling::embedded{pf::porosity::darcy{1e9 / 1e-4, 1e-4}}, duct_bc(V), 40, V);
    while (s.time() < 0.03) s.step(s.stable_dt(0.5));
    double pu, uu, m, pd, ud;
    ctu::window_means(s, xs - 0.2, xs - 0.1, pu, uu, m);
    ctu::window_means(s, xs + 0.1, xs + 0.2, pd, ud, m);
    const double up = s.coupling().total_through_flow() / s.coupling().coupled_area();
    std::printf("near-impermeable screen: dp %.1f Pa, through-velocity %.3e m/s, law %.3e m/s, upstream u %.3e\n",
                pu - pd, up, (pu - pd) / 1e9, uu);
    CHECK(std::isfinite(pu - pd));
    CHECK(pu - pd > 100.0);  // the stream is stopped: a stagnation/compression wave
    CHECK(std::fabs(up) < 1e-5);
  }
  // Nearly transparent: Darcy resistance 1e-3 Pa s/m (Δp ~ 1e-3 Pa at 1 m/s).
  {
    auto s = make_duct(pf::coupling::embedded{pf::porosity::darcy{1e-3 / 1e-4, 1e-4}}, duct_bc(V), 40, V);
    while (s.time() < 0.03) s.step(s.stable_dt(0.5));
    double pu, uu, m, pd, ud;
    ctu::window_means(s, xs - 0.2, xs - 0.1, pu, uu, m);
    ctu::window_means(s, xs + 0.1, xs + 0.2, pd, ud, m);
    std::printf("nearly transparent screen: dp %.3e Pa, upstream %.6f m/s, downstream %.6f m/s\n", pu - pd, uu, ud);
    CHECK(std::fabs(pu - pd) < 0.05);
    CHECK(uu == doctest::Approx(V).epsilon(1e-3));
    CHECK(ud == doctest::Approx(V).epsilon(1e-3));
  }
}
