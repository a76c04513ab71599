// Composition, leave-out and robustness of the fluid solver: policies in any order
// with defaults; inviscid + turbulence::none carries no gradient/eddy-viscosity storage
// and no viscous pass; bad input is rejected with a message; a blow-up stops with the
// cell and time; results are identical for any thread count.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <type_traits>

#include "fluid_test_util.hpp"

using namespace parafsi;
using pft::prim;

namespace {
using inviscid_solver =
    fluid::solver<flux::hllc_lm, recon::muscl<limiter::van_leer>, turbulence::none, viscosity::inviscid, frame::fixed>;
using les_solver = fluid::solver<flux::hllc_lm, recon::muscl<limiter::van_leer>, turbulence::smagorinsky,
                                 viscosity::constant, frame::fixed>;
using ml_solver = fluid::solver<flux::hllc_lm, recon::muscl<limiter::van_leer>, turbulence::prandtl_mixing_length,
                                viscosity::sutherland, frame::follow_payload>;

// Leave-out, checked at compile time.
static_assert(!inviscid_solver::is_viscous && !inviscid_solver::has_eddy_viscosity);
static_assert(std::is_same_v<inviscid_solver::viscous_storage, fluid::empty_storage>);
static_assert(std::is_same_v<inviscid_solver::turbulence_storage, fluid::empty_storage>);
// "Off" policies hold at most one constant (a Prandtl number read by the stable-step
// estimate), never a field.
static_assert(sizeof(turbulence::none) <= sizeof(double) && sizeof(viscosity::inviscid) <= sizeof(double));
static_assert(les_solver::is_viscous && les_solver::has_eddy_viscosity && !les_solver::needs_wall_distance);
static_assert(ml_solver::needs_wall_distance);
static_assert(sizeof(inviscid_solver) < sizeof(les_solver));
static_assert(!std::is_same_v<les_solver::viscous_storage, fluid::empty_storage>);
// Composition in any order deduces the same type.
using deduced = decltype(fluid::solver{std::declval<fluid::rectilinear_grid>(), std::declval<boundary::set>(),
                                       std::declval<viscosity::constant>(), std::declval<turbulence::smagorinsky>()});
static_assert(std::is_same_v<deduced, les_solver>);
template <class... P>
concept constructible = requires(P... p) {
  fluid::solver{fluid::rectilinear_grid{}, boundary::set{}, p...};
};
static_assert(constructible<flux::hllc, recon::first_order, time::ssp_rk3>);
}  // namespace

TEST_CASE("policies compose in any order and the name lists them") {
  auto grid = fluid::rectilinear_grid::uniform({4, 4, 4}, {0, 0, 0}, {1, 1, 1});
  fluid::solver a{grid, boundary::set::all(boundary::periodic{}), recon::muscl<limiter::mc>{}, flux::rusanov{},
                  time::ssp_rk3{}};
  const std::string n = a.name();
  CHECK(n.find("rusanov") != std::string::npos);
  CHECK(n.find("mc") != std::string::npos);
  CHECK(n.find("ssp_rk3") != std::string::npos);
  CHECK(n.find("inviscid") != std::string::npos);
}

TEST_CASE("bad input is rejected with a message naming the value") {
  auto grid = fluid::rectilinear_grid::uniform({4, 4, 4}, {0, 0, 0}, {1, 1, 1});
  auto expect = [](auto&& f, const std::string& needle) {
    try {
      f();
      FAIL("no exception");
    } catch (const invalid_input& e) {
      CAPTURE(e.what());
      CHECK(std::string(e.what()).find(needle) != std::string::npos);
    }
  };
  expect(
      [&] {
    fluid::solver s{grid, boundary::set::all(boundary::periodic{}).side(0, 1, boundary::slip_wall{})};
      },
      "periodic");
  expect(
      [&] {
    fluid::rectilinear_grid g(fluid::axis{{0.0, 0.5, 0.4, 1.0}}, fluid::axis::uniform(2, 0, 1),
                              fluid::axis::uniform(2, 0, 1));
      },
      "not increasing");
  expect([&] { fluid::axis::uniform(0, 0, 1); }, "at least one cell");
  fluid::solver s{grid, boundary::set::all(boundary::periodic{})};
  expect([&] { s.initialize([](const Eigen::Vector3d&) { return prim{-1.0, {0, 0, 0}, 1.0}; }); }, "density");
  expect([&] { s.initialize([](const Eigen::Vector3d&) { return prim{1.0, {0, 0, 0}, 0.0}; }); }, "pressure");
  expect([&] { s.step(-1.0); }, "dt");
  expect([&] { (void)s.stable_dt(2.0); }, "CFL");
  expect([&] { fluid::solver t{grid, boundary::set::all(boundary::periodic{}), gas::ideal{0.9, 287.0}}; }, "gamma");
  expect([&] { fluid::solver t{grid, boundary::set::all(boundary::periodic{}), viscosity::constant{-1.0}}; }, "mu");
  // Prescribed boundary states must be a gas, named by face; the sponge must damp.
  expect(
      [&] {
    fluid::solver t{grid, boundary::set{}.side(2, 1, boundary::far_field{std::nan(""), {0, 0, 0}, 1e5})};
      },
      "far_field on face z+: density");
  expect(
      [&] {
    fluid::solver t{grid, boundary::set{}.side(0, 0, boundary::far_field{1.2, {0, 0, 0}, 0.0})};
      },
      "far_field on face x-: pressure");
  expect(
      [&] {
    fluid::solver t{grid, boundary::set{}.side(1, 0, boundary::inflow{1.2, {0, HUGE_VAL, 0}, 1e5})};
      },
      "inflow on face y-: velocity component 1");
  expect(
      [&] {
    boundary::set b;
    b.layer = {4, -0.5};
    fluid::solver t{grid, b};
      },
      "sponge: strength");
}

