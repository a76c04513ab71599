// Flat circular canopy builder and fabric moduli: areas, lengths, tags, fibres, rejection.
#include <doctest/doctest.h>

#include "approx.hpp"

#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <set>

#include <parafsi/model/fabric_catalogue.hpp>
#include <parafsi/model/flat_circular_canopy.hpp>

namespace pf = parafsi;
namespace md = parafsi::model;
using pf::index_t;

namespace {
double tri_quality(const md::canopy_mesh& c, const std::array<index_t, 3>& t) {
  const auto& X = c.positions;
  const Eigen::Vector3d a = X[std::size_t(t[0])], b = X[std::size_t(t[1])], d = X[std::size_t(t[2])];
  const double A2 = (b - a).cross(d - a).norm();
  return 2.0 * std::sqrt(3.0) * A2 / ((b - a).squaredNorm() + (d - b).squaredNorm() + (a - d).squaredNorm());
}
}  // namespace

TEST_CASE("canopy: area equals the polygonal closed form, and pi/4 (D0^2 - Dv^2) on the nominal-area basis") {
  for (int N : {3, 8, 28}) {
    for (auto basis : {md::diameter_basis::nominal_area, md::diameter_basis::corners}) {
      md::canopy_parameters p;
      p.gores = N;
      p.basis = basis;
      p.element_size = N == 28 ? 0.03 : 0.05;
      const auto c = md::flat_circular_canopy(p);
      const double A = c.reference_area();
      // The pattern is the polygon exactly, so the only error is round-off.
      CHECK(A == doctest::Approx(c.polygon_area()).epsilon(1e-12));
      if (basis == md::diameter_basis::nominal_area) {
        CHECK(A == doctest::Approx(c.circle_area()).epsilon(1e-12));
      } else {
        const double ratio = std::sin(2 * std::numbers::pi / N) / (2 * std::numbers::pi / N);
        CHECK(A / c.circle_area() == doctest::Approx(ratio).epsilon(1e-12));
      }
      std::printf("N=%2d basis=%s: %zu triangles, %ld nodes, area %.12f, circle %.12f, ratio %.6f\n", N,
                  basis == md::diameter_basis::corners ? "corners" : "nominal", c.triangles.size(), c.node_count(), A,
                  c.circle_area(), A / c.circle_area());
    }
  }
}

TEST_CASE("canopy: triangles counter-clockwise, good quality, every triangle in one gore, warp along the centreline") {
  md::canopy_parameters p;
  const auto c = md::flat_circular_canopy(p);
  double qmin = 1;
  for (std::size_t e = 0; e < c.triangles.size(); ++e) {
    const auto& t = c.triangles[e];
    const auto& X = c.positions;
    const double z =
        (X[std::size_t(t[1])] - X[std::size_t(t[0])]).cross(X[std::size_t(t[2])] - X[std::size_t(t[0])]).z();
    REQUIRE(z > 0);
    qmin = std::min(qmin, tri_quality(c, t));
    // Warp = unit vector along the gore centreline; the triangle's centroid is inside its gore.
    const int k = c.gore[e];
    const double th = 2 * std::numbers::pi * (k + 0.5) / p.gores;
    CHECK(c.warp[e].dot(Eigen::Vector3d(std::cos(th), std::sin(th), 0)) == doctest::Approx(1.0));
    const Eigen::Vector3d g = (X[std::size_t(t[0])] + X[std::size_t(t[1])] + X[std::size_t(t[2])]) / 3.0;
    double phi = std::atan2(g.y(), g.x());
    if (phi < 0) phi += 2 * std::numbers::pi;
    CHECK(int(std::floor(phi / (2 * std::numbers::pi / p.gores))) == k);
  }
  std::printf("default canopy: %zu triangles, min quality %.3f\n", c.triangles.size(), qmin);
  CHECK(qmin > 0.3);
  // Bias construction: warp at 45 degrees to the centreline.
  p.fibre_angle = std::numbers::pi / 4;
  const auto b = md::flat_circular_canopy(p);
  const double th = std::numbers::pi / p.gores;
  CHECK(b.warp[0].dot(Eigen::Vector3d(std::cos(th), std::sin(th), 0)) == doctest::Approx(std::sqrt(0.5)));
}

