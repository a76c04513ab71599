// Belytschko–Tsay one-point quad membrane: patch test, objectivity, orthotropic moduli,
// exact energy gradient, folded start,
// hourglass control, set-up rejection, critical step vs the exact element frequency,
// scalar ≡ SIMD and thread independence, energy balance, and agreement with the CST
// triangle and Föppl–Hencky on the clamped circular membrane.
#include <doctest/doctest.h>

#include "approx.hpp"

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include <parafsi/core/parallel.hpp>
#include <parafsi/model/disk_mesh.hpp>
#include <parafsi/model/disk_quad_mesh.hpp>
#include <parafsi/structure/assembly.hpp>
#include <parafsi/structure/membrane_quad.hpp>
#include <parafsi/structure/membrane_tri.hpp>
#include <parafsi/structure/reference/hencky.hpp>
#include <parafsi/structure/relax.hpp>

#include "membrane_rig.hpp"

namespace st = parafsi::structure;
using mrig::rig;
using mrig::rotation;
using mrig::square_quads;
using parafsi::index_t;
using elastic = st::material::fabric<st::wrinkling::none>;

TEST_CASE("membrane_quad patch test: a uniform strain is reproduced exactly on a distorted mesh") {
  std::vector<Eigen::Vector3d> X;
  auto mesh = square_quads(6, X, 0.3);
  const double warp_angle = 0.5236;  // 30°
  mesh.warp = {std::cos(warp_angle), std::sin(warp_angle), 0.0};
  rig r(X, mesh, elastic{2e9, 1e9, 0.3, 0.4e9, 0.1, 1e-4}, st::quad_options{0.0, 0.05, 0.1, 0.0});
  const mrig::patch_map map(warp_angle);
  r.place(map(X));
  double err = 0, hg = 0;
  for (index_t e = 0; e < r.mem.size(); ++e) {
    err = std::max(err, map.strain_error(r.mem.strain_stress(r.nd, e)));
    hg = std::max(hg, r.mem.hourglass_mode(r.nd, e).norm());
  }
  std::printf("quad patch test: max strain error %.3e (strain ~ %.3e), max hourglass displacement %.3e m\n", err,
              std::abs(map.E11), hg);
  CHECK(err < 1e-13);
  CHECK(hg < 1e-14);
  const auto res = mrig::square_residual(r.forces(), 6);
  std::printf("quad patch test: max interior residual %.3e of max boundary force %.3e\n", res.max_interior,
              res.max_force);
  CHECK(res.max_force > 1.0);
  CHECK(res.max_interior < 1e-10 * res.max_force);
}

TEST_CASE("membrane_quad objectivity: a rigid rotation creates no strain and no force (flat and warped reference)") {
  for (double zj : {0.0, 0.05}) {
    std::vector<Eigen::Vector3d> X;
    auto mesh = square_quads(4, X, 0.2, zj);
    rig r(X, mesh, elastic::isotropic(1e9, 0.3, 0.05, 1e-4), st::quad_options{0.0, 0.05, 0.1, 0.0});
    const Eigen::Matrix3d R = rotation(1.3, 0.9, -2.2);
    std::vector<Eigen::Vector3d> x;
    for (const auto& p : X) x.push_back(R * p + Eigen::Vector3d{1, 2, 3});
    r.place(x);
    const double smax = mrig::max_strain_stress(r);
    double hg = 0;
    for (index_t e = 0; e < r.mem.size(); ++e) hg = std::max(hg, r.mem.hourglass_mode(r.nd, e).norm());
    const double fmax = mrig::max_norm(r.forces());
    std::printf("quad rigid rotation (reference warp %.2f cell): max |E| %.3e, hourglass %.3e m, max |f| %.3e N\n", zj,
                smax, hg, fmax);
    CHECK(smax < 1e-14);
    CHECK(hg < 1e-14);
    CHECK(fmax < 1e-8);
  }
}

