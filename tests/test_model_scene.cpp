// Drop-scene builders: packed shapes (the bundle at line stretch too), lines, riser, payload,
// masses, the C-9 variant, rejection; the duct/screen scene of the coupling tests.
#include <doctest/doctest.h>

#include "approx.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <utility>

#include <Eigen/Dense>

#include <parafsi/model/drop_box.hpp>
#include <parafsi/model/drop_scene.hpp>
#include <parafsi/model/duct_screen.hpp>
#include <parafsi/scene/drop_steps.hpp>
#include <parafsi/structure/nodes.hpp>

namespace pf = parafsi;
namespace md = parafsi::model;
using pf::index_t;

namespace {
double max_edge_strain(const md::canopy_mesh& c, const std::vector<Eigen::Vector3d>& x) {
  double e = 0;
  for (const auto& t : c.triangles)
    for (int a = 0; a < 3; ++a) {
      const auto i = std::size_t(t[std::size_t(a)]), j = std::size_t(t[std::size_t((a + 1) % 3)]);
      const double L0 = (c.positions[j] - c.positions[i]).norm(), L = (x[j] - x[i]).norm();
      e = std::max(e, std::abs(L / L0 - 1.0));
    }
  return e;
}
/// Largest principal stretch of the affine map of triangle t from the cut pattern to x
/// (the square root of the larger eigenvalue of C = F^T F in the element's plane), and the
/// area ratio |x-triangle| / |pattern triangle|.
std::pair<double, double> element_stretch(const md::canopy_mesh& c, const std::vector<Eigen::Vector3d>& x,
                                          const std::array<index_t, 3>& t) {
  const auto P = [&](int a) { return c.positions[std::size_t(t[std::size_t(a)])]; };
  const auto Q = [&](int a) { return x[std::size_t(t[std::size_t(a)])]; };
  const Eigen::Vector3d E1 = P(1) - P(0), E2 = P(2) - P(0), e1 = Q(1) - Q(0), e2 = Q(2) - Q(0);
  Eigen::Matrix2d G, g;  // reference and current Gram matrices of the edge pair
  G << E1.dot(E1), E1.dot(E2), E1.dot(E2), E2.dot(E2);
  g << e1.dot(e1), e1.dot(e2), e1.dot(e2), e2.dot(e2);
  const Eigen::Matrix2d Li = Eigen::Matrix2d(G.llt().matrixL()).inverse();
  const Eigen::Matrix2d C = Li * g * Li.transpose();
  const double m = 0.5 * C.trace(), lmax = m + std::sqrt(std::max(0.0, m * m - C.determinant()));
  return {std::sqrt(lmax), e1.cross(e2).norm() / E1.cross(E2).norm()};
}
double max_radius(const std::vector<Eigen::Vector3d>& x, std::size_t n) {
  double r = 0;
  for (std::size_t i = 0; i < n; ++i) r = std::max(r, x[i].head<2>().norm());
  return r;
}
}  // namespace

TEST_CASE("packed shapes keep the reference and meet the requested radius scale") {
  const auto c = md::flat_circular_canopy({});
  const auto flat = md::packed_positions(c, md::packed_shape::constructed());
  CHECK(max_edge_strain(c, flat) == 0.0);
  for (double s : {0.1, 0.2, 0.3}) {
    const auto x = md::packed_positions(c, md::packed_shape::reduced_radius(s));
    CHECK(max_radius(x, x.size()) == doctest::Approx(s * c.skirt_radius).epsilon(1e-12));
    for (std::size_t i = 0; i < x.size(); ++i) {
      CHECK(x[i].head<2>().norm() == doctest::Approx(s * c.positions[i].head<2>().norm()).epsilon(1e-12));
      CHECK(x[i].z() == c.positions[i].z());
    }
  }
  // Star fold: isometric (every edge keeps its length), seams on the cone of half-angle theta_s.
  for (double deg : {0.0, 3.0, 10.0}) {
    const double ts = deg * std::numbers::pi / 180;
    const auto x = md::packed_positions(c, md::packed_shape::star_fold(ts));
    const double e = max_edge_strain(c, x);
    std::printf("star fold theta_s = %4.1f deg: theta_m = %.2f deg, max |edge strain| = %.2e, radius %.4f m\n", deg,
                md::star_fold_centreline_angle(8, ts) * 180 / std::numbers::pi, e, max_radius(x, x.size()));
    CHECK(e < 1e-12);
    for (const auto& seam : c.seams)
      for (const index_t i : seam) {
        const Eigen::Vector3d p = x[std::size_t(i)];
        CHECK(std::atan2(p.head<2>().norm(), -p.z()) == doctest::Approx(ts).epsilon(1e-9));
      }
  }
  CHECK_THROWS_WITH_AS(md::packed_positions(c, md::packed_shape::reduced_radius(0.0)),
                       doctest::Contains("scale s must be in (0, 1], got 0"), pf::invalid_input);
  CHECK_THROWS_WITH_AS(md::packed_positions(c, md::packed_shape::reduced_radius(1.5)), doctest::Contains("got 1.5"),
                       pf::invalid_input);
}

