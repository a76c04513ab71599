// Piston (methods §4.9.1), the pressure rise typed over the coupling list, and stiff /
// extreme penalty cases; the plate is the sheet of model/duct_screen.hpp (2 m duct, plate
// at 0.5 m, nodes driven at v):
// - penalty: a rigid plate driven at v into still air: the compressed air obeys the
//   acoustic relation Δp = ρ c u_air within 2 %; against the plate speed, Δp = ρ c v is
//   missed by the numerical leak of the zero-thickness penalty wall (reported, asserted
//   < 10 % at PFAC ≥ 1);
// - embedded (the plate a moving wall in the face fluxes): Δp within 2 % of ρ c v and
//   within 0.5 % of the exact piston shock, at 50 to 200 cells and 2 to 20 m/s, with the
//   air moving at the plate speed (no leak);
// - PFAC far above the fluid-side cap (capped automatically) and ten times below the
//   cap run stably; a free fabric-weight plate stays stable;
// - a membrane moving more than a cell per fluid step is rejected with a message.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "coupling_test_util.hpp"

namespace pf = parafsi;
namespace st = pf::structure;

namespace {
constexpr double rho0 = 1.18, p0 = 101325.0;

/// The exact piston-driven shock: Δp = ρ c v [(γ+1)M/4 + √(1 + ((γ+1)M/4)²)], M = v/c.
double exact_piston_rise(double v) {
  const double c = std::sqrt(1.4 * p0 / rho0), q = 2.4 * v / c / 4.0;
  return rho0 * c * v * (q + std::sqrt(1.0 + q * q));
}

template <class MakeCoupling>
auto make_piston_with(double v, int cells, MakeCoupling make_coupling, double areal_density = 1.0,
                      bool free_plate = false) {
  const auto d = pf::model::duct_screen(2.0, cells, 0.5);
  pf::boundary::set bc = pf::boundary::set::all(pf::boundary::slip_wall{});
  bc.axis(0, pf::boundary::far_field{});
  pf::fluid::solver fl{ctu::duct_grid(d), bc};
  fl.fill_uniform({rho0, {0, 0, 0}, p0});
  st::nodes nd;
  for (const auto& x : d.sheet.positions) nd.add(x, {v, 0, 0});
  if (!free_plate)
    for (pf::index_t i = 0; i < nd.size(); ++i) nd.prescribe_velocity(i, {v, 0, 0});
  st::membrane_tri mem{ctu::sheet_mesh(d), st::material::fabric<>::isotropic(1e6, 0.3, areal_density, 1e-3)};
  st::assembly as{std::move(nd), std::move(mem)};
  as.integrator().gravity = {0, 0, 0};
  return pf::explicit_stepper{std::move(fl), std::move(as), make_coupling()};
}

auto make_piston(double v, double pfac, int cells, double fluid_cap = 1.0, double areal_density = 1.0,
                 bool free_plate = false) {
  return make_piston_with(
      v, cells,
      [&] {
    pf::coupling::penalty_options po;
    po.pfac = pfac;
    po.fluid_cap = fluid_cap;
    return pf::coupling::penalty{pf::porosity::impermeable{}, po};
      },
      areal_density, free_plate);
}

struct piston_result {
  double rise, u_air, max_pen, min_scale;
  long max_m;
};

template <class S>
piston_result run_piston(S& s, double v, double t_end, double x0 = 0.5) {
  piston_result r{0, 0, 0, 1, 0};
  while (s.time() < t_end - 1e-15) {
    s.step(std::min(s.stable_dt(0.5), t_end - s.time()));
    r.max_pen = std::max(r.max_pen, s.coupling().diagnostics().max_penetration_over_h);
    if constexpr (requires { s.coupling().diagnostics().min_stiffness_scale; })
      r.min_scale = std::min(r.min_scale, s.coupling().diagnostics().min_stiffness_scale);
    r.max_m = std::max(r.max_m, s.last_substeps());
  }
  const double c = std::sqrt(1.4 * p0 / rho0);
  const double xp = x0 + v * t_end, xf = x0 + c * t_end;
  const auto& g = s.fluid().grid();
  int n = 0;
  for (pf::index_t i = 0; i < g.n(0); ++i) {
    const double x = g.centre(0, i);
    if (x > xp + 0.2 * (xf - xp) && x < xp + 0.8 * (xf - xp)) {
      const auto w = s.fluid().primitive(i, 0, 0);
      REQUIRE(std::isfinite(w.p));
      r.rise += w.p - p0;
      r.u_air += w.u.x;
      ++n;
    }
  }
  REQUIRE(n > 0);
  r.rise /= n;
  r.u_air /= n;
  return r;
}
/// The pressure-rise runs per coupling and what each asserts.
template <class C>
struct piston;

template <>
struct piston<ctu::penalty> {
  struct run {
    double v, pfac;
    int cells;
  };
  static inline const std::vector<run> runs{{2.0, 0.1, 100}, {2.0, 1.0, 100}, {2.0, 10.0, 100}};
  static void check(const run& c, const piston_result& r) {
    const double cs = std::sqrt(1.4 * p0 / rho0);
    const double e_air = r.rise / (rho0 * cs * r.u_air) - 1.0, e_v = r.rise / (rho0 * cs * c.v) - 1.0;
    std::printf(
        "piston PFAC %-4g: dp = %.2f Pa, rho c v = %.2f Pa (error %+.2f %%), u_air = %.4f m/s "
        "(leak %.4f m/s), dp / (rho c u_air) - 1 = %+.2f %%, max |d|/h = %.4f\n",
        c.pfac, r.rise, rho0 * cs * c.v, 100 * e_v, r.u_air, c.v - r.u_air, 100 * e_air, r.max_pen);
    CHECK(std::fabs(e_air) < 0.02);  // acoustic relation in the compressed air
    // The penalty leak through the zero-thickness plate (docs/coupling.md): with the
    // default HLLC-LM (acoustic floor, K = 2) −6.7 % at PFAC 1 and −9.2 % at PFAC 10.
    if (c.pfac >= 1.0) CHECK(std::fabs(e_v) < 0.10);
  }
};

template <bool OS>
struct piston<ctu::embedded_t<OS>> {
  struct run {
    double v, pfac;
    int cells;
  };
  static inline const std::vector<run> runs{{2.0, 0, 50}, {2.0, 0, 100}, {2.0, 0, 200}, {20.0, 0, 100}};
  /// Within 2 % of ρcv (0.5 % of the exact piston shock), the air moving with the plate (no leak).
  static void check(const run& c, const piston_result& r) {
    const double cs = std::sqrt(1.4 * p0 / rho0);
    const double e_v = r.rise / (rho0 * cs * c.v) - 1.0, e_exact = r.rise / exact_piston_rise(c.v) - 1.0;
    std::printf(
        "%s piston v %-4g cells %-3d: dp = %.2f Pa, rho c v = %.2f Pa (%+.3f %%), exact shock %.2f Pa "
        "(%+.3f %%), u_air = %.5f m/s\n",
        ctu::embedded_t<OS>::name, c.v, c.cells, r.rise, rho0 * cs * c.v, 100 * e_v, exact_piston_rise(c.v),
        100 * e_exact, r.u_air);
    CHECK(std::fabs(e_exact) < 0.005);
    if (c.v <= 2.0) CHECK(std::fabs(e_v) < 0.02);  // the bound (the shock adds 0.35 % at 2 m/s)
    // The air moves with the plate: no leak (window mean between plate and shock; measured
    // +0.008 % first order and +0.12 % one-sided at 50 cells, both < 0.03 % at 200; the
    // penalty plate's leak is several per cent).
    CHECK(std::fabs(r.u_air - c.v) < 3e-3 * c.v);
  }
};
}  // namespace

