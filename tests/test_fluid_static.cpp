// Composition, leave-out and robustness of the fluid solver: policies in any order
// with defaults; inviscid + turbulence::none carries no gradient/eddy-viscosity storage
// and no viscous pass; bad input is rejected with a message; a blow-up stops with the
// cell and time; results are identical for any thread count; the viscous pass on SIMD lanes
// gives the scalar pass's rates (laminar, Smagorinsky, mixing length; stretched grid, rotated box).
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <type_traits>

#include <parafsi/fluid/detail/viscous.hpp>

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

namespace {
/// The solver's turbulence storage for a closure (none: empty).
template <class Turb, bool = Turb::active>
struct turbulence_storage_of {
  using type = fluid::empty_storage;
};
template <class Turb>
struct turbulence_storage_of<Turb, true> {
  using type = std::conditional_t<Turb::needs_wall_distance, soa<fluid::field::mu_t, fluid::field::wall_distance>,
                                  soa<fluid::field::mu_t>>;
};

/// True when the compiler contracts a b − c into a fused multiply-subtract here:
/// (1 + 2⁻³⁰)² − (1 + 2⁻²⁹) is 2⁻⁶⁰ fused, 0 rounded.
bool contracts() {
  volatile double v = 1.0 + 0x1p-30;
  const double a = v;
  return a * a - (1.0 + 0x1p-29) != 0.0;
}

/// One stage's viscous pass on SIMD lanes and on scalars (Lanes = 1) from the same random state on a
/// stretched grid (x: n_x = 19, not a whole number of packs; every axis refined with growth 1.15) with
/// the box rotated: the largest difference of the rates over the interior, relative to each
/// component's largest magnitude, and of μ_t; `differing` counts the values not equal bit for bit.
template <class Visc, class Turb>
std::pair<double, double> vector_against_scalar(const Visc& visc, const Turb& turb, long& differing) {
  using pf_turb = typename turbulence_storage_of<Turb>::type;
  using visc_storage = soa_of_t<fluid::viscous_fields>;
  constexpr bool wall = fluid::detail::viscous_pass<Visc, Turb, visc_storage, pf_turb>::needs_wall_distance;
  const fluid::rectilinear_grid grid{fluid::axis::refined(-1.0, 1.2, -0.3, 0.2, 0.05, 1.15),
                                     fluid::axis::refined(-0.6, 0.7, -0.1, 0.2, 0.06, 1.15),
                                     fluid::axis::refined(-0.5, 0.5, -0.2, 0.1, 0.07, 1.15)};
  REQUIRE(grid.n(0) % index_t(simd::width) != 0);
  const index_t N = grid.total_cells();
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  soa_of_t<fluid::primitive_fields> W(N);
  double* w[5] = {W.get<fluid::field::rho>(), W.get<fluid::field::u>(), W.get<fluid::field::v>(),
                  W.get<fluid::field::w>(), W.get<fluid::field::p>()};
  for (index_t c = 0; c < N; ++c) {
    w[0][c] = 1.2 + 0.3 * uni(rng);
    for (int a = 1; a < 4; ++a) w[a][c] = 5.0 * uni(rng);
    w[4][c] = 1e5 * (1.0 + 0.2 * uni(rng));
  }
  fluid::detail::stage_geometry geo;
  geo.R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
  const gas::ideal air{};
  struct run {
    visc_storage vs;
    pf_turb ts;
    soa_of_t<fluid::conserved_fields> dU;
    std::vector<int> axes;  // the hook's calls
  };
  run r[2];
  for (auto& x : r) {
    x.vs.resize(N, 0.0);
    x.dU.resize(N, 0.0);
    if constexpr (Turb::active) x.ts.resize(N, 0.0);
    std::mt19937_64 rd(777);
    for (int f = 0; f < 5; ++f) {
      double* d = fluid::detail::conserved_ptrs(x.dU)[std::size_t(f)];
      for (index_t c = 0; c < N; ++c) d[c] = 10.0 * uni(rd);
    }
    if constexpr (wall) {
      double* d = x.ts.template get<fluid::field::wall_distance>();
      for (index_t c = 0; c < N; ++c) d[c] = 0.02 * (1.5 + uni(rd));
    }
  }
  const auto Wc = fluid::detail::primitive_ptrs(std::as_const(W));
  auto pass = [&]<std::size_t L>(run& x) {
    fluid::detail::viscous_pass<Visc, Turb, visc_storage, pf_turb, L>{visc, turb, air, grid, x.vs, x.ts, false}(
        geo, Wc, fluid::detail::conserved_ptrs(x.dU), [&](int d, double* const*) { x.axes.push_back(d); });
  };
  pass.template operator()<simd::width>(r[0]);
  pass.template operator()<1>(r[1]);
  CHECK(r[0].axes == std::vector<int>{0, 1, 2});
  CHECK(r[1].axes == std::vector<int>{0, 1, 2});
  double worst = 0.0, worst_mut = 0.0;
  differing = 0;
  for (int f = 1; f < 5; ++f) {
    const double* a = fluid::detail::conserved_ptrs(r[0].dU)[std::size_t(f)];
    const double* b = fluid::detail::conserved_ptrs(r[1].dU)[std::size_t(f)];
    double scale = 0.0, diff = 0.0;
    for (index_t k = 0; k < grid.n(2); ++k)
      for (index_t j = 0; j < grid.n(1); ++j)
        for (index_t i = 0; i < grid.n(0); ++i) {
          const index_t c = grid.index(i, j, k);
          scale = std::max(scale, std::fabs(b[c]));
          diff = std::max(diff, std::fabs(a[c] - b[c]));
          differing += a[c] != b[c];
        }
    worst = std::max(worst, diff / scale);
  }
  if constexpr (Turb::active) {
    const double* a = r[0].ts.template get<fluid::field::mu_t>();
    const double* b = r[1].ts.template get<fluid::field::mu_t>();
    for (index_t k = -1; k <= grid.n(2); ++k)
      for (index_t j = -1; j <= grid.n(1); ++j)
        for (index_t i = -1; i <= grid.n(0); ++i) {
          const index_t c = grid.index(i, j, k);
          worst_mut = std::max(worst_mut, std::fabs(a[c] - b[c]) / std::fabs(b[c]));
          differing += a[c] != b[c];
        }
  }
  return {worst, worst_mut};
}
}  // namespace

