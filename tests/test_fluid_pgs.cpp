// Pressure-gradient scaling (fluid/pressure_scaling.hpp): a slow flow run with the sound
// speed lowered by α keeps its velocity field and its physical pressure differences and
// takes about α times fewer steps. Reference: the Gresho vortex, an exact steady solution
// of the Euler equations whose velocity and pressure differences do not depend on M.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>

#include "fluid_test_util.hpp"

using namespace parafsi;

namespace {
struct pgs_run {
  long steps = 0;
  double u_err = 0;  ///< L1 |u − u_exact| / L1 |u_exact|
  double p_err = 0;  ///< L1 |(p_phys − p∞) − Δp_exact| / max Δp_exact
};

// Physical Mach number `mach`, scaled by α: the scaled gas is the Gresho vortex at α M.
pgs_run gresho_scaled(double mach, double alpha, int n, double t_end) {
  const fluid::pressure_gradient_scaling pgs{alpha};
  pgs.validate();
  const fluid::reference::gresho_vortex physical{mach}, scaled{pgs.effective_mach(mach)};
  // The vortex's reference pressure (its centre value) plays the ambient's role.
  const double p_inf = 1.0 / (physical.gamma * mach * mach);
  // The scaled initial state must be the physical one with the ambient divided by α².
  const auto s0 = scaled(0.61, 0.43), p0 = physical(0.61, 0.43);
  REQUIRE(s0.p == doctest::Approx(pgs.scaled_ambient(p_inf) + (p0.p - p_inf)).epsilon(1e-12));

  auto grid = fluid::rectilinear_grid::uniform({n, n, 2}, {0, 0, 0}, {1, 1, 2.0 / n});
  fluid::solver s{grid, boundary::set::all(boundary::periodic{}), flux::hllc_lm{}, recon::muscl<limiter::van_leer>{}};
  s.initialize_averaged([&](const Eigen::Vector3d& x) { return scaled(x[0], x[1]); }, 4);
  pft::run_to(s, t_end, 0.5);
  pgs_run r;
  r.steps = long(s.steps());
  double du = 0, un = 0, dp = 0;
  const double dp_max = 4.0 * std::log(2.0) - 2.0;  // Δp outside the vortex ring
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double x = (i + 0.5) / n, y = (j + 0.5) / n;
      const auto e = physical(x, y);
      const auto w = s.primitive(i, j, 0);
      du += std::hypot(w.u.x - e.u.x, w.u.y - e.u.y);
      un += std::hypot(e.u.x, e.u.y);
      dp += std::fabs((pgs.physical_pressure(w.p, p_inf) - p_inf) - (e.p - p_inf));
    }
  r.u_err = du / un;
  r.p_err = dp / (double(n) * n) / dp_max;
  return r;
}
}  // namespace

TEST_CASE("pressure-gradient scaling: the Gresho vortex at M = 0.01 keeps u and physical Δp, alpha x fewer steps") {
  const double mach = 0.01, t_end = 0.2;
  const int n = 32;
  const double alphas[] = {1, 4, 8};
  pgs_run r[3];
  for (int k = 0; k < 3; ++k) {
    r[k] = gresho_scaled(mach, alphas[k], n, t_end);
    std::printf("gresho PGS M=%g alpha=%g (alpha M = %.2f): %ld steps, L1 u error %.4f, L1 physical dp error %.4f\n",
                mach, alphas[k], alphas[k] * mach, r[k].steps, r[k].u_err, r[k].p_err);
  }
  for (int k = 1; k < 3; ++k) {
    // Steps scale with 1/(|u| + c/α): at u_max/c = 0.01 α the saving is within 10 % of α.
    CHECK(double(r[0].steps) / double(r[k].steps) >= 0.9 * alphas[k]);
    // Velocity and physical pressure differences stay those of the unscaled run (HLLC-LM's
    // low-Mach dissipation even falls as αM grows): no worse than 1.2 × the α = 1 error.
    CHECK(r[k].u_err <= 1.2 * r[0].u_err);
    CHECK(r[k].p_err <= 1.2 * r[0].p_err);
  }
  // And the unscaled run itself is an accurate solution (sanity of the reference).
  CHECK(r[0].u_err < 0.10);
  CHECK(r[0].p_err < 0.10);
}

TEST_CASE("pressure-gradient scaling: bad alpha is rejected with its value") {
  CHECK_THROWS_WITH_AS(fluid::pressure_gradient_scaling{0.5}.validate(),
                       doctest::Contains("alpha must lie in [1, 1000], got 0.5"), invalid_input);
  CHECK_THROWS_AS(fluid::pressure_gradient_scaling{std::nan("")}.validate(), invalid_input);
  const fluid::pressure_gradient_scaling pgs{4};
  CHECK(pgs.scaled_ambient(101325.0) == doctest::Approx(101325.0 / 16));
  CHECK(pgs.physical_pressure(101325.0 / 16 + 37.0, 101325.0) == doctest::Approx(101325.0 + 37.0).epsilon(1e-14));
}
