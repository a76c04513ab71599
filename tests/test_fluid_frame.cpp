// Moving-box properties: free-stream preservation on a translating + rotating box
// (GCL), Galilean invariance (a moving box reproduces the fixed-box solution shifted
// by the box velocity), the follow-payload frame tracks its target and turns its
// axis to the target's velocity (the paper's Eq. 1, discrete form).
#include <doctest/doctest.h>

#include "approx.hpp"

#include <numbers>

#include "fluid_test_util.hpp"

using namespace parafsi;
using pft::prim;

TEST_CASE("free-stream preservation on a translating and rotating box") {
  const double rho0 = 1.18, p0 = 101325.0;
  const double c0 = std::sqrt(1.4 * p0 / rho0);
  for (const Eigen::Vector3d& u0 : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(3.0, -4.0, 12.0)}) {
    frame::rigid motion{Eigen::Vector3d(12.0, 16.0, 0.0), Eigen::Vector3d(0.6, 0.0, 0.8)};  // 20 m/s, 1 rad/s
    fluid::solver s{fluid::rectilinear_grid::uniform({10, 8, 6}, {-1, -1, -1}, {1, 1, 1}),
                    boundary::set::all(boundary::far_field{rho0, {u0[0], u0[1], u0[2]}, p0}), motion,
                    recon::muscl<limiter::mc>{}};
    s.fill_uniform({rho0, {u0[0], u0[1], u0[2]}, p0});
    for (int n = 0; n < 2000; ++n) s.step(s.stable_dt(0.5));
    double du = 0, dp = 0;
    for (index_t k = 0; k < 6; ++k)
      for (index_t j = 0; j < 8; ++j)
        for (index_t i = 0; i < 10; ++i) {
          const auto w = s.primitive(i, j, k);
          du = std::max(du, std::sqrt(std::pow(w.u.x - u0[0], 2) + std::pow(w.u.y - u0[1], 2) +
                                      std::pow(w.u.z - u0[2], 2)));
          dp = std::max(dp, std::fabs(w.p - p0));
        }
    const double turned = std::acos(std::clamp((s.pose().R.trace() - 1) / 2, -1.0, 1.0));
    MESSAGE("u0 = ", u0.transpose(), ": after 2000 steps (box turned ", turned, " rad): max|du| = ", du,
            " m/s, max|dp| = ", dp, " Pa");
    CHECK(turned > 0.05);
    CHECK(du / c0 < 1e-12);
    CHECK(dp / p0 < 1e-12);
  }
}