// Bundle at line stretch: the half-gore map (packed_shape.hpp) keeps every element within
// its reference (largest principal stretch exactly 1, in one direction), shrinks each
// element's area by the same factor |S x M| / |e x m|, keeps the normals pointing outwards
// from the axis, puts the skirt corners on the mouth circle and leaves every tape and band
// no longer than its rest length.
TEST_CASE("bundle: no element stretched, the mouth diameter, area ratio, outward normals") {
  for (int gores : {8, 28}) {
    md::canopy_parameters cp;
    cp.gores = gores;
    cp.element_size = gores == 8 ? 0.0333 : 0.05;  // the drop's coarse element; C-9 proportions
    const auto c = md::flat_circular_canopy(cp);
    const double pi = std::numbers::pi, a = std::cos(pi / gores);
    for (double d : {0.01, 0.05, 0.1, 0.5}) {
      const auto x = md::packed_positions(c, md::packed_shape::bundle(d));
      const double rho = 0.5 * d / c.skirt_radius, zeta = std::cos(0.5 * pi / gores) * std::sqrt(1 - rho * rho);
      const double area = std::sqrt((1 - a) * rho * rho * ((1 + a) * rho * rho + 2 * zeta * zeta)) /
                          std::sin(pi / gores);
      double smax = 0, amin = 1e300, amax = 0, outward = 1;
      for (const auto& t : c.triangles) {
        const auto [stretch, ratio] = element_stretch(c, x, t);
        smax = std::max(smax, stretch);
        amin = std::min(amin, ratio);
        amax = std::max(amax, ratio);
        const auto X = [&](int k) { return x[std::size_t(t[std::size_t(k)])]; };
        const Eigen::Vector3d n = (X(1) - X(0)).cross(X(2) - X(0)).normalized(), m = (X(0) + X(1) + X(2)) / 3;
        outward = std::min(outward, n.head<2>().dot(m.head<2>().normalized()));
      }
      std::printf(
          "bundle N = %2d, d = %.2f D0: max principal stretch - 1 = %.1e, area ratio %.5f..%.5f (%.5f), "
          "min outward normal %.3f, height %.4f m\n",
          gores, d, smax - 1, amin, amax, area, outward, -x[std::size_t(c.line_attachment[0])].z());
      CHECK(smax - 1 <= 1e-12);
      CHECK(smax - 1 >= -1e-12);  // taut along one direction: at its reference length
      CHECK(amin == doctest::Approx(area).epsilon(1e-9));
      CHECK(amax == doctest::Approx(area).epsilon(1e-9));
      CHECK(outward > 0.8);
      // Mouth: every skirt corner (line attachment) on the circle of diameter d D0, at the
      // same height zeta R_s below the vent centre; the vent centre stays at the apex.
      for (const index_t i : c.line_attachment) {
        CHECK(2 * x[std::size_t(i)].head<2>().norm() == doctest::Approx(d * cp.nominal_diameter).epsilon(1e-12));
        CHECK(-x[std::size_t(i)].z() == doctest::Approx(zeta * c.skirt_radius).epsilon(1e-12));
      }
      CHECK(x[std::size_t(c.vent_centre)].norm() == 0.0);
      // Seams and centrelines at sqrt(rho^2 + zeta^2) of their reference lengths.
      for (const auto& seam : c.seams) {
        const double L0 = (c.positions[std::size_t(seam.back())] - c.positions[std::size_t(seam.front())]).norm();
        const double L = (x[std::size_t(seam.back())] - x[std::size_t(seam.front())]).norm();
        CHECK(L / L0 == doctest::Approx(std::hypot(rho, zeta)).epsilon(1e-12));
      }
      // Tapes and bands: none longer than its rest length in the cut pattern.
      for (const auto* segs : {&c.skirt_tape, &c.vent_tape, &c.band_segments})
        for (const auto& e : *segs) {
          const double L0 = (c.positions[std::size_t(e[1])] - c.positions[std::size_t(e[0])]).norm();
          CHECK((x[std::size_t(e[1])] - x[std::size_t(e[0])]).norm() <= L0 * (1 + 1e-12));
        }
    }
  }
  const auto c = md::flat_circular_canopy({});
  CHECK_THROWS_WITH_AS(md::packed_positions(c, md::packed_shape::bundle(0.005)),
                       doctest::Contains("bundle mouth diameter d/D0 must be in [0.01, 0.5], got 0.005"),
                       pf::invalid_input);
  CHECK_THROWS_WITH_AS(md::packed_positions(c, md::packed_shape::bundle(0.75)), doctest::Contains("got 0.75"),
                       pf::invalid_input);
}

