// Assembly composition (leave-out), energy balance, and the rigid-body attachment.
#include <doctest/doctest.h>

#include <array>
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

/// A membrane triangle (nodes 0–2 at x, v), a line from node 0 to node 3, and node 3 tied
/// to a 2 kg body at the body point `hang` (the body at the origin with attitude q, velocity
/// vb, angular velocity wb): the rig of the hold tests.
namespace {
auto line_rig(const std::array<Eigen::Vector3d, 3>& x, const std::array<Eigen::Vector3d, 3>& v,
              const Eigen::Vector3d& hang, const Eigen::Quaterniond& q, const Eigen::Vector3d& vb,
              const Eigen::Vector3d& wb) {
  st::nodes nd;
  for (int k = 0; k < 3; ++k) nd.add(x[std::size_t(k)], v[std::size_t(k)]);
  const index_t tie = nd.add(hang);
  st::triangle_mesh m;
  m.triangles = {{0, 1, 2}};
  st::attachment body{st::rigid_body{st::rigid_body::cuboid(2.0, {0.4, 0.3, 0.2}), {0, 0, 0}, q, vb, wb}};
  body.attach(tie, hang);
  st::assembly a{std::move(nd),
                 st::membrane_tri{m,
                                  st::material::fabric<st::wrinkling::none>::isotropic(1e7, 0.3, 0.05, 1e-4),
                                  {0.05}},
                 st::cable{st::line_mesh{{{tie, 0}}, {0.8}}, st::material::cable{5e3, 0.05, 0.1, 0}}, std::move(body)};
  a.finalize();
  return a;
}
}  // namespace

TEST_CASE("hold(V): a captive structure translates rigidly at V whatever its loads; release_hold() frees it") {
  // A loaded, moving membrane + line + spinning body held captive (the drop's --captive):
  // each node and the body's mass centre move by exactly V t, the attitude stays, the load
  // hook still runs every substep.
  auto a = line_rig({{{0, 0, 1}, {1, 0, 1}, {0, 1, 1.2}}}, {{{0.3, 0, 0}, {0, -0.2, 0}, {0, 0, 0.5}}}, {0.1, 0.0, 0.0},
                    Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX())), {0.1, 0.2, -0.4},
                    {1.0, 0.0, 3.0});
  const Eigen::Vector3d V(0.4, -1.5, -7.0);
  a.hold(V);
  CHECK(a.held());
  std::vector<Eigen::Vector3d> x0;
  for (index_t i = 0; i < a.node_set().size(); ++i) x0.push_back(a.node_set().position(i));
  const auto& b = a.part<2>().body();
  const Eigen::Vector3d c0 = b.mass_centre();
  const Eigen::Quaterniond q0 = b.attitude();
  const double dt = 0.5 * a.stable_dt();
  int calls = 0;
  const int n = 400;
  for (int k = 0; k < n; ++k)
    a.step(dt, [&](st::load_sink& sink, double) {
      ++calls;
      sink.add(1, {50.0, 0.0, 20.0});  // a load the held structure must not follow
    });
  const double t = a.time();
  CHECK(calls == n);
  double worst = 0;
  for (index_t i = 0; i < a.node_set().size(); ++i) {
    worst = std::max(worst, (a.node_set().position(i) - x0[std::size_t(i)] - V * t).norm());
    CHECK((a.node_set().velocity(i) - V).norm() <= 1e-15 * V.norm());
  }
  CHECK(worst <= 1e-13 * V.norm() * t);  // shape and place: round-off of n additions
  CHECK((b.mass_centre() - c0 - V * t).norm() <= 1e-13 * V.norm() * t);
  CHECK(b.attitude().angularDistance(q0) == 0.0);
  CHECK((b.mass_centre_velocity() - V).norm() <= 1e-15 * V.norm());
  CHECK(b.angular_velocity_world().norm() == 0.0);
  // Freed, the structure follows its loads again: over the first free substep the held
  // membrane is unstrained (moved rigidly) and node 2 carries no line, so gravity alone
  // kicks it by g dt, while node 0 is pulled by the taut line as well.
  a.release_hold();
  CHECK(!a.held());
  a.step(dt);
  const Eigen::Vector3d g_dt = dt * a.integrator().gravity;
  CHECK((a.node_set().velocity(2) - V - g_dt).norm() <= 1e-9 * g_dt.norm());
  CHECK((a.node_set().velocity(0) - V - g_dt).norm() > 10.0 * g_dt.norm());
}

TEST_CASE("hold(V, bodies): the body translates at V, its line and membrane move under their loads") {
  // A canopy on a held payload (the drop's --captive-hold payload): the body keeps its
  // attitude and moves at V whatever the line pulls; the node tied to it follows it; the
  // free nodes are integrated (gravity and the taut line move them off the translation).
  auto a = line_rig({{{0, 0, 1}, {1, 0, 1}, {0, 1, 1}}},
                    {{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()}}, {0.0, 0.0, 0.0},
                    Eigen::Quaterniond::Identity(), {0, 0, 0}, {0.0, 2.0, 0.0});
  const index_t hang = 3;
  const Eigen::Vector3d V(0.0, 0.0, -7.0);
  using scope = decltype(a)::hold_scope;
  a.hold(V, scope::bodies);
  CHECK(a.held_scope() == scope::bodies);
  const auto& b = a.part<2>().body();
  // The body takes V at once, its spin stops, its node goes with it.
  CHECK((b.mass_centre_velocity() - V).norm() <= 1e-15 * V.norm());
  CHECK(b.angular_velocity_world().norm() == 0.0);
  CHECK((a.node_set().velocity(hang) - V).norm() <= 1e-15 * V.norm());
  const Eigen::Vector3d c0 = b.mass_centre(), x1 = a.node_set().position(1);
  const Eigen::Quaterniond q0 = b.attitude();
  const double dt = 0.5 * a.stable_dt();
  for (int k = 0; k < 400; ++k) a.step(dt);
  const double t = a.time();
  CHECK((b.mass_centre() - c0 - V * t).norm() <= 1e-13 * V.norm() * t);
  CHECK(b.attitude().angularDistance(q0) == 0.0);  // the spin it had is held too
  CHECK((a.node_set().position(hang) - b.position()).norm() <= 1e-12);
  // Node 1 started at rest and is integrated under its loads: it lags the held translation.
  const double off = (a.node_set().position(1) - x1 - V * t).norm();
  MESSAGE("held body: node 1 at ", off, " m off the translation V t = ", V.norm() * t, " m");
  CHECK(off > 0.1 * V.norm() * t);
}
