// Toro's Riemann problems on the 3-D solver along each axis, against the exact
// solution: L1 errors of density, velocity and pressure per flux (MUSCL + van Leer,
// 200 cells), bounded per flux and problem; no negative density or pressure.
#include <doctest/doctest.h>

#include <cstdio>
#include <map>
#include <string>

#include "fluid_test_util.hpp"

using namespace parafsi;

namespace {
struct errors {
  double rho = 0, u = 0, p = 0, min_rho = 1e300, min_p = 1e300;
};

template <class Flux, class Recon = recon::muscl<limiter::van_leer>>
errors run_case(const pft::riemann_case& rc, int axis, int n) {
  std::array<index_t, 3> cells{2, 2, 2};
  std::array<double, 3> lo{0, 0, 0}, hi{0.02, 0.02, 0.02};
  cells[std::size_t(axis)] = n;
  hi[std::size_t(axis)] = 1.0;
  // Transmissive ends along the axis (Toro's set-up), slip walls across it.
  auto bc = boundary::set::all(boundary::slip_wall{});
  bc.axis(axis, boundary::outflow{});
  fluid::solver s{fluid::rectilinear_grid::uniform(cells, lo, hi), bc, Flux{}, Recon{}};
  s.initialize([&](const Eigen::Vector3d& x) {
    const auto& st = x[axis] < rc.x0 ? rc.L : rc.R;
    fluid::prim<double> w{st.rho, {0, 0, 0}, st.p};
    (axis == 0 ? w.u.x : axis == 1 ? w.u.y : w.u.z) = st.u;
    return w;
  });
  pft::run_to(s, rc.t_end, 0.5);
  fluid::exact_riemann ex(rc.L, rc.R);
  errors e;
  for (int c = 0; c < n; ++c) {
    index_t ijk[3] = {0, 1, 1};
    ijk[axis] = c;
    const auto w = s.primitive(ijk[0], ijk[1], ijk[2]);
    const double x = s.grid().centre(axis, c), h = s.grid().width(axis, c);
    const auto ref = ex.sample((x - rc.x0) / rc.t_end);
    const double u = axis == 0 ? w.u.x : axis == 1 ? w.u.y : w.u.z;
    e.rho += std::fabs(w.rho - ref.rho) * h;
    e.u += std::fabs(u - ref.u) * h;
    e.p += std::fabs(w.p - ref.p) * h;
    e.min_rho = std::min(e.min_rho, w.rho);
    e.min_p = std::min(e.min_p, w.p);
  }
  return e;
}

// L1 bounds (density, velocity, pressure) at 200 cells: 1.3 × the errors measured
// with g++ 12 -O3 (Sod's density L1 of 0.0027 is in line with Toro's MUSCL results), so a regression in any flux or in
// the reconstruction fails.
struct bound {
  double rho, u, p;
};
const std::map<std::string, bound> bounds = {
    {"hllc_lm/sod", {0.00351, 0.00666, 0.00233}},      {"hllc_lm/lax", {0.016, 0.0137, 0.0147}},
    {"hllc_lm/toro2", {0.00573, 0.0191, 0.00281}},     {"hllc_lm/toro3", {0.114, 0.308, 5.87}},
    {"hllc/sod", {0.00372, 0.00701, 0.00257}},         {"hllc/lax", {0.016, 0.0137, 0.0147}},
    {"hllc/toro2", {0.00573, 0.0191, 0.00281}},        {"hllc/toro3", {0.114, 0.304, 5.82}},
    {"rusanov/sod", {0.00478, 0.00829, 0.00335}},      {"rusanov/lax", {0.0191, 0.0159, 0.0175}},
    {"rusanov/toro2", {0.00567, 0.0164, 0.00283}},     {"rusanov/toro3", {0.126, 0.347, 6.86}},
    {"ausm_plus_up/sod", {0.00411, 0.00819, 0.00311}}, {"ausm_plus_up/lax", {0.0159, 0.0148, 0.0152}},
    {"ausm_plus_up/toro2", {0.00783, 0.0191, 0.0032}}, {"ausm_plus_up/toro3", {0.114, 0.317, 6.15}},
};
}  // namespace

TEST_CASE_TEMPLATE("Riemann problems match the exact solution along every axis", Flux, flux::hllc_lm, flux::hllc,
                   flux::rusanov, flux::ausm_plus_up) {
  for (const auto& rc : pft::toro_cases) {
    const std::string key = std::string(Flux::name()) + "/" + rc.name;
    const bound b = bounds.at(key);
    for (int axis = 0; axis < 3; ++axis) {
      CAPTURE(key);
      CAPTURE(axis);
      const errors e = run_case<Flux>(rc, axis, 200);
      if (axis == 0)
        std::printf("riemann %-20s L1 rho %.5f  u %.5f  p %.5f  (min rho %.3g, min p %.3g)\n", key.c_str(), e.rho, e.u,
                    e.p, e.min_rho, e.min_p);
      CHECK(e.rho < b.rho);
      CHECK(e.u < b.u);
      CHECK(e.p < b.p);
      CHECK(e.min_rho > 0.0);
      CHECK(e.min_p > 0.0);
    }
  }
}

TEST_CASE("Sod: the three axes give the same answer to round-off, and the error halves with resolution") {
  const auto& sod = pft::toro_cases[0];
  const errors ex = run_case<flux::hllc_lm>(sod, 0, 200);
  const errors ey = run_case<flux::hllc_lm>(sod, 1, 200);
  const errors ez = run_case<flux::hllc_lm>(sod, 2, 200);
  CHECK(std::fabs(ex.rho - ey.rho) < 1e-12);
  CHECK(std::fabs(ex.rho - ez.rho) < 1e-12);
  const errors e400 = run_case<flux::hllc_lm>(sod, 0, 400);
  const double order = std::log2(ex.rho / e400.rho);
  MESSAGE("Sod density L1: 200 cells ", ex.rho, ", 400 cells ", e400.rho, ", observed order ", order);
  // Discontinuities limit the L1 order to about 1 (shock) and 1/2–2/3 (contact).
  CHECK(order > 0.6);
}

TEST_CASE("first-order reconstruction is more diffusive than MUSCL on Sod") {
  const auto& sod = pft::toro_cases[0];
  const errors e1 = run_case<flux::hllc, recon::first_order>(sod, 0, 200);
  const errors e2 = run_case<flux::hllc, recon::muscl<limiter::mc>>(sod, 0, 200);
  MESSAGE("Sod density L1: first order ", e1.rho, ", MUSCL-MC ", e2.rho);
  CHECK(e2.rho < 0.7 * e1.rho);
}