TEST_CASE_TEMPLATE_DEFINE("piston: pressure rise against rho c v", C, rise) {
  pf::parallel::set_threads(1);  // tiny grids: threads only add overhead
  for (const auto& c : piston<C>::runs) {
    auto s = make_piston_with(c.v, c.cells, [&] { return C::make(pf::porosity::impermeable{}, c.pfac); });
    piston<C>::check(c, run_piston(s, c.v, 3e-3));
  }
}
TEST_CASE_TEMPLATE_APPLY(rise, ctu::couplings);

TEST_CASE("stiff cases: PFAC far above the fluid-side cap, and ten times below it") {
  const double v = 2.0;
  // Far above the cap: capped automatically (scale < 1), stable.
  auto hi = make_piston(v, 1e4, 100);
  const auto rh = run_piston(hi, v, 2e-3);
  std::printf("PFAC 1e4 (capped): min stiffness scale %.3e, dp = %.2f Pa, max |d|/h = %.2e\n", rh.min_scale, rh.rise,
              rh.max_pen);
  CHECK(rh.min_scale < 1.0);
  CHECK(std::isfinite(rh.rise));
  CHECK(rh.rise > 0.8 * rho0 * 343.0 * v);
  // The cap itself: the PFAC at which the scale reaches 1 is 1e4 * min_scale; run at a tenth.
  const double pfac_cap = 1e4 * rh.min_scale;
  auto lo = make_piston(v, 0.1 * pfac_cap, 100);
  const auto rl = run_piston(lo, v, 2e-3);
  std::printf("PFAC cap %.3g, run at %.3g: min scale %.3f, dp = %.2f Pa, max |d|/h = %.2e\n", pfac_cap, 0.1 * pfac_cap,
              rl.min_scale, rl.rise, rl.max_pen);
  CHECK(rl.min_scale == 1.0);
  CHECK(rl.rise > 0.8 * rho0 * 343.0 * v);
  // Without the cap, far above it: the coupling rings but the check is that the cap is what keeps it sane.
}

TEST_CASE("stiff cases: a free fabric-weight plate (0.05 kg/m^2) with PFAC 10 stays stable and is braked by the air") {
  const double v = 2.0;
  auto s = make_piston(v, 10.0, 100, 1.0, 0.05, /*free_plate=*/true);
  const auto r = run_piston(s, v, 1e-3);
  std::printf("free light plate: max substeps %ld, plate velocity %.4f m/s, max |d|/h = %.3e\n", r.max_m,
              s.structure().node_set().velocity(0).x(), r.max_pen);
  CHECK(std::isfinite(s.structure().node_set().velocity(0).x()));
  CHECK(std::fabs(s.structure().node_set().velocity(0).x()) < v);  // the air brakes it
}

TEST_CASE("extreme: a membrane moving faster than a cell per step is rejected with a message") {
  auto s = make_piston(4000.0, 1.0, 100);
  const double dt = s.fluid().stable_dt(0.5);  // 0.02 m cell, 4000 m/s: 1.9 cells per step
  try {
    s.step(dt);
    FAIL("no error");
  } catch (const pf::numerical_failure& e) {
    const std::string what = e.what();
    MESSAGE(what);
    CHECK(what.find("cells of size") != std::string::npos);
    CHECK(what.find("reduce the time step") != std::string::npos);
  }
  // stable_dt() includes the travel limit.
  auto s2 = make_piston(4000.0, 1.0, 100);
  CHECK(s2.stable_dt(0.5) < dt);
  CHECK_NOTHROW(s2.step(s2.stable_dt(0.5)));
}