TEST_CASE("membrane_quad: orthotropic law reproduces the warp, weft, shear and bias moduli") {
  const double E1 = 2.0e9, E2 = 0.8e9, nu12 = 0.25, G12 = 0.15e9;
  const auto fab = elastic{E1, E2, nu12, G12, 0.05, 1e-4};
  std::vector<Eigen::Vector3d> X{{0, 0, 0}, {1, 0.1, 0}, {1.1, 0.9, 0}, {-0.1, 0.8, 0}};
  st::quad_mesh m;
  m.quads = {{0, 1, 2, 3}};
  const double th = 0.6;
  m.warp = {std::cos(th), std::sin(th), 0};
  rig r(X, m, fab);
  const Eigen::Vector3d e1{std::cos(th), std::sin(th), 0}, e2{-std::sin(th), std::cos(th), 0};
  const Eigen::Matrix3d Rg = rotation(0.3, 0.2, 0.1);
  auto impose = [&](double a11, double a22, double a12) {
    Eigen::Matrix3d Ef = a11 * e1 * e1.transpose() + a22 * e2 * e2.transpose() +
                         a12 * (e1 * e2.transpose() + e2 * e1.transpose());
    const Eigen::Matrix3d U =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(Eigen::Matrix3d::Identity() + 2 * Ef).operatorSqrt();
    std::vector<Eigen::Vector3d> x;
    for (const auto& p : X) x.push_back(Rg * U * p);
    r.place(x);
    return r.mem.strain_stress(r.nd, 0);
  };
  const double eps = 1e-3;
  auto s = impose(eps, -nu12 * eps, 0);
  const double warp = s[3] / s[0];
  CHECK(warp == doctest::Approx(E1).epsilon(1e-9));
  CHECK(std::abs(s[4]) < 1e-9 * std::abs(s[3]));
  s = impose(-nu12 * E2 / E1 * eps, eps, 0);
  const double weft = s[4] / s[1];
  CHECK(weft == doctest::Approx(E2).epsilon(1e-9));
  CHECK(std::abs(s[3]) < 1e-9 * std::abs(s[4]));
  s = impose(0, 0, eps);
  CHECK(s[5] / s[2] == doctest::Approx(G12).epsilon(1e-9));
  const double sig = 1e5, c2 = 0.5;
  const double e11 = sig * (c2 / E1 - nu12 / E1 * c2), e22 = sig * (c2 / E2 - nu12 / E1 * c2), g12 = sig * c2 / G12;
  s = impose(e11, e22, 0.5 * g12);
  const double Sn = 0.5 * (s[3] + s[4]) + s[5];
  const double En = 0.5 * (s[0] + s[1]) + 0.5 * s[2];
  const double E45 = 4.0 / (1 / E1 + 1 / E2 + 1 / G12 - 2 * nu12 / E1);
  std::printf("quad moduli: warp %.6e (E1 %.6e) weft %.6e (E2 %.6e) bias %.6e (closed form %.6e)\n", warp, E1, weft, E2,
              Sn / En, E45);
  CHECK(Sn == doctest::Approx(sig).epsilon(1e-6));
  CHECK(Sn / En == doctest::Approx(E45).epsilon(1e-6));
}