TEST_CASE("canopy: each mesh edge is shared by at most two triangles; boundary = skirt + vent polygons") {
  const auto c = md::flat_circular_canopy({});
  std::map<std::pair<index_t, index_t>, int> edges;
  for (const auto& t : c.triangles)
    for (int a = 0; a < 3; ++a) {
      index_t u = t[std::size_t(a)], v = t[std::size_t((a + 1) % 3)];
      if (u > v) std::swap(u, v);
      ++edges[{u, v}];
    }
  std::set<std::pair<index_t, index_t>> boundary;
  for (const auto& [e, n] : edges) {
    REQUIRE(n <= 2);
    if (n == 1) boundary.insert(e);
  }
  std::set<std::pair<index_t, index_t>> tapes;
  for (const auto& s : c.skirt_tape) tapes.insert({std::min(s[0], s[1]), std::max(s[0], s[1])});
  for (const auto& s : c.vent_tape) tapes.insert({std::min(s[0], s[1]), std::max(s[0], s[1])});
  CHECK(boundary == tapes);
}

TEST_CASE("canopy: skirt and vent tape lengths are the polygon perimeters; bands run seam to seam through the vent") {
  for (int N : {8, 28, 7}) {
    md::canopy_parameters p;
    p.gores = N;
    p.element_size = 0.04;
    const auto c = md::flat_circular_canopy(p);
    const double s = 2 * N * std::sin(std::numbers::pi / N);
    CHECK(c.length(c.skirt_tape) == doctest::Approx(s * c.skirt_radius).epsilon(1e-12));
    CHECK(c.length(c.vent_tape) == doctest::Approx(s * c.vent_radius).epsilon(1e-12));
    const double seam = c.skirt_radius - c.vent_radius;
    if (N % 2 == 0) {
      REQUIRE(c.bands.size() == std::size_t(N / 2));
      REQUIRE(c.vent_centre >= 0);
      // Total band length: N seams + N/2 vent diameters (corner to corner).
      CHECK(c.length(c.band_segments) == doctest::Approx(N * seam + N / 2 * 2 * c.vent_radius).epsilon(1e-12));
      for (std::size_t j = 0; j < c.bands.size(); ++j) {
        CHECK(c.bands[j].front() == c.line_attachment[j]);
        CHECK(c.bands[j].back() == c.line_attachment[j + std::size_t(N / 2)]);
        CHECK(std::count(c.bands[j].begin(), c.bands[j].end(), c.vent_centre) == 1);
      }
    } else {
      CHECK(c.vent_centre == -1);
      CHECK(c.bands.size() == std::size_t(N));
      CHECK(c.length(c.band_segments) == doctest::Approx(N * seam).epsilon(1e-12));
    }
  }
}

TEST_CASE("canopy: tags are consistent") {
  const auto c = md::flat_circular_canopy({});
  const int N = c.params.gores;
  REQUIRE(c.line_attachment.size() == std::size_t(N));
  REQUIRE(c.seams.size() == std::size_t(N));
  for (int k = 0; k < N; ++k) {
    const index_t a = c.line_attachment[std::size_t(k)];
    CHECK(a == c.seams[std::size_t(k)].back());
    CHECK((c.node_tag[std::size_t(a)] & md::canopy_tag::skirt));
    CHECK((c.node_tag[std::size_t(a)] & md::canopy_tag::seam));
    CHECK((c.node_tag[std::size_t(a)] & md::canopy_tag::line_attachment));
    CHECK(c.positions[std::size_t(a)].norm() == doctest::Approx(c.skirt_radius));
    CHECK(c.positions[std::size_t(c.seams[std::size_t(k)].front())].norm() == pft::rel(c.vent_radius, 1e-12));
  }
  std::set<index_t> skirt(c.skirt.begin(), c.skirt.end()), vent(c.vent.begin(), c.vent.end());
  CHECK(skirt.size() == c.skirt.size());
  int n_attach = 0;
  for (index_t i = 0; i < c.node_count(); ++i) {
    const unsigned t = c.node_tag[std::size_t(i)];
    CHECK(bool(t & md::canopy_tag::skirt) == bool(skirt.count(i)));
    CHECK(bool(t & md::canopy_tag::vent) == bool(vent.count(i)));
    if (t & md::canopy_tag::skirt)
      CHECK(std::abs(c.positions[std::size_t(i)].norm() * std::cos(0.0)) <= c.skirt_radius + 1e-12);
    n_attach += bool(t & md::canopy_tag::line_attachment);
  }
  CHECK(n_attach == N);
  // Skirt nodes lie on the skirt polygon: distance along the gore's centreline direction = R_s cos(pi/N).
  for (const index_t i : c.skirt) {
    const Eigen::Vector3d x = c.positions[std::size_t(i)];
    double phi = std::atan2(x.y(), x.x());
    if (phi < 0) phi += 2 * std::numbers::pi;
    const double w = 2 * std::numbers::pi / N;
    const double th = (std::min(N - 1, int(std::floor(phi / w))) + 0.5) * w;
    CHECK(x.dot(Eigen::Vector3d(std::cos(th), std::sin(th), 0)) ==
          doctest::Approx(c.skirt_radius * std::cos(std::numbers::pi / N)).epsilon(1e-12));
  }
}