TEST_CASE("paper scene: lengths, confluence, masses, attachments, reference geometry") {
  for (auto shape : {md::packed_shape::constructed(), md::packed_shape::reduced_radius(0.2),
                     md::packed_shape::star_fold(5 * std::numbers::pi / 180), md::packed_shape::bundle(0.1)}) {
    auto p = md::drop_scene_parameters::paper("mat59225");
    p.shape = shape;
    const auto s = md::build_drop_scene(p);
    const int N = 8;
    const double Ls = 1.0, Lr = 0.08;
    CHECK(p.line_length() == 1.0);
    CHECK(p.riser_length() == pft::rel(0.08, 1e-12));
    // Lines: N lines, each Ls in rest length and in straight length, ending at the confluence.
    const auto& L = s.cable(md::cable_kind::suspension_line);
    CHECK(L.segments.size() == std::size_t(N * p.line_segments));
    CHECK(L.total_rest_length() == doctest::Approx(N * Ls).epsilon(1e-12));
    REQUIRE(s.suspension.lines.size() == std::size_t(N));
    for (std::size_t k = 0; k < std::size_t(N); ++k) {
      const auto& path = s.suspension.lines[k];
      // Every line starts at a skirt node of a seam (its line attachment node).
      CHECK(path.front() == s.canopy.line_attachment[k]);
      const unsigned tag = s.canopy.node_tag[std::size_t(path.front())];
      CHECK((tag & md::canopy_tag::skirt));
      CHECK((tag & md::canopy_tag::seam));
      CHECK(path.back() == s.suspension.confluence);
      CHECK((s.positions[std::size_t(path.back())] - s.positions[std::size_t(path.front())]).norm() ==
            doctest::Approx(Ls).epsilon(1e-12));
    }
    // Riser: confluence to hanging point, Lr long, hanging point at the payload's r_T.
    const auto& R = s.cable(md::cable_kind::riser);
    CHECK(R.total_rest_length() == doctest::Approx(Lr).epsilon(1e-12));
    CHECK((s.positions[std::size_t(s.suspension.hanging_point)] - s.positions[std::size_t(s.suspension.confluence)])
              .norm() == doctest::Approx(Lr).epsilon(1e-12));
    REQUIRE(s.attachments.size() == 1);
    CHECK(s.attachments[0].node == s.suspension.hanging_point);
    CHECK((s.payload.hanging_point_world() - s.positions[std::size_t(s.suspension.hanging_point)]).norm() < 1e-12);
    CHECK((s.payload.position - Eigen::Vector3d(0, 0, 35)).norm() < 1e-12);
    CHECK(s.payload.mass == 1.8);
    CHECK(s.payload.hanging_point.z() == pft::rel(0.05, 1e-12));
    CHECK(s.payload.inertia_diagonal.x() == pft::rel(1.8 / 12 * (0.15 * 0.15 + 0.1 * 0.1), 1e-12));
    // Confluence distance from the skirt plane: sqrt(Ls^2 - rho^2), rho the packed skirt corner radius.
    const double rho =
        (s.frame.conjugate() * (s.positions[std::size_t(s.canopy.line_attachment[0])] - s.offset)).head<2>().norm();
    const double zs = (s.positions[std::size_t(s.canopy.line_attachment[0])] - s.offset).z();
    const double zc = (s.positions[std::size_t(s.suspension.confluence)] - s.offset).z();
    CHECK(zs - zc == doctest::Approx(std::sqrt(Ls * Ls - rho * rho)).epsilon(1e-12));
    // Vertical drop at rest: axis +z, velocities zero.
    CHECK((s.axis() - Eigen::Vector3d::UnitZ()).norm() < 1e-12);
    for (const auto& v : s.velocities) CHECK(v.norm() == 0.0);
    // Reference geometry = the cut pattern (rigidly placed): area and lengths unchanged.
    double Aref = 0;
    for (const auto& t : s.triangles)
      Aref += 0.5 * (s.reference[std::size_t(t[1])] - s.reference[std::size_t(t[0])])
                        .cross(s.reference[std::size_t(t[2])] - s.reference[std::size_t(t[0])])
                        .norm();
    CHECK(Aref == doctest::Approx(std::numbers::pi / 4 * (1 - 0.01)).epsilon(1e-12));
    // Masses: cloth = areal density x reference area; total = cloth + tapes + bands + lines + riser + payload.
    double cloth = 0;
    for (index_t i = 0; i < s.canopy_nodes; ++i) cloth += s.lumped_mass[std::size_t(i)];
    double cables = 0;
    for (const auto& cs : s.cables) cables += cs.material.mass_per_length * cs.total_rest_length();
    CHECK(s.canopy_cloth_mass() == doctest::Approx(0.080 * std::numbers::pi / 4 * 0.99).epsilon(1e-12));
    CHECK(s.total_mass() == doctest::Approx(1.8 + s.canopy_cloth_mass() + cables).epsilon(1e-12));
    CHECK(cloth > s.canopy_cloth_mass());  // cloth + tapes/bands on canopy nodes
    // Skirt tape rest length = gore polygon perimeter.
    const double Rs = s.canopy.skirt_radius;
    CHECK(s.cable(md::cable_kind::skirt_tape).total_rest_length() ==
          doctest::Approx(2 * N * Rs * std::sin(std::numbers::pi / N)).epsilon(1e-12));
    CHECK(s.cable(md::cable_kind::radial_band).segments.size() > 0);
    // Riser = N lines in parallel.
    CHECK(R.material.EA() == doctest::Approx(N * L.material.EA()));
    // Element arrays in the forms the structure module takes.
    CHECK(s.warp.size() == s.triangles.size());
    CHECK(s.reference.size() == s.positions.size());
    CHECK(s.point_mass.size() == s.positions.size());
    for (const auto& cs : s.cables) CHECK(cs.rest_length.size() == cs.segments.size());
    // Packed radius scale in the scene.
    if (shape.kind == md::packed_kind::reduced_radius) CHECK(rho == doctest::Approx(0.2 * Rs).epsilon(1e-12));
    if (shape.kind == md::packed_kind::bundle) {
      // Line stretch: the skirt corners on the mouth circle (0.1 D0), every line segment at
      // its rest length (relative 1e-12: a tension below EA 1e-12 = 1.4e-9 N), so the lines
      // and the riser start straight and just taut; the canopy from its skirt corners to
      // its vent centre inside the fluid box's refined block.
      CHECK(2 * rho == doctest::Approx(0.1).epsilon(1e-12));
      for (const auto k : {md::cable_kind::suspension_line, md::cable_kind::riser}) {
        const auto& cs = s.cable(k);
        for (std::size_t e = 0; e < cs.segments.size(); ++e) {
          const double l =
              (s.positions[std::size_t(cs.segments[e][1])] - s.positions[std::size_t(cs.segments[e][0])]).norm();
          CHECK(l == doctest::Approx(cs.rest_length[e]).epsilon(1e-12));
        }
      }
      const md::drop_box b = md::make_drop_box(s, md::drop_box_parameters{});
      for (index_t i = 0; i < s.canopy_nodes; ++i) {
        const Eigen::Vector3d xi = b.axes.transpose() * (s.positions[std::size_t(i)] - s.payload.position);
        for (int d = 0; d < 3; ++d) {
          CHECK(xi[d] >= b.fine_lo[std::size_t(d)]);
          CHECK(xi[d] <= b.fine_hi[std::size_t(d)]);
        }
      }
    }
    std::printf(
        "paper scene (%s): %ld nodes, %zu triangles, cloth %.4f kg, total %.4f kg, line EA %.0f N, "
        "confluence %.4f m below skirt\n",
        shape.name(), s.node_count(), s.triangles.size(), s.canopy_cloth_mass(), s.total_mass(), L.material.EA(),
        zs - zc);
  }
}