TEST_CASE("membrane_quad hourglass control: a single element loaded in its hourglass mode does not collapse") {
  // Unit square, self-equilibrated nodal loads F h_I e_x (h = (1,−1,1,−1)): the one-point
  // strain is blind to this mode; only the hourglass spring resists, δ = F/(4 k_hg).
  std::vector<Eigen::Vector3d> X{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  st::quad_mesh m;
  m.quads = {{0, 1, 2, 3}};
  const double F = 2.0, h[4] = {1, -1, 1, -1};
  double omega = 0;  // of the controlled mode, √(4 k_hg / m); the same damping and time for both runs
  auto run = [&](double r_hg, double& delta, double& k) {
    st::nodes nd;
    for (const auto& x : X) nd.add(x);
    st::assembly s{std::move(nd), st::membrane_quad{m, elastic::isotropic(1e9, 0.3, 0.05, 1e-4),
                                                    st::quad_options{0.0, 0.05, r_hg, 0.0}}};
    s.integrator().gravity.setZero();
    s.finalize();
    k = s.part<0>().hourglass_spring(0);
    const double m_node = s.node_set().mass(0);
    if (omega == 0) omega = std::sqrt(4 * k / m_node);
    s.integrator().mass_damping = 2 * omega;
    auto load = [&](st::load_sink& sink, double) {
      for (int a = 0; a < 4; ++a) sink.add(a, Eigen::Vector3d{F * h[a], 0, 0});
    };
    const double dt = s.stable_dt();
    while (s.time() < 40 / omega) s.step(dt, load);
    delta = 0;
    for (int a = 0; a < 4; ++a) delta += 0.25 * h[a] * (s.node_set().position(a).x() - X[std::size_t(a)].x());
  };
  double d1, k1, d0, k0;
  run(0.05, d1, k1);
  run(0.0, d0, k0);
  const double d_exact = F / (4 * k1);
  std::printf(
      "hourglass load: r_hg = 0.05: delta %.6e m (F/(4k) = %.6e m, k_hg = %.4e N/m); r_hg = 0: delta %.3e m "
      "after the same time\n",
      d1, d_exact, k1, d0);
  CHECK(d1 == pft::rel(d_exact, 0.01));
  CHECK(std::abs(d1) < 1e-3);  // bounded, far below the element size
  // Uncontrolled: the mode drifts at the terminal speed F/(m α), δ ≈ 20 F/(4 k_hg) by then
  // and growing linearly in time.
  CHECK(std::abs(d0) > 10 * std::abs(d1));
}

TEST_CASE("membrane_quad: degenerate and inverted quads are rejected at set-up with their id") {
  auto message = [](std::vector<Eigen::Vector3d> X, std::vector<std::array<index_t, 4>> q) {
    st::nodes nd;
    for (const auto& x : X) nd.add(x);
    st::quad_mesh m;
    m.quads = q;
    st::assembly s{std::move(nd), st::membrane_quad{m, st::material::fabric<>::isotropic(1e9, 0.3, 0.05, 1e-4)}};
    std::string msg;
    try {
      s.finalize();
    } catch (const parafsi::invalid_input& e) {
      msg = e.what();
    }
    return msg;
  };
  const std::vector<Eigen::Vector3d> good{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  auto with = [&](std::vector<Eigen::Vector3d> extra) {
    auto X = good;
    X.insert(X.end(), extra.begin(), extra.end());
    return X;
  };
  // Element 1: re-entrant (arrowhead) quad.
  std::string a = message(with({{2, 0, 0}, {3, 0, 0}, {2.2, 0.2, 0}, {2, 1, 0}}), {{0, 1, 2, 3}, {4, 5, 6, 7}});
  // Element 1: self-intersecting (bow-tie) quad.
  std::string b = message(with({{2, 0, 0}, {3, 0, 0}, {2, 1, 0}, {3, 1, 0}}), {{0, 1, 2, 3}, {4, 5, 6, 7}});
  // Element 2: repeated node (collapsed to a triangle).
  std::string c = message(good, {{0, 1, 2, 3}, {0, 1, 2, 3}, {0, 1, 2, 2}});
  // Element 1: all corners on a line (zero area).
  std::string d = message(with({{2, 0, 0}, {3, 0, 0}, {4, 0, 0}, {5, 0, 0}}), {{0, 1, 2, 3}, {4, 5, 6, 7}});
  // Element 0: nearly collapsed corner (a sliver quad).
  std::string e = message({{0, 0, 0}, {1, 0, 0}, {1, 1e-3, 0}, {0, 1e-3, 0}}, {{0, 1, 2, 3}});
  std::printf("rejections:\n  %s\n  %s\n  %s\n  %s\n", a.c_str(), b.c_str(), c.c_str(), d.c_str());
  CHECK(a.find("element 1") != std::string::npos);
  CHECK(a.find("inverted") != std::string::npos);
  CHECK(b.find("element 1") != std::string::npos);
  CHECK(c.find("element 2") != std::string::npos);
  CHECK(c.find("repeats") != std::string::npos);
  CHECK(d.find("element 1") != std::string::npos);
  // A thin but regular rectangle is a valid element (all corners 90°).
  CHECK(e.empty());
}

TEST_CASE("membrane_quad: critical step is below 2/omega_max of the element and not far below") {
  // Exact ω_max of one free element: eigenvalues of M^{-1/2} K M^{-1/2}, K by central
  // differences of the corner forces at the (stress-free) reference.
  const auto fab = elastic{2e9, 1e9, 0.3, 0.5e9, 0.05, 1e-4};
  const std::vector<std::vector<Eigen::Vector3d>> shapes{
      {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}},
      {{0, 0, 0}, {3, 0, 0}, {3, 1, 0}, {0, 1, 0}},
      {{0, 0, 0}, {1.2, 0.1, 0}, {0.9, 0.8, 0}, {-0.2, 1.1, 0}},
      {{0, 0, 0}, {1, 0, 0}, {1.8, 1, 0}, {0.8, 1, 0}},      // parallelogram, 51° corner
      {{0, 0, 0}, {1, 0, 0}, {0.7, 0.5, 0}, {0.3, 0.5, 0}},  // trapezoid
  };
  for (double r_hg : {0.05, 0.1})
    for (const auto& X : shapes) {
      st::quad_mesh m;
      m.quads = {{0, 1, 2, 3}};
      rig r(X, m, fab, st::quad_options{0.0, 0.05, r_hg, 0.0});
      Eigen::Matrix<double, 12, 12> K;
      const double h = 1e-7;
      for (int j = 0; j < 12; ++j) {
        auto xp = X, xm = X;
        xp[std::size_t(j / 3)](j % 3) += h;
        xm[std::size_t(j / 3)](j % 3) -= h;
        r.place(xp);
        const auto fp = r.forces();
        r.place(xm);
        const auto fm = r.forces();
        for (int i = 0; i < 12; ++i)
          K(i, j) = -(fp[std::size_t(i / 3)](i % 3) - fm[std::size_t(i / 3)](i % 3)) / (2 * h);
      }
      r.place(X);
      Eigen::Matrix<double, 12, 12> A = 0.5 * (K + K.transpose());
      for (int i = 0; i < 12; ++i)
        for (int j = 0; j < 12; ++j) A(i, j) /= std::sqrt(r.nd.mass(i / 3) * r.nd.mass(j / 3));
      const double w2 = Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 12, 12>>(A).eigenvalues().maxCoeff();
      const double exact = 2 / std::sqrt(w2), dt = r.mem.critical_dt(r.nd);
      std::printf("quad dt: r_hg %.2f shape %zu: critical_dt %.4e s, 2/omega_max %.4e s, ratio %.3f\n", r_hg,
                  std::size_t(&X - shapes.data()), dt, exact, dt / exact);
      CHECK(dt <= exact);
      CHECK(dt >= 0.4 * exact);
    }
}

TEST_CASE("membrane_quad: corner forces are the exact gradient of the stored energy (incl. hourglass)") {
  // Warped, distorted reference; a large general deformation with hourglass content.
  std::vector<Eigen::Vector3d> X{{0, 0, 0.02}, {1.1, 0.1, -0.03}, {0.9, 0.95, 0.04}, {-0.1, 0.8, -0.01}};
  st::quad_mesh m;
  m.quads = {{0, 1, 2, 3}};
  rig r(X, m, elastic{2e9, 1e9, 0.3, 0.4e9, 0.1, 1e-4}, st::quad_options{0.0, 0.05, 0.1, 0.0});
  std::mt19937 g(5);
  std::uniform_real_distribution<double> u(-0.08, 0.08);
  const Eigen::Matrix3d R = rotation(0.4, 0.3, -0.2);
  std::vector<Eigen::Vector3d> x;
  for (const auto& p : X) x.push_back(R * (1.03 * p) + Eigen::Vector3d{u(g), u(g), u(g)});
  auto energy = [&](const std::vector<Eigen::Vector3d>& y) {
    r.place(y);
    r.mem.template compute_forces<true>(r.nd.kinematics());
    return r.mem.strain_energy();
  };
  r.place(x);
  const auto f = r.forces();
  const double U = energy(x), Uhg = r.mem.hourglass_energy();
  double err = 0, fmax = 0;
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k) {
      const double h = 1e-7;
      auto xp = x, xm = x;
      xp[std::size_t(i)](k) += h;
      xm[std::size_t(i)](k) -= h;
      const double dU = (energy(xp) - energy(xm)) / (2 * h);
      err = std::max(err, std::abs(f[std::size_t(i)](k) + dU));
      fmax = std::max(fmax, std::abs(f[std::size_t(i)](k)));
    }
  std::printf("quad gradient: U %.4e J (hourglass %.3e J), max |f + dU/dx| %.3e of max |f| %.3e\n", U, Uhg, err, fmax);
  CHECK(Uhg > 1e-4 * U);
  CHECK(err < 1e-6 * fmax);
}