TEST_CASE("viscous pass: SIMD lanes give the scalar pass's rates (laminar, Smagorinsky, mixing length)") {
  const bool fused = contracts();
  // The rotation reproduces Eigen's 3×3 product bit for bit on scalars, and on packs unless the
  // compiler contracts row 2's sum into fused multiply-adds otherwise than for scalars.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  long scalar_diff = 0, pack_diff = 0;
  double pack_rel = 0.0;
  for (int n = 0; n < 1000; ++n) {
    Eigen::Matrix3d M;
    for (int q = 0; q < 9; ++q) M.data()[q] = uni(rng);
    alignas(64) double xs[3][simd::width];
    for (auto& row : xs)
      for (double& v : row) v = uni(rng);
    simd::pack<double> xp[3] = {simd::load_aligned<simd::pack<double>>(xs[0]),
                                simd::load_aligned<simd::pack<double>>(xs[1]),
                                simd::load_aligned<simd::pack<double>>(xs[2])},
                       yp[3];
    fluid::detail::rotate(M, xp, yp);
    alignas(64) double ys[3][simd::width];
    for (int a = 0; a < 3; ++a) yp[a].store_aligned(ys[a]);
    for (std::size_t l = 0; l < simd::width; ++l) {
      const double x1[3] = {xs[0][l], xs[1][l], xs[2][l]};
      double y1[3];
      fluid::detail::rotate(M, x1, y1);
      const Eigen::Vector3d ye = M * Eigen::Vector3d(x1[0], x1[1], x1[2]);
      for (int a = 0; a < 3; ++a) {
        scalar_diff += y1[a] != ye[a];
        pack_diff += ys[a][l] != ye[a];
        const double size = std::fabs(M(a, 0) * x1[0]) + std::fabs(M(a, 1) * x1[1]) + std::fabs(M(a, 2) * x1[2]);
        pack_rel = std::max(pack_rel, std::fabs(ys[a][l] - ye[a]) / size);
      }
    }
  }
  MESSAGE("rotate against Eigen (", std::string(fused ? "contracting" : "not contracting"), " a*b+c): scalars ",
          scalar_diff, " values differ, packs ", pack_diff, " (max difference / sum of |terms| ", pack_rel, ")");
  CHECK(scalar_diff == 0);
  if (fused) CHECK(pack_rel <= 0x1p-51);  // two roundings of the sum's terms
  else CHECK(pack_diff == 0);

  viscosity::constant air_mu{};
  air_mu.mu_value = 0.05;
  long laminar = 0, smag = 0, ml = 0;
  const auto [lam_dU, lam_mut] = vector_against_scalar(air_mu, turbulence::none{}, laminar);
  turbulence::smagorinsky sm{};
  sm.mu_cap = 0.02;  // capped in part of the cells
  const auto [sm_dU, sm_mut] = vector_against_scalar(viscosity::sutherland{}, sm, smag);
  turbulence::prandtl_mixing_length pml{};
  pml.mu_cap = 0.02;
  const auto [ml_dU, ml_mut] = vector_against_scalar(air_mu, pml, ml);
  MESSAGE("SIMD (", simd::width,
          " lanes) against scalar, max relative difference of dU / mu_t (values not bit-equal):"
          " laminar ",
          lam_dU, " (", laminar, "), Smagorinsky + Sutherland ", sm_dU, " / ", sm_mut, " (", smag, "), mixing length ",
          ml_dU, " / ", ml_mut, " (", ml, ")");
  // Every value has the scalar pass's operations in the same order: bit for bit unless the
  // compiler contracts a b + c into fused multiply-adds (-ffp-contract=fast with FMA hardware),
  // which it does at some sites of the pack instantiation otherwise than for scalars (round-off).
  if (!fused) {
    CHECK(laminar == 0);
    CHECK(smag == 0);
    CHECK(ml == 0);
  }
  CHECK(lam_dU <= 1e-13);
  CHECK(sm_dU <= 1e-13);
  CHECK(ml_dU <= 1e-13);
  CHECK(sm_mut <= 1e-13);
  CHECK(ml_mut <= 1e-13);
}