TEST_CASE("scene: flight-path angle rotates the axis against the velocity") {
  auto p = md::drop_scene_parameters::paper();
  p.flight_path_angle = 30;
  p.initial_speed = 20;
  const auto s = md::build_drop_scene(p);
  const Eigen::Vector3d vhat(std::cos(std::numbers::pi / 6), 0, -std::sin(std::numbers::pi / 6));
  CHECK((s.axis() + vhat).norm() < 1e-12);
  CHECK((s.payload.velocity - 20 * vhat).norm() < 1e-12);
  CHECK((s.velocities[0] - 20 * vhat).norm() < 1e-12);
  // The canopy is up-stream (behind) the payload along the flight direction.
  CHECK((s.positions[std::size_t(s.canopy.vent_centre)] - s.payload.position).dot(vhat) < -1.0);
}

TEST_CASE("C-9 variant: 28 gores, 28 ft, 13.4 m/s") {
  const auto p = md::drop_scene_parameters::c9();
  const auto s = md::build_drop_scene(p);
  CHECK(p.canopy.gores == 28);
  CHECK(p.canopy.nominal_diameter == doctest::Approx(8.5344));
  CHECK(s.canopy.line_attachment.size() == 28);
  CHECK(s.suspension.lines.size() == 28);
  CHECK(s.canopy.bands.size() == 14);
  CHECK(s.canopy_reference_area() == doctest::Approx(std::numbers::pi / 4 * 8.5344 * 8.5344 * 0.99).epsilon(1e-12));
  CHECK(s.payload.velocity.z() == doctest::Approx(-13.4));
  CHECK(s.cable(md::cable_kind::suspension_line).total_rest_length() == doctest::Approx(28 * 8.5344).epsilon(1e-12));
  CHECK(s.cable(md::cable_kind::riser).total_rest_length() == doctest::Approx(0.08 * 8.5344).epsilon(1e-12));
  CHECK(s.fabric.name == "c9_mil_c_7020");
  std::printf(
      "C-9 scene: %ld nodes, %zu triangles, cloth %.3f kg, total %.3f kg, fabric E*t %.0f N/m, line EA %.0f N\n",
      s.node_count(), s.triangles.size(), s.canopy_cloth_mass(), s.total_mass(), s.moduli.stiffness(),
      s.cable(md::cable_kind::suspension_line).material.EA());
}