TEST_CASE("membrane_quad: SIMD and scalar kernels agree; results do not depend on thread count") {
  const auto d = parafsi::model::disk_quad_mesh(1.0, 12);
  st::quad_mesh m;
  m.quads = d.quads;
  std::mt19937 g(11);
  const auto x = mrig::stretched_noisy(d.positions, g);
  rig r(d.positions, m, st::material::fabric<>{2e9, 1e9, 0.3, 0.3e9, 0.05, 1e-4},
        st::quad_options{0.05, 0.05, 0.1, 0.1});
  r.mem.set_pressure(100.0);
  r.place(x);
  std::uniform_real_distribution<double> u(-0.01, 0.01);
  for (std::size_t i = 0; i < x.size(); ++i) r.nd.set_velocity(index_t(i), Eigen::Vector3d{u(g), u(g), u(g)} * 100.0);
  mrig::check_simd_and_threads(r, "quad ");
}

TEST_CASE("membrane_quad: energy ledger balances for an undamped pressurised sheet") {
  // Clamped square sheet, sudden pressure, no damping: K + U − W stays constant.
  std::vector<Eigen::Vector3d> X;
  auto mesh = square_quads(8, X, 0.2);
  st::nodes nd;
  for (const auto& p : X) nd.add(p);
  for (int j = 0; j <= 8; ++j)
    for (int i = 0; i <= 8; ++i)
      if (i == 0 || j == 0 || i == 8 || j == 8) nd.pin(index_t(j * 9 + i));
  st::assembly s{std::move(nd),
                 st::membrane_quad{mesh, st::material::fabric<st::wrinkling::none>::isotropic(1e9, 0.3, 0.05, 1e-4)}};
  s.part<0>().set_pressure(50.0);
  s.integrator().gravity.setZero();
  s.track_energy();
  const double dt = s.stable_dt();
  double wmax = 0;
  while (s.time() < 0.02) {
    s.step(dt);
    wmax = std::max(wmax, s.energy().external);
  }
  const auto& E = s.energy();
  std::printf("quad energy: K %.4e U %.4e (hourglass %.3e) W %.4e, balance %.3e J (%.2e of max W)\n", E.kinetic,
              E.strain, s.part<0>().hourglass_energy(), E.external, E.balance(), E.balance() / wmax);
  CHECK(wmax > 0);
  CHECK(std::abs(E.balance()) < 0.01 * wmax);
}

