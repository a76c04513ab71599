// Membrane (CST) verification: patch tests, objectivity, orthotropic moduli, wrinkling,
// sliver rejection, scalar ≡ SIMD, thread independence, folded reference.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include <parafsi/core/parallel.hpp>
#include <parafsi/model/disk_mesh.hpp>
#include <parafsi/structure/assembly.hpp>
#include <parafsi/structure/membrane_tri.hpp>

#include "membrane_rig.hpp"

namespace st = parafsi::structure;
using mrig::rig;
using mrig::rotation;
using mrig::square_mesh;
using parafsi::index_t;

TEST_CASE("membrane_tri patch test: a uniform strain is reproduced exactly in every element") {
  std::vector<Eigen::Vector3d> X;
  auto mesh = square_mesh(6, X, 0.25);
  const double warp_angle = 0.5236;  // 30°
  mesh.warp = {std::cos(warp_angle), std::sin(warp_angle), 0.0};
  const auto fab = st::material::fabric<st::wrinkling::none>{2e9, 1e9, 0.3, 0.4e9, 0.1, 1e-4};
  rig r(X, mesh, fab);
  // x = R (F0 X) + c with a general in-plane F0 and a 3-D rigid rotation R; exact Green
  // strain in the fibre axes (e1 = warp, e2 = z × e1).
  const mrig::patch_map map(warp_angle);
  r.place(map(X));
  double err = 0;
  for (index_t e = 0; e < r.mem.size(); ++e) err = std::max(err, map.strain_error(r.mem.strain_stress(r.nd, e)));
  std::printf("patch test: max strain error %.3e (strain ~ %.3e)\n", err, std::abs(map.E11));
  CHECK(err < 1e-13);
  // Interior nodes are in equilibrium: net force ≈ 0 relative to element force scale.
  const auto res = mrig::square_residual(r.forces(), 6);
  std::printf("patch test: max interior residual %.3e of max boundary force %.3e\n", res.max_interior, res.max_force);
  CHECK(res.max_interior < 1e-10 * res.max_force);
}

TEST_CASE("membrane_tri objectivity: a rigid rotation creates no strain and no force") {
  std::vector<Eigen::Vector3d> X;
  auto mesh = square_mesh(4, X, 0.2);
  rig r(X, mesh, st::material::fabric<st::wrinkling::none>::isotropic(1e9, 0.3, 0.05, 1e-4));
  const Eigen::Matrix3d R = rotation(1.3, 0.9, -2.2);  // large rotation
  std::vector<Eigen::Vector3d> x;
  for (const auto& p : X) x.push_back(R * p + Eigen::Vector3d{1, 2, 3});
  r.place(x);
  const double smax = mrig::max_strain_stress(r);
  const double fmax = mrig::max_norm(r.forces());
  std::printf("rigid rotation: max |E| %.3e, max |f| %.3e N (E t = 1e5 N/m)\n", smax, fmax);
  CHECK(smax < 1e-14);
  CHECK(fmax < 1e-9);
}