TEST_CASE("scene: bad parameters are rejected with the value named") {
  auto bad = [](auto f) {
    auto p = md::drop_scene_parameters::paper();
    f(p);
    return p;
  };
  CHECK_THROWS_WITH_AS(md::build_drop_scene(bad([](auto& p) { p.canopy.gores = 1; })), doctest::Contains("got 1"),
                       pf::invalid_input);
  CHECK_THROWS_WITH_AS(md::build_drop_scene(bad([](auto& p) { p.canopy.vent_ratio = 1.2; })),
                       doctest::Contains("got 1.2"), pf::invalid_input);
  CHECK_THROWS_WITH_AS(md::build_drop_scene(bad([](auto& p) { p.payload.mass = -2; })),
                       doctest::Contains("mass must be > 0, got -2"), pf::invalid_input);
  CHECK_THROWS_WITH_AS(md::build_drop_scene(bad([](auto& p) { p.line_length_ratio = -1; })),
                       doctest::Contains("got -1"), pf::invalid_input);
  CHECK_THROWS_WITH_AS(md::build_drop_scene(bad([](auto& p) {
                         p.shape = md::packed_shape::constructed();
                         p.line_length_ratio = 0.5;
                       })),
                       doctest::Contains("shorter than the attachment radius"), pf::invalid_input);
  CHECK_THROWS_WITH_AS(md::build_drop_scene(bad([](auto& p) { p.riser_ratio = 0; })),
                       doctest::Contains("riser ratio Lr/Ls must be > 0, got 0"), pf::invalid_input);
  CHECK_THROWS_WITH_AS(md::build_drop_scene(bad([](auto& p) { p.line_segments = 0; })), doctest::Contains("got 0"),
                       pf::invalid_input);
  CHECK_THROWS_WITH_AS(md::build_drop_scene(bad([](auto& p) { p.fabric = "silk"; })),
                       doctest::Contains("unknown fabric 'silk'"), pf::invalid_input);
  CHECK_THROWS_WITH_AS(md::build_drop_scene(bad([](auto& p) { p.line.elongation = -0.25; })),
                       doctest::Contains("suspension line): elongation at break must be > 0, got -0.25"),
                       pf::invalid_input);
  CHECK_THROWS_WITH_AS(md::build_drop_scene(bad([](auto& p) { p.payload.size.x() = -0.1; })),
                       doctest::Contains("got -0.1"), pf::invalid_input);
}

#include <parafsi/structure/from_drop_scene.hpp>

TEST_CASE("scene data plugs into the structure module as is; lumped masses match") {
  namespace st = parafsi::structure;
  const auto s = md::build_drop_scene(md::drop_scene_parameters::paper());
  // The membrane damping is irrelevant here (50 steps of free fall).
  auto chute = st::make_drop_assembly(s, 0.05);
  for (index_t i = 0; i < s.node_count(); ++i)
    CHECK(chute.node_set().mass(i) == pft::rel(s.lumped_mass[std::size_t(i)], 1e-12));
  // The parts by name are the parts by position (0 membrane, 1-5 cables, 6 payload).
  CHECK(static_cast<const void*>(&st::canopy(chute)) == &chute.part<0>());
  CHECK(static_cast<const void*>(&st::suspension_lines(chute)) == &chute.part<1>());
  CHECK(static_cast<const void*>(&st::riser(chute)) == &chute.part<2>());
  CHECK(static_cast<const void*>(&st::skirt_tape(chute)) == &chute.part<3>());
  CHECK(static_cast<const void*>(&st::vent_tape(chute)) == &chute.part<4>());
  CHECK(static_cast<const void*>(&st::radial_bands(chute)) == &chute.part<5>());
  CHECK(static_cast<const void*>(&st::payload(chute)) == &chute.part<6>());
  const st::drop_assembly& cchute = chute;
  CHECK(&st::payload(cchute).body() == &st::payload(chute).body());
  CHECK(st::riser(chute).size() == index_t(s.cable(md::cable_kind::riser).segments.size()));
  // The body received the hanging node's lumped mass.
  CHECK(st::payload(chute).body().mass() ==
        pft::rel(s.payload.mass + s.lumped_mass[std::size_t(s.suspension.hanging_point)], 1e-12));
  const double dt = chute.stable_dt();
  std::printf("assembly from the scene: stable structural step %.3e s\n", dt);
  CHECK(dt > 1e-6);
  for (int n = 0; n < 50; ++n) chute.step(dt);
  CHECK(std::isfinite(st::payload(chute).body().position().z()));
  // Free fall for 50 steps: everything falls together (no strain yet from a reduced-radius start).
  const double t = chute.time();
  CHECK(st::payload(chute).body().position().z() == doctest::Approx(35.0 - 0.5 * 9.81 * t * t).epsilon(1e-6));
}

// ------------------------------------------------------------------ fluid box
#include <parafsi/fluid/grid.hpp>
#include <parafsi/model/drop_box.hpp>