TEST_CASE("clamped circular membrane: quad and triangle agree with each other and with Föppl–Hencky") {
  parafsi::parallel::set_threads(1);
  const mrig::hencky_case hc;
  // Triangles: 6 N² CST, N = 16 (1536 elements, 817 nodes).
  const double w_tri = hc.tri_deflection(16);
  // Quads: O-grid, n = 20 (400 + 80·10 = 1200 elements, 1241 nodes).
  auto quad_run = [&](int n, double r_hg, double& hg_share) {
    const auto d = parafsi::model::disk_quad_mesh(hc.a, n);
    st::nodes nd;
    for (const auto& x : d.positions) nd.add(x);
    for (auto i : d.rim) nd.pin(i);
    st::quad_mesh m;
    m.quads = d.quads;
    st::membrane_quad mem{m, hc.fabric(), st::quad_options{0.0, 0.05, r_hg, 0.0}};
    mem.set_pressure(hc.p);
    st::assembly s{std::move(nd), std::move(mem)};
    hc.relax(s);
    const double U = s.evaluate_forces();
    hg_share = s.part<0>().hourglass_energy() / U;
    std::printf("Hencky quad n = %d (%zu quads, r_hg %.2f): w0 = %.8e m, hourglass energy %.3e J of strain %.3e J\n", n,
                d.quads.size(), r_hg, s.node_set().position(d.centre).z(), s.part<0>().hourglass_energy(), U);
    return s.node_set().position(d.centre).z();
  };
  double share05, share10, share_coarse;
  const double w_quad = quad_run(20, 0.05, share05);
  const double w_quad10 = quad_run(20, 0.10, share10);
  const double w_coarse = quad_run(10, 0.05, share_coarse);
  const double w_ref = hc.w_ref();
  std::printf(
      "Hencky: w_ref %.8e  tri (N=16) %.8e (%+.3e)  quad (n=20) %.8e (%+.3e), quad vs tri %+.3e; "
      "r_hg 0.1: %+.3e vs ref; quad n=10: %+.3e vs ref\n",
      w_ref, w_tri, w_tri / w_ref - 1, w_quad, w_quad / w_ref - 1, w_quad / w_tri - 1, w_quad10 / w_ref - 1,
      w_coarse / w_ref - 1);
  std::printf("Hencky: hourglass share of strain energy %.3e (r_hg 0.05), %.3e (r_hg 0.1), %.3e (n = 10)\n", share05,
              share10, share_coarse);
  CHECK(std::abs(w_quad / w_tri - 1) < 0.02);
  CHECK(std::abs(w_quad / w_ref - 1) < 0.02);
  CHECK(std::abs(w_tri / w_ref - 1) < 0.02);
  CHECK(std::abs(w_quad10 / w_ref - 1) < 0.02);
  CHECK(std::abs(w_quad / w_ref - 1) < 0.003);    // in fact much closer
  CHECK(std::abs(w_quad10 / w_quad - 1) < 1e-4);  // insensitive to r_hg
  CHECK(share05 < 1e-3);
  CHECK(share10 < 1e-3);
  CHECK(share_coarse < 1e-3);
}