TEST_CASE("orthotropic law reproduces the warp, weft, shear and bias moduli") {
  const double E1 = 2.0e9, E2 = 0.8e9, nu12 = 0.25, G12 = 0.15e9;
  const auto fab = st::material::fabric<st::wrinkling::none>{E1, E2, nu12, G12, 0.05, 1e-4};
  std::vector<Eigen::Vector3d> X{{0, 0, 0}, {1, 0.1, 0}, {0.2, 0.9, 0}};
  st::triangle_mesh m;
  m.triangles = {{0, 1, 2}};
  const double th = 0.6;  // warp direction in the plane
  m.warp = {std::cos(th), std::sin(th), 0};
  rig r(X, m, fab);
  const Eigen::Vector3d e1{std::cos(th), std::sin(th), 0}, e2{-std::sin(th), std::cos(th), 0};
  const Eigen::Matrix3d Rg = rotation(0.3, 0.2, 0.1);
  // Impose the Green strain E (fibre axes) by the stretch F = sqrt(I + 2E) in 3-D.
  auto impose = [&](double a11, double a22, double a12) {
    Eigen::Matrix3d Ef = Eigen::Matrix3d::Zero();
    Ef += a11 * e1 * e1.transpose() + a22 * e2 * e2.transpose() + a12 * (e1 * e2.transpose() + e2 * e1.transpose());
    const Eigen::Matrix3d C = Eigen::Matrix3d::Identity() + 2 * Ef;
    const Eigen::Matrix3d U = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(C).operatorSqrt();
    std::vector<Eigen::Vector3d> x;
    for (const auto& p : X) x.push_back(Rg * U * p);
    r.place(x);
    return r.mem.strain_stress(r.nd, 0);
  };
  const double eps = 1e-3;
  auto s = impose(eps, -nu12 * eps, 0);  // uniaxial stress along the warp
  CHECK(s[3] / s[0] == doctest::Approx(E1).epsilon(1e-9));
  CHECK(std::abs(s[4]) < 1e-9 * std::abs(s[3]));
  s = impose(-nu12 * E2 / E1 * eps, eps, 0);  // uniaxial stress along the weft
  CHECK(s[4] / s[1] == doctest::Approx(E2).epsilon(1e-9));
  CHECK(std::abs(s[3]) < 1e-9 * std::abs(s[4]));
  s = impose(0, 0, eps);  // pure shear: S12 = G12 · 2E12
  CHECK(s[5] / s[2] == doctest::Approx(G12).epsilon(1e-9));
  // Bias (45°) uniaxial stress σ: strains from the compliance (Jones 1999, Eq. 2.89),
  // apparent modulus 1/E45 = (1/E1 + 1/E2 + 1/G12 − 2ν12/E1)/4.
  const double sig = 1e5, c2 = 0.5;
  const double e11 = sig * (c2 / E1 - nu12 / E1 * c2), e22 = sig * (c2 / E2 - nu12 / E1 * c2), g12 = sig * c2 / G12;
  s = impose(e11, e22, 0.5 * g12);
  const double Sn = 0.5 * (s[3] + s[4]) + s[5];                        // n·S·n, n = (1,1)/√2
  const double Et = 0.5 * (s[0] + s[1]) + s[2] * 1.0 * 0.5 * 2 * 0.5;  // n·E·n
  const double E45 = 4.0 / (1 / E1 + 1 / E2 + 1 / G12 - 2 * nu12 / E1);
  std::printf("moduli: warp %.6e weft %.6e bias apparent %.6e (closed form %.6e)\n", E1, E2, Sn / Et, E45);
  CHECK(Sn == doctest::Approx(sig).epsilon(1e-6));
  CHECK(Sn / Et == doctest::Approx(E45).epsilon(1e-6));
}