TEST_CASE("Galilean invariance: a translating box reproduces the fixed-box solution") {
  // A vortex plus a density blob in a periodic box: solve once in a fixed box, once in
  // a box moving at V with the same field advected by V (absolute velocities u + V).
  const Eigen::Vector3d V(7.0, -3.0, 2.0);
  auto init = [](const Eigen::Vector3d& x, const Eigen::Vector3d& shift) {
    const double r2 = x[0] * x[0] + x[1] * x[1];
    const double f = 0.3 * std::exp(-r2 / 0.05);
    return prim{1.0 + 0.2 * std::exp(-(r2 + x[2] * x[2]) / 0.02),
                {shift[0] - f * x[1], shift[1] + f * x[0], shift[2] + 0.1 * std::sin(2 * std::numbers::pi * x[2])},
                1.0 + 0.05 * std::exp(-r2 / 0.03)};
  };
  auto grid = fluid::rectilinear_grid::uniform({16, 16, 8}, {-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
  auto bc = boundary::set::all(boundary::periodic{});
  fluid::solver fixed_box{grid, bc, flux::hllc_lm{}};
  fluid::solver moving_box{grid, bc, flux::hllc_lm{}, frame::translate{V}};
  fixed_box.initialize([&](const Eigen::Vector3d& x) { return init(x, Eigen::Vector3d::Zero()); });
  moving_box.initialize([&](const Eigen::Vector3d& x) { return init(x, V); });
  const double dt = 0.2 * fixed_box.stable_dt(0.5);
  for (int n = 0; n < 100; ++n) {
    fixed_box.step(dt);
    moving_box.step(dt);
  }
  double d = 0;
  for (index_t k = 0; k < 8; ++k)
    for (index_t j = 0; j < 16; ++j)
      for (index_t i = 0; i < 16; ++i) {
        const auto a = fixed_box.primitive(i, j, k), b = moving_box.primitive(i, j, k);
        d = std::max({d, std::fabs(a.rho - b.rho), std::fabs(a.p - b.p), std::fabs(a.u.x - (b.u.x - V[0])),
                      std::fabs(a.u.y - (b.u.y - V[1])), std::fabs(a.u.z - (b.u.z - V[2]))});
      }
  MESSAGE("max difference fixed vs moving box after 100 steps: ", d);
  CHECK((moving_box.pose().X - V * moving_box.time()).norm() < 1e-12);
  CHECK(d < 1e-10);
}

TEST_CASE("follow_payload frame: tracks the target and aligns its axis with the target velocity") {
  fluid::solver s{fluid::rectilinear_grid::uniform({4, 4, 4}, {-1, -1, -1}, {1, 1, 1}),
                  boundary::set::all(boundary::far_field{}), frame::follow_payload{}};
  // A target on a curved path: x(t) = (a sin ωt, 0, −v t), velocity direction turns.
  const double a = 2.0, w = 1.5, v = 6.0, dt = 1e-3;
  double worst_pos = 0, worst_angle = 0;
  for (int n = 1; n <= 400; ++n) {
    const double t = n * dt;
    const Eigen::Vector3d x(a * std::sin(w * t), 0.0, -v * t), vel(a * w * std::cos(w * t), 0.0, -v);
    s.frame().track(x, vel);
    s.advance_pose_only(dt);
    const Eigen::Vector3d axis = s.pose().R * Eigen::Vector3d(0, 0, -1);
    worst_pos = std::max(worst_pos, (s.pose().X - x).norm());
    // The box starts 0.46 rad off the velocity and turns at most max_rate = 10 rad/s:
    // aligned after 46 steps; from then on it must stay aligned.
    if (n > 100)
      worst_angle = std::max(worst_angle, std::atan2(axis.cross(vel.normalized()).norm(), axis.dot(vel.normalized())));
  }
  MESSAGE("follow_payload: max position error ", worst_pos, " m, max axis misalignment ", worst_angle, " rad");
  CHECK(worst_pos < 1e-12);
  CHECK(worst_angle < 1e-9);
  // Its turning rate equals Eq. 1, |v × v̇| / |v|², to first order in dt.
  const double t = 0.4;
  const Eigen::Vector3d vel(a * w * std::cos(w * t), 0, -v), acc(-a * w * w * std::sin(w * t), 0, 0);
  const double eq1 = vel.cross(acc).norm() / vel.squaredNorm();
  CHECK(s.pose().Omega.norm() == pft::rel(eq1, 0.01));
}

TEST_CASE("a rotating box ends each step at the same pose with SSP-RK2 and SSP-RK3") {
  auto grid = fluid::rectilinear_grid::uniform({4, 4, 4}, {-1, -1, -1}, {1, 1, 1});
  frame::rigid motion{Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(0.0, 0.0, 1.0)};
  fluid::solver a{grid, boundary::set::all(boundary::far_field{}), motion, time::ssp_rk2{}};
  fluid::solver b{grid, boundary::set::all(boundary::far_field{}), motion, time::ssp_rk3{}};
  for (int n = 0; n < 100; ++n) {
    a.step(1e-4);
    b.step(1e-4);
  }
  const Eigen::Matrix3d R_exact = Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  CHECK((a.pose().R - R_exact).norm() < 1e-13);
  CHECK((b.pose().R - R_exact).norm() < 1e-13);
  CHECK((b.pose().X - Eigen::Vector3d(1, 2, 3) * 0.01).norm() < 1e-13);
}
