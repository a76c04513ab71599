// Assembly composition (leave-out), energy balance, and the rigid-body attachment.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <tuple>
#include <type_traits>

#include <parafsi/structure/assembly.hpp>
#include <parafsi/structure/attachment.hpp>
#include <parafsi/structure/cable.hpp>
#include <parafsi/structure/membrane_tri.hpp>

namespace st = parafsi::structure;
using parafsi::index_t;

// ---- leave-out: no cable / body storage and no cable / body pass when not declared
using membrane_only = st::assembly<st::membrane_tri<>>;
using with_cables = st::assembly<st::membrane_tri<>, st::cable<>>;
using with_body = st::assembly<st::membrane_tri<>, st::cable<>, st::attachment<>>;
static_assert(!membrane_only::has_cables && !membrane_only::has_body);
static_assert(membrane_only::line_count == 0 && membrane_only::body_count == 0);
static_assert(std::is_same_v<membrane_only::parts_type, std::tuple<st::membrane_tri<>>>);
static_assert(with_cables::has_cables && !with_cables::has_body);
static_assert(with_body::has_cables && with_body::has_body && with_body::body_count == 1);
static_assert(sizeof(membrane_only) + sizeof(st::cable<>) <= sizeof(with_cables) + alignof(std::max_align_t));
static_assert(sizeof(with_cables) < sizeof(with_body));

TEST_CASE("energy balance of a damped membrane + cable assembly under gravity") {
  st::nodes nd;
  nd.add({0, 0, 0});
  nd.add({1, 0, 0});
  nd.add({0, 1, 0});
  nd.add({1, 1, 0});
  st::triangle_mesh m;
  m.triangles = {{0, 1, 2}, {1, 3, 2}};
  st::assembly a{std::move(nd),
                 st::membrane_tri{m,
                                  st::material::fabric<st::wrinkling::none>::isotropic(1e9, 0.3, 0.05, 1e-4),
                                  {0.05}},
                 st::cable{st::line_mesh{{{0, 3}}, {}}, st::material::cable{1e4, 0.01, 0.1, 0}}};
  a.finalize();
  a.node_set().set_position(3, {1.1, 1.0, 0.05});
  a.node_set().pin(0);
  a.track_energy();
  const double U0 = a.evaluate_forces();
  const double dt = 0.1 * a.stable_dt();
  while (a.time() < 2.0) a.step(dt);
  const auto& E = a.energy();
  std::printf("assembly energy: U0 %.6e, K %.3e U %.3e D %.6e W %.3e, balance error %.3e (%.2e relative)\n", U0,
              E.kinetic, E.strain, E.damping, E.external, E.balance() - U0, (E.balance() - U0) / U0);
  CHECK(E.damping > 0.9 * U0);                    // most of it was dissipated
  CHECK(std::abs(E.balance() - U0) < 0.02 * U0);  // and accounted for
}

TEST_CASE("substeps: advance() splits a fluid step into ceil(dt_f / dt_s) equal substeps") {
  st::nodes nd;
  nd.add({0, 0, 0});
  nd.add({1, 0, 0}, {0, 0, 0}, 1.0);
  nd.pin(0);
  st::assembly a{std::move(nd), st::cable{st::line_mesh{{{0, 1}}, {}}, st::material::cable{1e4, 0.0, 0.0, 0.0}}};
  const double ds = a.stable_dt();
  CHECK(ds == doctest::Approx(0.9 * std::sqrt(2.0 * 1.0 / 1e4)).epsilon(1e-12));
  CHECK(a.advance(10.5 * ds) == 11);
  CHECK(a.steps() == 11);
}

TEST_CASE("a cable attached off-centre to a rigid body transmits force and moment; momentum conserved") {
  st::nodes nd;
  const index_t hang = nd.add({0.3, 0.1, 0.0});
  const index_t tip = nd.add({0.3, 0.1, 1.0}, {0.5, -0.2, 2.0}, 0.2);
  st::attachment body{st::rigid_body{st::rigid_body::cuboid(2.0, {0.4, 0.3, 0.2}),
                                     {0, 0, 0},
                                     Eigen::Quaterniond::Identity(),
                                     {0, 0, 0},
                                     {0.0, 0.0, 3.0}}};
  body.attach(hang, {0.3, 0.1, 0.0});  // off-centre hanging point
  st::assembly a{std::move(nd), st::cable{st::line_mesh{{{hang, tip}}, {0.9}}, st::material::cable{5e3, 0.05, 0.1, 0}},
                 std::move(body)};
  a.integrator().gravity.setZero();
  a.finalize();
  const Eigen::Vector3d P0 = a.linear_momentum(), L0 = a.angular_momentum();
  const Eigen::Vector3d spin0 = a.part<1>().body().spin_angular_momentum_world();
  const double dt = a.stable_dt();
  double Tmax = 0;
  for (int n = 0; n < 20000; ++n) {
    a.step(dt);
    Tmax = std::max(Tmax, a.part<0>().tension(a.node_set(), 0));
  }
  const Eigen::Vector3d P1 = a.linear_momentum(), L1 = a.angular_momentum();
  const Eigen::Vector3d Pb = a.part<1>().body().linear_momentum();
  const Eigen::Vector3d dspin = a.part<1>().body().spin_angular_momentum_world() - spin0;
  std::printf(
      "attachment: max tension %.3e N, body momentum (%.3e %.3e %.3e), spin change |%.3e|, "
      "|dP| %.3e of %.3e, |dL| %.3e of %.3e\n",
      Tmax, Pb.x(), Pb.y(), Pb.z(), dspin.norm(), (P1 - P0).norm(), P0.norm(), (L1 - L0).norm(), L0.norm());
  CHECK(Tmax > 1.0);           // the line did pull
  CHECK(Pb.norm() > 0.1);      // force transmitted to the body
  CHECK(dspin.norm() > 1e-3);  // moment transmitted (off-centre point)
  CHECK((P1 - P0).norm() < 1e-10 * P0.norm());
  CHECK((L1 - L0).norm() < 1e-10 * L0.norm());
}

TEST_CASE("a payload spinning at 100 rad/s with a riser stays stable") {
  st::nodes nd;
  const index_t hang = nd.add({0.0, 0.0, 0.1});
  const index_t top = nd.add({0.0, 0.0, 1.1}, {0, 0, 0}, 0.05);
  nd.pin(top);
  st::attachment body{st::rigid_body{st::rigid_body::cuboid(1.8, {0.2, 0.2, 0.2}),
                                     {0, 0, 0},
                                     Eigen::Quaterniond::Identity(),
                                     {0, 0, 0},
                                     {0.0, 0.0, 100.0}}};
  body.attach(hang, {0.0, 0.0, 0.1});
  st::assembly a{std::move(nd), st::cable{st::line_mesh{{{hang, top}}, {}}, st::material::cable{2e4, 0.02, 0.1, 0}},
                 std::move(body)};
  const double E0 = a.part<1>().body().kinetic_energy();
  long m = 0;
  while (a.time() < 1.0) m = std::max(m, a.advance(1e-3));
  const double wz = a.part<1>().body().angular_velocity_world().z();
  std::printf("spinning payload: %ld substeps per ms, omega_z %.6f rad/s, hang height %.4f m, K %.4e -> %.4e J\n", m,
              wz, a.node_set().position(hang).z(), E0, a.part<1>().body().kinetic_energy());
  CHECK(std::abs(wz - 100.0) < 1e-6 * 100.0);    // spin about the line axis is untouched
  CHECK(a.node_set().position(hang).z() < 0.1);  // it hangs from the line under gravity
  CHECK(a.node_set().position(hang).z() > 0.05);
}