TEST_CASE("drop box: extents, refined block, axes and size from the scene") {
  auto P = md::drop_scene_parameters::paper();
  const auto R = md::drop_resolution::preset("coarse");
  P.canopy.element_size = R.element * P.canopy.nominal_diameter;
  const auto s = md::build_drop_scene(P);
  md::drop_box_parameters bp;  // 5 x 5 x 7 D0, 1.5 D0 ahead
  bp.cell = R.cell;
  bp.growth = R.growth;
  const md::drop_box b = md::make_drop_box(s, bp);
  // D0 = 1 m: the numbers of the file comment, exactly.
  const double zc = (s.positions[std::size_t(s.suspension.confluence)] - s.payload.position).z();
  // The confluence: the riser (0.08 Ls) above the hanging point (half the payload's 0.10 m).
  CHECK(zc == doctest::Approx(0.08 + 0.05).epsilon(1e-12));
  CHECK(b.lo == std::array<double, 3>{-2.5, -2.5, -1.5});
  CHECK(b.hi == std::array<double, 3>{2.5, 2.5, 5.5});
  CHECK(b.fine_lo == std::array<double, 3>{-0.6, -0.6, zc + 0.55});
  CHECK(b.fine_hi == std::array<double, 3>{0.6, 0.6, zc + 1.0 + 0.55});
  CHECK(b.cell == 0.0667);
  CHECK(b.growth == 1.2);
  CHECK((b.axes - Eigen::Matrix3d::Identity()).norm() < 1e-15);  // vertical drop: the world axes
  // The estimate against the grid built from these numbers: the coarse box is 38^3 =
  // 54 872 cells (docs/validation.md §8); the estimate is within a cell per axis.
  index_t n[3];
  for (std::size_t d = 0; d < 3; ++d) {
    n[d] = pf::fluid::axis::refined(b.lo[d], b.hi[d], b.fine_lo[d], b.fine_hi[d], b.cell, b.growth).cells();
    CHECK(std::abs(b.cells_estimate[d] - double(n[d])) <= 1.0);
  }
  CHECK(n[0] * n[1] * n[2] == 54872);

  // Fixed box: the bottom and the refined column lowered by the fall, the top unchanged.
  bp.fall = 10.0;
  const md::drop_box f = md::make_drop_box(s, bp);
  CHECK(f.lo[2] == -11.5);
  CHECK(f.fine_lo[2] == (zc + 0.55) - 10.0);
  CHECK(f.hi[2] == b.hi[2]);
  CHECK(f.fine_hi[2] == b.fine_hi[2]);
  CHECK(f.fall == 10.0);

  // A grid offset moves the box and its refined block along the axis by offset · h, the
  // rest unchanged; outside [0, 1) cells it is refused by value.
  bp.fall = 0.0;
  bp.offset = 0.25;
  const md::drop_box o = md::make_drop_box(s, bp);
  const double dz = 0.25 * 0.0667;
  CHECK(o.lo[2] == doctest::Approx(b.lo[2] + dz).epsilon(1e-14));
  CHECK(o.hi[2] == doctest::Approx(b.hi[2] + dz).epsilon(1e-14));
  CHECK(o.fine_lo[2] == doctest::Approx(b.fine_lo[2] + dz).epsilon(1e-14));
  CHECK(o.fine_hi[2] == doctest::Approx(b.fine_hi[2] + dz).epsilon(1e-14));
  CHECK((o.lo[0] == b.lo[0] && o.hi[1] == b.hi[1] && o.fine_lo[0] == b.fine_lo[0]));
  bp.offset = 1.0;
  CHECK_THROWS_WITH_AS(md::make_drop_box(s, bp), doctest::Contains("grid offset must be in [0, 1) cells, got 1"),
                       pf::invalid_input);
  bp.offset = 0.0;

  // A slanted flight path: orthonormal axes, z_b along the canopy axis, y_b = ŷ (the
  // horizontal normal of the flight plane x–z).
  auto Q = P;
  Q.flight_path_angle = 30;
  const auto sq = md::build_drop_scene(Q);
  const md::drop_box q = md::make_drop_box(sq, md::drop_box_parameters{});
  CHECK((q.axes.transpose() * q.axes - Eigen::Matrix3d::Identity()).norm() < 1e-14);
  CHECK(q.axes.determinant() == doctest::Approx(1.0).epsilon(1e-14));
  CHECK((q.axes.col(2) - sq.axis()).norm() < 1e-14);
  CHECK((q.axes.col(1) - Eigen::Vector3d::UnitY()).norm() < 1e-14);
}