TEST_CASE("a blow-up stops with the cell, position and time") {
  auto bc = boundary::set::all(boundary::slip_wall{});
  bc.axis(0, boundary::outflow{});
  fluid::solver s{fluid::rectilinear_grid::uniform({100, 2, 2}, {0, 0, 0}, {1, 0.02, 0.02}), bc, flux::hllc{}};
  s.initialize([](const Eigen::Vector3d& x) {
    return x[0] < 0.5 ? prim{1, {0, 0, 0}, 1000} : prim{1, {0, 0, 0}, 0.01};
  });
  const double dt = 20 * s.stable_dt(0.5);  // far above the CFL limit
  bool thrown = false;
  try {
    for (int n = 0; n < 50; ++n) s.step(dt);
  } catch (const numerical_failure& e) {
    thrown = true;
    const std::string w = e.what();
    CAPTURE(w);
    CHECK(w.find("cell (") != std::string::npos);
    CHECK(w.find("t = ") != std::string::npos);
    CHECK(e.index >= 0);
    CHECK(e.t > 0.0);
  }
  CHECK(thrown);
}

TEST_CASE("conservation to round-off in a periodic box, and identical results for 1 and 2 threads") {
  const int t0 = parallel::max_threads();
  auto run = [](int threads) {
    parallel::set_threads(threads);
    fluid::solver s{fluid::rectilinear_grid::uniform({24, 20, 16}, {0, 0, 0}, {1, 1, 1}),
                    boundary::set::all(boundary::periodic{}), flux::hllc_lm{}, viscosity::constant{1e-3, 0.72},
                    turbulence::smagorinsky{}};
    s.set_threading(true);  // small grid: force the threaded phases
    s.initialize([](const Eigen::Vector3d& x) {
      const double k = 2 * std::numbers::pi;
      return prim{1.0 + 0.1 * std::sin(k * x[0]),
                  {0.3 * std::sin(k * x[1]), 0.2 * std::cos(k * x[2]), 0.1},
                  1.0 + 0.1 * std::cos(k * x[0] + k * x[1])};
    });
    const auto t0 = s.totals();
    for (int n = 0; n < 20; ++n) s.step(s.stable_dt(0.5));
    return std::make_pair(t0, s);
  };
  auto [a0, a] = run(1);
  auto [b0, b] = run(2);
  parallel::set_threads(t0);
  const auto ta = a.totals();
  CHECK(std::fabs(ta.mass - a0.mass) < 1e-13 * a0.mass);
  CHECK(std::fabs(ta.energy - a0.energy) < 1e-13 * a0.energy);
  for (int d = 0; d < 3; ++d) CHECK(std::fabs(ta.momentum[std::size_t(d)] - a0.momentum[std::size_t(d)]) < 1e-13);
  bool identical = true;
  for (index_t k = 0; k < 16; ++k)
    for (index_t j = 0; j < 20; ++j)
      for (index_t i = 0; i < 24; ++i) {
        const auto qa = a.conserved(i, j, k), qb = b.conserved(i, j, k);
        identical = identical && qa.rho == qb.rho && qa.m.x == qb.m.x && qa.m.y == qb.m.y && qa.m.z == qb.m.z &&
                    qa.E == qb.E;
      }
  CHECK(identical);
}

TEST_CASE("mixing-length closure: eddy viscosity from the wall distance and the shear") {
  const turbulence::prandtl_mixing_length ml{0.41, 0.07, 1.0, 1.0};
  // l_m = min(κ d, C_l L, C_Δ Δ): with d = 0.01, Δ = 0.5: l_m = 0.0041; μ_t = ρ l_m² |S|.
  CHECK(ml.eddy_viscosity(1.2, 100.0, 0.5, 0.01) == doctest::Approx(1.2 * 0.0041 * 0.0041 * 100.0).epsilon(1e-12));
  // Far from walls the free-shear length C_l L = 0.07 applies.
  CHECK(ml.eddy_viscosity(1.2, 1.0, 0.5, 1e30) == doctest::Approx(1.2 * 0.07 * 0.07 * 1.0).epsilon(1e-12));
  // Very strong shear is capped at mu_cap (1000 × air's viscosity by default).
  CHECK(ml.eddy_viscosity(1.2, 1e4, 0.5, 1e30) == doctest::Approx(ml.mu_cap).epsilon(1e-15));
  const turbulence::smagorinsky sm{0.1};
  CHECK(sm.eddy_viscosity(1.0, 10.0, 0.2, 0.0) == doctest::Approx(0.02 * 0.02 * 10.0).epsilon(1e-12));
}
