// Coupling points: count and density rule, barycentric weights, location in
// uniform and stretched grids, trilinear weights (partition of unity, exact for
// linear fields), and the moving-box transform.
#include <doctest/doctest.h>

#include <parafsi/coupling/coupling.hpp>
#include <parafsi/fluid/fluid.hpp>

#include <cmath>
#include <random>

namespace pf = parafsi;
using pf::index_t;

TEST_CASE("coupling points: NQUAD from the cell size, weights, density rule") {
  const auto grid = pf::fluid::rectilinear_grid::uniform({10, 10, 10}, {0, 0, 0}, {1, 1, 1});  // h = 0.1
  const pf::coupling::grid_locator loc(grid);
  std::vector<Eigen::Vector3d> x{{0.2, 0.2, 0.5}, {0.5, 0.2, 0.5}, {0.2, 0.5, 0.5}};  // legs 0.3, L = 0.42
  pf::coupling::coupling_points pts;
  pts.build({{0, 1, 2}}, [&](index_t i) { return x[std::size_t(i)]; }, loc, pf::frame::pose{}, {});
  const int n = int(std::ceil(2 * std::sqrt(0.18) / 0.1));  // 9
  CHECK(pts.nquad(0) == n);
  CHECK(pts.size() == n * n);
  double s0 = 0, s1 = 0, s2 = 0;
  double min_gap = 1e9;
  for (index_t c = 0; c < pts.size(); ++c) {
    CHECK(pts.weight(c, 0) + pts.weight(c, 1) + pts.weight(c, 2) == doctest::Approx(1.0).epsilon(1e-15));
    for (int a = 0; a < 3; ++a) CHECK(pts.weight(c, a) > 0.0);
    s0 += pts.weight(c, 0);
    s1 += pts.weight(c, 1);
    s2 += pts.weight(c, 2);
  }
  // Sub-triangle centroids average to the centroid: each node carries a third.
  CHECK(s0 / pts.size() == doctest::Approx(1.0 / 3.0).epsilon(1e-13));
  CHECK(s1 / pts.size() == doctest::Approx(1.0 / 3.0).epsilon(1e-13));
  CHECK(s2 / pts.size() == doctest::Approx(1.0 / 3.0).epsilon(1e-13));
  // Spacing along an edge direction: leg / n <= h / 2.
  min_gap = 0.3 / n;
  CHECK(min_gap <= 0.05 + 1e-12);
  CHECK_THROWS_AS((pf::coupling::point_options{1, 32}.validate()), pf::invalid_input);
}

TEST_CASE("grid locator: partition of unity and exact linear interpolation") {
  // Uniform (fast path) and stretched (binary search) grids.
  const auto uni = pf::fluid::rectilinear_grid::uniform({12, 9, 7}, {-1, 0, 0}, {1, 1, 0.7});
  const pf::fluid::rectilinear_grid str{pf::fluid::axis::refined(-1, 1, -0.2, 0.2, 0.05, 1.2),
                                        pf::fluid::axis::uniform(9, 0, 1),
                                        pf::fluid::axis::refined(0, 1, 0.4, 0.6, 0.05, 1.3)};
  for (const auto* g : {&uni, &str}) {
    const pf::coupling::grid_locator loc(*g);
    auto lin = [](const Eigen::Vector3d& p) { return 1.5 + 2.0 * p.x() - 0.7 * p.y() + 3.1 * p.z(); };
    std::vector<double> f(std::size_t(g->total_cells()), 0.0);
    for (index_t k = 0; k < g->n(2); ++k)
      for (index_t j = 0; j < g->n(1); ++j)
        for (index_t i = 0; i < g->n(0); ++i)
          f[std::size_t(g->index(i, j, k))] = lin({g->centre(0, i), g->centre(1, j), g->centre(2, k)});
    std::mt19937 rng(7);
    double max_err = 0;
    for (int q = 0; q < 2000; ++q) {
      Eigen::Vector3d xi;
      for (int d = 0; d < 3; ++d) {
        const double lo = g->centre(d, 0), hi = g->centre(d, g->n(d) - 1);
        xi[d] = std::uniform_real_distribution<double>(lo, hi)(rng);
      }
      const auto s = loc.locate(xi);
      REQUIRE(s.inside);
      double w = 0, v = 0;
      for (int a = 0; a < 8; ++a) {
        CHECK(s.weight(a) >= 0.0);
        w += s.weight(a);
        v += s.weight(a) * f[std::size_t(s.base + loc.corner(a))];
      }
      CHECK(w == doctest::Approx(1.0).epsilon(1e-14));
      max_err = std::max(max_err, std::fabs(v - lin(xi)));
    }
    MESSAGE("max linear-field interpolation error: " << max_err);
    CHECK(max_err < 1e-12);
    // Near the box face: clamped to interior cells, weights still sum to one.
    const auto s = loc.locate({g->face(0, 0) + 1e-6, 0.5, 0.35});
    CHECK(s.inside);
    CHECK(s.ijk[0] == 0);
    double w = 0;
    for (int a = 0; a < 8; ++a) w += s.weight(a);
    CHECK(w == doctest::Approx(1.0).epsilon(1e-14));
    CHECK_FALSE(loc.locate({g->face(0, g->n(0)) + 1e-3, 0.5, 0.35}).inside);
  }
}

TEST_CASE("grid locator: points in a moving, turned box (xi = R^T (x - X))") {
  const auto g = pf::fluid::rectilinear_grid::uniform({8, 8, 8}, {-1, -1, -1}, {1, 1, 1});
  const pf::coupling::grid_locator loc(g);
  pf::frame::pose p;
  p.X = {3, -2, 5};
  p.R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d xi{0.31, -0.42, 0.17};
  const auto s = loc.locate(p.to_box(p.to_inertial(xi)));
  const auto s0 = loc.locate(xi);
  CHECK(s.base == s0.base);
  for (int d = 0; d < 3; ++d) CHECK(s.t[std::size_t(d)] == doctest::Approx(s0.t[std::size_t(d)]).epsilon(1e-12));
}