TEST_CASE("drop box as blocks: the finest cell is h, the root blocks cover the box, levels from the block size") {
  auto P = md::drop_scene_parameters::paper();
  const auto R = md::drop_resolution::preset("coarse");
  P.canopy.element_size = R.element * P.canopy.nominal_diameter;
  const auto s = md::build_drop_scene(P);
  md::drop_box_parameters bp;  // 5 x 5 x 7 D0
  bp.cell = R.cell;
  const md::drop_box b = md::make_drop_box(s, bp);
  // L the largest with `across` root blocks of n 2^L h within the narrowest side (5 m):
  // 5 / (2 * 8 * 0.0667) = 4.69 -> L = 2; 5 / (1 * 16 * 0.0667) = 4.69 -> L = 2 too.
  auto check = [&](int n, int across, int L_expected, index_t nb_xy) {
    const auto [lay, L] = pf::scene::make_drop_blocks(b, n, across);
    CHECK(L == L_expected);
    CHECK(lay.block_cells == n);
    for (int d = 0; d < 3; ++d) {
      CHECK(lay.cell_width(d, L) == doctest::Approx(b.cell).epsilon(1e-12));
      CHECK(lay.lo[std::size_t(d)] <= b.lo[std::size_t(d)] + 1e-12);  // the box, grown to whole root blocks
      CHECK(lay.hi[std::size_t(d)] >= b.hi[std::size_t(d)] - 1e-12);
      CHECK(0.5 * (lay.lo[std::size_t(d)] + lay.hi[std::size_t(d)]) ==
            doctest::Approx(0.5 * (b.lo[std::size_t(d)] + b.hi[std::size_t(d)])).epsilon(1e-12));
    }
    CHECK(lay.root_blocks[0] == nb_xy);
    CHECK(lay.root_blocks[1] == nb_xy);
  };
  check(8, 2, 2, 3);   // root blocks of 2.13 m: 3 across 5 m
  check(16, 2, 1, 3);  // the same root width with one level less
  check(16, 1, 2, 2);  // root blocks of 4.27 m: 2 across, the levels of the 8-cell blocks
  CHECK_THROWS_WITH_AS(pf::scene::make_drop_blocks(b, 8, 0), doctest::Contains("across >= 1"), pf::invalid_input);
}

TEST_CASE("drop canopy travel: the travel limit's cells, or twice the fastest node's path over the window plus one") {
  // A fluid's layout and pose are all the bound reads: blocks of 8 cells, h = 0.05 m on level 2.
  struct fluid_like {
    pf::fluid::block_layout lay{{-2.4, -2.4, -2.4}, {2.4, 2.4, 2.4}, {3, 3, 3}, 8};
    pf::frame::pose p;
    const pf::fluid::block_layout& layout() const { return lay; }
    const pf::frame::pose& pose() const { return p; }
  } f;
  f.p.V = Eigen::Vector3d(0, 0, -5);     // the box falls at 5 m/s
  f.p.Omega = Eigen::Vector3d(0, 0, 2);  // and turns about its z axis at 2 rad/s
  const double h = f.lay.cell_width(0, 2);
  REQUIRE(h == pft::rel(0.05, 1e-12));
  pf::structure::nodes nd;
  nd.add({0.3, 0, 0}, {0, 0, -5});  // with the box's translation: 0.6 m/s relative (the turn at r = 0.3 m)
  nd.add({0, 0, 0}, {0, 3, -5});    // 3 m/s across the box axis: the fastest of the canopy
  nd.add({2, 0, 0}, {0, 4, -5});    // turning with the box: at rest relative to it (4 m/s if the turn were
                                    // left out, 8 if it were taken the wrong way round)
  nd.add({0, 0, 1}, {0, 40, -5});   // 40 m/s relative, not a canopy node (canopy_nodes = 3): ignored
  const double window = 2e-3;       // 3 m/s over 2 ms: 6 mm, 0.12 cells
  CHECK(pf::scene::drop_canopy_travel(f, nd, 3, 2, 8, window) == doctest::Approx(1.0 + 2.0 * 3.0 * window / h));
  CHECK(pf::scene::drop_canopy_travel(f, nd, 3, 2, 8, 0.0) == 8.0);     // no window: the travel limit
  CHECK(pf::scene::drop_canopy_travel(f, nd, 3, 2, 1, window) == 1.0);  // one finest step: a cell
  CHECK(pf::scene::drop_canopy_travel(f, nd, 3, 2, 4, 0.1) == 4.0);     // a long window: capped at the limit
  CHECK(pf::scene::drop_canopy_travel(f, nd, 4, 2, 100, window) == doctest::Approx(1.0 + 2.0 * 40.0 * window / h));
}

TEST_CASE("drop box and canopy: sizes that would overflow a count or the memory are refused first") {
  const auto s = md::build_drop_scene(md::drop_scene_parameters::paper());
  md::drop_box_parameters bp;
  bp.cell = 1e-300;
  CHECK_THROWS_WITH_AS(md::make_drop_box(s, bp), doctest::Contains("would have more than 1e308 cells"),
                       pf::invalid_input);
  bp.cell = 1e-3;  // about 1.6e9 cells
  CHECK_THROWS_WITH_AS(md::make_drop_box(s, bp), doctest::Contains("would have about 1."), pf::invalid_input);
  bp.cell = 0.0667;
  bp.max_cells = 1000;
  CHECK_THROWS_WITH_AS(md::make_drop_box(s, bp), doctest::Contains("more than the limit of 1000 cells"),
                       pf::invalid_input);
  bp = {};
  bp.ahead = 8.0;  // longer than the box
  CHECK_THROWS_WITH_AS(md::make_drop_box(s, bp), doctest::Contains("ahead of the payload"), pf::invalid_input);
  auto P = md::drop_scene_parameters::paper();
  P.canopy.element_size = 1e-300;
  CHECK_THROWS_WITH_AS(md::build_drop_scene(P), doctest::Contains("would give more than 1e308 triangles"),
                       pf::invalid_input);
  P.canopy.element_size = 2e-4;  // an estimate of about 8e7 triangles: under the limit of 1e8 (not built here)
  CHECK_NOTHROW(P.canopy.validate());
  P.canopy.max_triangles = 1e4;
  CHECK_THROWS_WITH_AS(P.canopy.validate(), doctest::Contains("more than the limit of 10000"), pf::invalid_input);
  CHECK_THROWS_WITH_AS(md::drop_resolution::preset("ultra"), doctest::Contains("unknown resolution 'ultra'"),
                       pf::invalid_input);
}