TEST_CASE("canopy: bad parameters are rejected with the value named") {
  auto with = [](auto f) {
    md::canopy_parameters p;
    f(p);
    return p;
  };
  CHECK_THROWS_WITH_AS(md::flat_circular_canopy(with([](auto& p) { p.gores = 2; })),
                       doctest::Contains("at least 3 gores, got 2"), pf::invalid_input);
  CHECK_THROWS_WITH_AS(md::flat_circular_canopy(with([](auto& p) { p.vent_ratio = 1.0; })),
                       doctest::Contains("vent ratio Dv/D0 must be in (0, 1) (vent smaller than D0), got 1"),
                       pf::invalid_input);
  CHECK_THROWS_WITH_AS(md::flat_circular_canopy(with([](auto& p) { p.vent_ratio = 1.5; })),
                       doctest::Contains("got 1.5"), pf::invalid_input);
  CHECK_THROWS_WITH_AS(md::flat_circular_canopy(with([](auto& p) { p.nominal_diameter = -1.0; })),
                       doctest::Contains("nominal diameter D0 must be > 0, got -1"), pf::invalid_input);
  CHECK_THROWS_WITH_AS(md::flat_circular_canopy(with([](auto& p) { p.element_size = -0.1; })),
                       doctest::Contains("element size must be > 0, got -0.1"), pf::invalid_input);
  CHECK_THROWS_WITH_AS(md::flat_circular_canopy(with([](auto& p) { p.radial_divisions = -3; })),
                       doctest::Contains("got -3"), pf::invalid_input);
}

TEST_CASE("fabric catalogue: derived moduli E t = (F_b / 5 cm) / elongation; existing API unchanged") {
  CHECK(md::fabric_catalogue.size() == 3);
  const double expect_Et[3] = {450.0 / 0.05 / 0.26, 950.0 / 0.05 / 0.24, 560.0 / 0.05 / 0.22};
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& f = md::fabric_catalogue[i];
    const auto m = md::derived_moduli(f);
    CHECK(m.stiffness() == doctest::Approx(expect_Et[i]).epsilon(1e-12));
    CHECK(m.E22 == m.E11);
    CHECK(m.G12 == doctest::Approx(m.E11 / (2 * (1 + m.nu12))));
    CHECK(m.areal_density == f.areal_density);
    CHECK(m.thickness == f.thickness);
    std::printf("%-9s E*t = %8.1f N/m  E11 = E22 = %.4g Pa  nu12 = %.2f  G12 = %.4g Pa\n", std::string(f.name).c_str(),
                m.stiffness(), m.E11, m.nu12, m.G12);
  }
  md::moduli_options o;
  o.shear_ratio = 0.05;
  o.weft_ratio = 0.8;
  o.modulus_scale = 2.0;
  const auto m = md::derived_moduli(md::fabric("mat509"), o);
  CHECK(m.E11 == doctest::Approx(2 * 560.0 / 0.05 / 0.22 / 0.17e-3));
  CHECK(m.E22 == doctest::Approx(0.8 * m.E11));
  CHECK(m.G12 == doctest::Approx(0.05 * m.E11));
  // C-9 cloth: Darcy fit exact at its test point.
  const auto& c9 = md::fabric("c9_mil_c_7020");
  CHECK(c9.thickness * (c9.alpha * c9.air_permeability + c9.beta * c9.air_permeability * c9.air_permeability) ==
        doctest::Approx(c9.test_pressure));
  o = {};
  o.nu12 = 0.75;
  CHECK_THROWS_WITH_AS(md::derived_moduli(md::fabric("mat544"), o), doctest::Contains("got 0.75"), pf::invalid_input);
  CHECK_THROWS_WITH_AS(md::fabric("mat000"), doctest::Contains("unknown fabric 'mat000'"), pf::invalid_input);
}
