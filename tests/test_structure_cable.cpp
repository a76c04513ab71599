// Cable verification: slack/taut law, oscillation frequency, slack→taut snap, catenary,
// steel wire on light fabric (computed substeps).
#include <doctest/doctest.h>

#include "approx.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include <parafsi/core/parallel.hpp>
#include <parafsi/model/disk_mesh.hpp>
#include <parafsi/structure/assembly.hpp>
#include <parafsi/structure/cable.hpp>
#include <parafsi/structure/membrane_tri.hpp>
#include <parafsi/structure/reference/catenary.hpp>
#include <parafsi/structure/relax.hpp>

namespace st = parafsi::structure;
using parafsi::index_t;

namespace {
/// Node 0 pinned at the origin, node 1 (point mass M) at distance x along +x.
auto two_node(double x, double L0, double EA, double M, double xi = 0.0, double preload = 0.0) {
  st::nodes nd;
  nd.add({0, 0, 0});
  nd.add({x, 0, 0}, {0, 0, 0}, M);
  nd.pin(0);
  st::assembly a{std::move(nd), st::cable{st::line_mesh{{{0, 1}}, {L0}}, st::material::cable{EA, 0.0, xi, preload}}};
  a.integrator().gravity.setZero();
  return a;
}
}  // namespace

TEST_CASE("cable law: slack carries nothing, taut carries EA x strain, preload shifts it") {
  const double EA = 2e4, L0 = 0.5;
  auto slack = two_node(0.49, L0, EA, 1.0);
  slack.evaluate_forces();
  CHECK(slack.node_set().force(1).norm() == 0.0);
  const double eps = 2e-3;
  auto taut = two_node(L0 * (1 + eps), L0, EA, 1.0);
  taut.evaluate_forces();
  CHECK(-taut.node_set().force(1).x() == doctest::Approx(EA * eps).epsilon(1e-12));
  CHECK(taut.part<0>().tension(taut.node_set(), 0) == doctest::Approx(EA * eps).epsilon(1e-12));
  auto pre = two_node(L0 * (1 + eps), L0, EA, 1.0, 0.0, 5.0);
  pre.evaluate_forces();
  CHECK(-pre.node_set().force(1).x() == doctest::Approx(5.0 + EA * eps).epsilon(1e-12));
}

TEST_CASE("a mass on a cable oscillates at sqrt(EA/(L m))") {
  const double EA = 1e4, L0 = 1.0, M = 2.0;
  // Gravity along +x stretches the line by δ = M g/k; an oscillation of amplitude δ/2
  // about that equilibrium keeps it taut, so the motion is harmonic.
  const double k = EA / L0, delta = M * 9.81 / k, x_eq = L0 + delta;
  auto a = two_node(x_eq + 0.5 * delta, L0, EA, M);
  a.integrator().gravity = {9.81, 0, 0};
  const double omega = std::sqrt(EA / (L0 * M)), T = 2 * std::numbers::pi / omega;
  const double dt = T / 2000;
  // Period from the upward zero crossings of the displacement over 10 periods.
  double prev = 0.5 * delta, first = -1, last = -1;
  int crossings = 0;
  while (a.time() < 10.5 * T) {
    a.step(dt);
    const double u = a.node_set().position(1).x() - x_eq;
    if (prev < 0 && u >= 0) {
      const double tc = a.time() - dt * u / (u - prev);
      if (first < 0) first = tc;
      else {
        last = tc;
        ++crossings;
      }
    }
    prev = u;
  }
  const double Tm = (last - first) / crossings;
  // Leapfrog's own period at this step: sin(ω̃Δt/2) = ωΔt/2.
  const double Tleap = 2 * std::numbers::pi * dt / (2 * std::asin(omega * dt / 2));
  std::printf("cable-mass: period %.9f s, closed form %.9f s (rel. err %.2e; leapfrog predicts %.2e)\n", Tm, T,
              Tm / T - 1, Tleap / T - 1);
  CHECK(Tm == pft::rel(T, 1e-5));
}

TEST_CASE("slack to taut snap: stable, peak tension v0 sqrt(k M), energy conserved") {
  const double EA = 5e4, L0 = 1.0, M = 1.0, v0 = 3.0;
  auto a = two_node(0.9, L0, EA, M);  // 10 cm of slack
  a.node_set().set_velocity(1, {v0, 0, 0});
  a.track_energy();
  const double k = EA / L0, dt = 0.02 * std::sqrt(M / k);
  double Tmax = 0, drift = 0;
  const double E0 = 0.5 * M * v0 * v0;
  while (a.time() < 0.3) {
    a.step(dt);
    Tmax = std::max(Tmax, a.part<0>().tension(a.node_set(), 0));
    drift = std::max(drift, std::abs(a.energy().balance() - E0) / E0);
  }
  const double Tpeak = v0 * std::sqrt(k * M);
  std::printf("snap: peak tension %.6e N, elastic collision %.6e N, max energy error %.3e\n", Tmax, Tpeak, drift);
  CHECK(Tmax == doctest::Approx(Tpeak).epsilon(2e-3));
  CHECK(drift < 2e-2);                      // bounded: the kink at L = L0 costs O(Δt) per snap
  CHECK(a.node_set().velocity(1).x() < 0);  // it bounced back
}