TEST_CASE("membrane_quad folded start: reference far from the initial positions runs stably") {
  // As the CST test: flat O-grid disk (R = 0.5 m) as the cut pattern, started folded
  // radially to 30 % with a corrugation, rim held, pressure inflates the slack bag.
  const auto d = parafsi::model::disk_quad_mesh(0.5, 12);
  st::quad_mesh m;
  m.quads = d.quads;
  m.reference = d.positions;
  auto nd = mrig::folded_disk(d.positions, d.rim);
  using fab = st::material::fabric<st::wrinkling::tension_field>;
  st::assembly s{std::move(nd), st::membrane_quad{m, fab::isotropic(4e8, 0.2, 0.05, 1e-4)}};
  double H0 = 0;
  const auto r = mrig::run_folded(s, d.centre, [&](auto& a) { H0 = a.template part<0>().hourglass_energy(); });
  const auto& E = s.energy();
  std::printf(
      "quad folded start: U0 %.3e J (hourglass %.3e J), apex %.3f m, max substeps/ms %ld, strain [%.3e, %.3e], "
      "K %.3e U %.3e (hourglass %.3e) D %.3e W %.3e, balance error %.3e of input %.3e\n",
      r.U0, H0, r.apex, r.max_substeps, r.emin, r.emax, E.kinetic, E.strain, s.part<0>().hourglass_energy(), E.damping,
      E.external, E.balance() - r.U0, r.U0 + E.external);
  mrig::check_folded(r, E);
}