TEST_CASE("duct screen: cubic cells, the sheet spans the cross-section at x_s with normal +x; bad input rejected") {
  const auto d = md::duct_screen(2.0, 100, 0.5);
  CHECK(d.cells == std::array<index_t, 3>{100, 2, 2});
  CHECK(d.width == 0.04);  // 2 L / cells: two cells of 2 cm across
  CHECK(d.hi[0] == 2.0);
  CHECK(d.hi[1] == d.width);
  CHECK(d.hi[2] == d.width);
  CHECK(d.hi[0] / d.cells[0] == doctest::Approx(d.hi[1] / d.cells[1]).epsilon(1e-15));  // cubic cells
  REQUIRE(d.sheet.positions.size() == 9);
  REQUIRE(d.sheet.triangles.size() == 8);
  CHECK(d.sheet.edge.size() == 8);
  double area = 0;
  for (const auto& t : d.sheet.triangles) {
    const Eigen::Vector3d a = d.sheet.positions[std::size_t(t[0])], b = d.sheet.positions[std::size_t(t[1])],
                          c = d.sheet.positions[std::size_t(t[2])];
    const Eigen::Vector3d n = 0.5 * (b - a).cross(c - a);
    CHECK(n.x() > 0);  // counter-clockwise about +x
    CHECK(std::abs(n.y()) + std::abs(n.z()) == 0.0);
    area += n.norm();
  }
  CHECK(area == doctest::Approx(d.area()).epsilon(1e-14));
  CHECK(d.area() == doctest::Approx(0.04 * 0.04).epsilon(1e-15));
  for (const auto& x : d.sheet.positions) {
    CHECK(x.x() == 0.5);
    CHECK(x.y() >= 0.0);
    CHECK(x.y() <= d.width);
    CHECK(x.z() >= 0.0);
    CHECK(x.z() <= d.width);
  }
  CHECK(d.sheet.positions[4].isApprox(Eigen::Vector3d(0.5, 0.02, 0.02)));  // the free centre node
  std::string msg;
  try {
    md::duct_screen(1.0, 40, 1.5);
  } catch (const pf::invalid_input& e) {
    msg = e.what();
  }
  CHECK(msg.find("model::duct_screen") != std::string::npos);
  CHECK(msg.find("1.5") != std::string::npos);
  CHECK_THROWS_AS(md::duct_screen(1.0, 1, 0.5), pf::invalid_input);
  CHECK_THROWS_AS(md::duct_screen(-1.0, 40, 0.5), pf::invalid_input);
  // Inclined by 30° about z in a duct 8 cells wide: area W_y W / cos θ, normal (cos θ, −sin θ, 0).
  const auto q = md::duct_screen(1.0, 40, 0.5, 2, 30.0, 8);
  CHECK(q.cells == std::array<index_t, 3>{40, 8, 2});
  CHECK(q.width_y == doctest::Approx(0.2).epsilon(1e-15));
  CHECK(q.sheet_area() == doctest::Approx(0.2 * 0.05 / std::cos(M_PI / 6)).epsilon(1e-14));
  double qa = 0;
  for (const auto& t : q.sheet.triangles) {
    const Eigen::Vector3d a = q.sheet.positions[std::size_t(t[0])], b = q.sheet.positions[std::size_t(t[1])],
                          c = q.sheet.positions[std::size_t(t[2])];
    const Eigen::Vector3d n = 0.5 * (b - a).cross(c - a);
    CHECK(n.normalized().isApprox(Eigen::Vector3d(std::cos(M_PI / 6), -std::sin(M_PI / 6), 0.0), 1e-14));
    qa += n.norm();
  }
  CHECK(qa == doctest::Approx(q.sheet_area()).epsilon(1e-14));
  for (const auto& x : q.sheet.positions) {
    CHECK(x.x() >= 0.5 - 0.1 * std::tan(M_PI / 6) - 1e-15);
    CHECK(x.x() <= 0.5 + 0.1 * std::tan(M_PI / 6) + 1e-15);
  }
  CHECK_THROWS_AS(md::duct_screen(1.0, 40, 0.5, 2, 85.0, 8), pf::invalid_input);
  CHECK_THROWS_AS(md::duct_screen(1.0, 40, 0.5, 2, 0.0, 3), pf::invalid_input);
}