TEST_CASE("wrinkling: compression is carried only as residual x elastic stress") {
  std::vector<Eigen::Vector3d> X{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  st::triangle_mesh m;
  m.triangles = {{0, 1, 2}};
  const double rc = 1e-3;
  auto iso_el = st::material::fabric<st::wrinkling::none>::isotropic(1e9, 0.3, 0.05, 1e-4);
  auto iso_w1 = st::material::fabric<>::isotropic(1e9, 0.3, 0.05, 1e-4, st::wrinkling::stress_elimination{rc});
  auto iso_tf = st::material::fabric<st::wrinkling::tension_field>::isotropic(1e9, 0.3, 0.05, 1e-4, {rc});
  rig a(X, m, iso_el);
  rig b(X, m, iso_w1);
  rig c(X, m, iso_tf);
  auto put = [&](auto& r, double sx, double sy) {
    std::vector<Eigen::Vector3d> x{{0, 0, 0}, {sx, 0, 0}, {0, sy, 0}};
    r.place(x);
    return r.mem.strain_stress(r.nd, 0);
  };
  // Slack: biaxial compression → every stress scaled by r_c.
  auto se = put(a, 0.98, 0.97), sw = put(b, 0.98, 0.97);
  CHECK(se[3] < 0);
  CHECK(sw[3] == doctest::Approx(rc * se[3]).epsilon(1e-12));
  CHECK(sw[4] == doctest::Approx(rc * se[4]).epsilon(1e-12));
  // Wrinkled: tension along x, strong contraction along y → minor principal stress × r_c.
  se = put(a, 1.01, 0.98);
  sw = put(b, 1.01, 0.98);
  CHECK(se[4] < 0);
  CHECK(sw[3] == doctest::Approx(se[3]).epsilon(1e-12));
  CHECK(sw[4] == doctest::Approx(rc * se[4]).epsilon(1e-12));
  // Tension field (isotropic, exact): uniaxial S11 = E e1 (+ r_c elastic).
  const auto st_ = put(c, 1.01, 0.98);
  const double e1 = 0.5 * (1.01 * 1.01 - 1);
  CHECK(st_[3] == doctest::Approx(1e9 * e1 + rc * se[3]).epsilon(1e-12));
  CHECK(st_[4] == doctest::Approx(rc * se[4]).epsilon(1e-12));
}

TEST_CASE("wrinkling: a sheet pushed together stays stable and carries ~no compression") {
  std::vector<Eigen::Vector3d> X;
  auto mesh = square_mesh(8, X, 0.0);
  const double rc = 1e-3, Et = 1e5;
  st::nodes nd;
  std::mt19937 g(3);
  std::uniform_real_distribution<double> u(-1e-4, 1e-4);
  for (const auto& p : X) nd.add(p + Eigen::Vector3d{0, 0, u(g)});
  std::vector<index_t> right;
  for (int j = 0; j <= 8; ++j) {
    nd.pin(index_t(j * 9));
    right.push_back(index_t(j * 9 + 8));
    nd.prescribe_velocity(index_t(j * 9 + 8), {-1.0, 0, 0});  // 1 m/s inwards
  }
  st::assembly s{std::move(nd), st::membrane_tri{mesh, st::material::fabric<>::isotropic(1e10, 0.3, 0.05, 1e-5, {rc}),
                                                 st::membrane_options{0.1}}};
  s.integrator().gravity.setZero();
  s.track_energy();
  const double dt = s.stable_dt();
  long n = 0;
  while (s.time() < 0.1) {
    s.step(dt);
    ++n;
  }  // 10 % compression
  for (index_t i : right) s.node_set().set_velocity(i, Eigen::Vector3d::Zero());
  const double t1 = s.time();
  while (s.time() < t1 + 0.05) {
    s.step(dt);
    ++n;
  }
  // Reaction on the moving edge vs the elastic reaction of a 10 % compression, E t · 0.1 per unit width.
  s.evaluate_forces();
  double fx = 0;
  for (index_t i : right) fx += s.node_set().force(i).x();
  const double elastic = Et * 0.1;
  std::printf("wrinkling sheet: %ld steps, edge reaction %.3e N vs elastic %.3e N, energy balance %.3e J\n", n, fx,
              elastic, s.energy().balance());
  CHECK(std::isfinite(fx));
  CHECK(std::abs(fx) < 2 * rc * elastic);
}

TEST_CASE("sliver triangles are rejected at set-up with their id") {
  st::nodes nd;
  nd.add({0, 0, 0});
  nd.add({1, 0, 0});
  nd.add({0, 1, 0});
  nd.add({2, 0, 0});
  nd.add({3, 1e-5, 0});
  st::triangle_mesh m;
  m.triangles = {{0, 1, 2}, {1, 3, 4}};
  st::assembly s{std::move(nd), st::membrane_tri{m, st::material::fabric<>::isotropic(1e9, 0.3, 0.05, 1e-4)}};
  std::string msg;
  try {
    s.finalize();
  } catch (const parafsi::invalid_input& e) {
    msg = e.what();
  }
  INFO(msg);
  CHECK(msg.find("element 1") != std::string::npos);
  CHECK(msg.find("sliver") != std::string::npos);
}

TEST_CASE("a non-finite reference position or warp direction is refused at set-up, not called a sliver") {
  auto finalize_message = [](Eigen::Vector3d x2, Eigen::Vector3d warp) {
    st::nodes nd;
    nd.add({0, 0, 0});
    nd.add({1, 0, 0});
    nd.add({0, 1, 0});
    st::triangle_mesh m;
    m.triangles = {{0, 1, 2}};
    m.reference = {{0, 0, 0}, {1, 0, 0}, x2};  // the stress-free state
    m.warp = warp;
    st::assembly s{std::move(nd), st::membrane_tri{m, st::material::fabric<>::isotropic(1e9, 0.3, 0.05, 1e-4)}};
    std::string msg;
    try {
      s.finalize();
    } catch (const parafsi::invalid_input& e) {
      msg = e.what();
    }
    return msg;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::string a = finalize_message({0, nan, 0}, Eigen::Vector3d::UnitX());
  INFO(a);
  CHECK(a.find("element 0 has a non-finite reference position at node 2") != std::string::npos);
  CHECK(a.find("sliver") == std::string::npos);
  const std::string b = finalize_message({0, 1, 0}, {nan, 0, 0});
  INFO(b);
  CHECK(b.find("element 0 has a non-finite warp direction") != std::string::npos);
  CHECK(finalize_message({0, 1, 0}, Eigen::Vector3d::UnitX()).empty());  // the valid element passes
}

TEST_CASE("membrane_tri: SIMD and scalar kernels agree; results do not depend on thread count") {
  const auto d = parafsi::model::disk_mesh(1.0, 12);
  st::triangle_mesh m;
  m.triangles = d.triangles;
  std::mt19937 g(11);
  const auto x = mrig::stretched_noisy(d.positions, g);
  rig r(d.positions, m, st::material::fabric<>{2e9, 1e9, 0.3, 0.3e9, 0.05, 1e-4});
  r.mem.set_pressure(100.0);
  r.place(x);
  mrig::check_simd_and_threads(r, "");
}

TEST_CASE("folded start: reference geometry far from the initial positions runs stably") {
  // Reference: flat disk of radius 0.5 m (the cut pattern). Start: folded radially to 30 %
  // with a corrugation, the rim held at its folded position (like a skirt gathered by
  // the lines); pressure inflates the slack bag, mass damping brings it to rest.
  const auto d = parafsi::model::disk_mesh(0.5, 10);
  st::triangle_mesh m;
  m.triangles = d.triangles;
  m.reference = d.positions;
  auto nd = mrig::folded_disk(d.positions, d.rim);
  // Tension-field wrinkling: for an isotropic sheet it derives from a potential, so the
  // energy ledger must balance. (Stress elimination, W1, is not conservative: in this
  // folded start it feeds a sustained flutter; see docs/structure.md.)
  using fab = st::material::fabric<st::wrinkling::tension_field>;
  st::assembly s{std::move(nd), st::membrane_tri{m, fab::isotropic(4e8, 0.2, 0.05, 1e-4), st::membrane_options{0.0}}};
  const auto r = mrig::run_folded(s, 0, [](auto&) {});
  const auto& E = s.energy();
  std::printf(
      "folded start: apex height %.3f m, max substeps per ms %ld, strain range [%.3e, %.3e], "
      "K %.3e U %.3e D %.3e W %.3e\n",
      r.apex, r.max_substeps, r.emin, r.emax, E.kinetic, E.strain, E.damping, E.external);
  std::printf("folded start: energy balance error %.3e J of %.3e J input\n", E.balance() - r.U0, r.U0 + E.external);
  mrig::check_folded(r, E);
}