TEST_CASE("hanging chain matches the catenary within 1 % of the span") {
  const int N = 40;
  const double L = 1.2, S = 1.0;
  st::nodes nd;
  for (int i = 0; i <= N; ++i) {
    const double s = double(i) / N;
    nd.add({-0.5 * S + S * s, 0.0, -0.66 * std::min(s, 1 - s)});
  }
  nd.pin(0);
  nd.pin(N);
  st::line_mesh lm;
  for (int i = 0; i < N; ++i) {
    lm.segments.push_back({i, i + 1});
    lm.rest_length.push_back(L / N);
  }
  st::assembly c{std::move(nd), st::cable{lm, st::material::cable{1e4, 0.1, 0.2, 0.0}}};
  const st::reference::catenary cat(S, L);
  c.integrator().mass_damping = 2 * std::sqrt(9.81 / cat.sag());
  st::relax_options ro;
  ro.tolerance = 1e-10;
  ro.t_min = 1.0;
  ro.t_max = 60.0;
  const auto r = st::relax(c, ro);
  REQUIRE(r.converged);
  double dev = 0;
  for (int i = 0; i <= N; ++i) {
    const auto x = c.node_set().position(i);
    dev = std::max(dev, std::abs(x.z() - cat.z(x.x())));
  }
  std::printf("catenary: %d links, max deviation %.3e m = %.3e of span (sag %.6f vs %.6f)\n", N, dev, dev / S,
              -c.node_set().position(N / 2).z(), cat.sag());
  CHECK(dev / S < 0.01);
}

// relax() never hangs: a chain with EA = 1e300 N has a stable step of ~1e-151 s, so
// reaching t_max = 60 s would take ~1e152 steps; refused before the first step, naming
// the step count. A step limit stops a run that would take longer than max_steps.
TEST_CASE("relax refuses a run whose stable step makes t_max unreachable, and stops at max_steps") {
  auto chain = [](double EA) {
    const int N = 8;
    st::nodes nd;
    for (int i = 0; i <= N; ++i) {
      const double s = double(i) / N;
      nd.add({-0.5 + s, 0.0, -0.66 * std::min(s, 1 - s)});
    }
    nd.pin(0);
    nd.pin(N);
    st::line_mesh lm;
    for (int i = 0; i < N; ++i) {
      lm.segments.push_back({i, i + 1});
      lm.rest_length.push_back(1.2 / N);
    }
    return st::assembly{std::move(nd), st::cable{lm, st::material::cable{EA, 0.1, 0.2, 0.0}}};
  };
  auto stiff = chain(1e300);
  st::relax_options ro;
  ro.t_max = 60.0;
  CHECK_THROWS_WITH_AS(st::relax(stiff, ro), doctest::Contains("steps, more than max_steps = 1000000000"),
                       parafsi::numerical_failure);
  CHECK(stiff.time() == 0.0);  // refused before any step
  auto soft = chain(1e4);
  ro.max_steps = 50;
  ro.t_min = 1.0;
  ro.t_max = 1e30;  // unbounded time: the step limit alone ends it
  CHECK_THROWS_WITH_AS(st::relax(soft, ro), doctest::Contains("not at rest after max_steps = 50 steps"),
                       parafsi::numerical_failure);
}

TEST_CASE("steel wire lines on a light fabric run stably with the computed substep count") {
  auto make = [] {
    const auto d = parafsi::model::disk_mesh(0.5, 6);
    st::nodes nd;
    for (const auto& p : d.positions) nd.add(p);
    const index_t conf = nd.add({0, 0, -0.5});
    nd.pin(conf);
    st::triangle_mesh m;
    m.triangles = d.triangles;
    st::line_mesh lines;
    for (std::size_t k = 0; k < d.rim.size(); k += 6) {  // 6 lines of 10 wire elements
      const Eigen::Vector3d a = d.positions[std::size_t(d.rim[k])], b{0, 0, -0.5};
      index_t prev = d.rim[k];
      for (int j = 1; j <= 10; ++j) {
        const index_t next = j == 10 ? conf : nd.add(a + (b - a) * (j / 10.0));
        lines.segments.push_back({prev, next});
        prev = next;
      }
    }
    const double A = std::numbers::pi * 0.25e-6;  // 1 mm steel wire
    st::material::cable steel{200e9 * A, 7850 * A, 0.05, 0.0};
    st::membrane_tri mem{m, st::material::fabric<>::isotropic(2e8, 0.3, 0.04, 1e-4), st::membrane_options{0.05}};
    mem.set_pressure(50.0);
    return st::assembly{std::move(nd), std::move(mem), st::cable{lines, steel}};
  };
  auto s = make();
  const double dt_fluid = 5e-4;
  s.track_energy();
  long m = 0;
  while (s.time() < 0.05) m = std::max(m, s.advance(dt_fluid));
  const auto& E = s.energy();
  std::printf(
      "steel wire: stable dt %.3e s, %ld substeps per fluid step, K %.3e U %.3e D %.3e W %.3e, "
      "balance %.3e\n",
      s.stable_dt(), m, E.kinetic, E.strain, E.damping, E.external, E.balance());
  CHECK(m >= 5);  // the wires, not the fabric, set the step
  CHECK(s.stable_dt() < 0.2 * 0.9 * s.part<0>().critical_dt(s.node_set()));
  CHECK(std::abs(E.balance()) < 0.05 * E.external);
  // The same run at 2.5× the computed step fails loudly, naming a node and the time.
  auto bad = make();
  const double dt_bad = 2.5 * bad.stable_dt();
  std::string msg;
  try {
    while (bad.time() < 0.05) bad.step(dt_bad);
  } catch (const parafsi::numerical_failure& e) {
    msg = e.what();
  }
  INFO(msg);
  CHECK(msg.find("node") != std::string::npos);
  CHECK(msg.find("t = ") != std::string::npos);
}
