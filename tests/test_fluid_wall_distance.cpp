// The mixing length's distance field from structure points (fluid/wall_distance.hpp):
// - against a brute-force minimum over all points, on a stretched grid: equal (to 1e-15 m)
//   within the reach, +∞ (1e30) beyond it, ghost cells untouched;
// - points on a sphere of radius R (spacing s): the field lies between the distance to the
//   sphere |r − R| and |r − R| + s/√2 (the farthest a surface point is from its nearest
//   grid point on the sphere), wherever that is within the reach;
// - bad input named.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <parafsi/fluid/wall_distance.hpp>

using namespace parafsi;

namespace {
/// The cells of g (with `ghosts`, the ghost layers too) against a brute-force search over
/// `pts`: cells within `reach` of a point, cells beyond, and cells whose value d differs
/// (more than 1e-15 from the nearest distance, the same sum in another order; or not 1e30
/// beyond the reach).
struct brute_force_count {
  int inside = 0, beyond = 0, wrong = 0;
};
brute_force_count compare_brute_force(const fluid::rectilinear_grid& g, const std::vector<Eigen::Vector3d>& pts,
                                      double reach, const std::vector<double>& d, bool ghosts) {
  const index_t ng = ghosts ? fluid::rectilinear_grid::ghosts : 0;
  brute_force_count r;
  for (index_t k = -ng; k < g.n(2) + ng; ++k)
    for (index_t j = -ng; j < g.n(1) + ng; ++j)
      for (index_t i = -ng; i < g.n(0) + ng; ++i) {
        const Eigen::Vector3d x(g.centre(0, i), g.centre(1, j), g.centre(2, k));
        double best = 1e300;
        for (const auto& p : pts) best = std::min(best, (x - p).norm());
        const double got = d[std::size_t(g.index(i, j, k))];
        if (best <= reach) {
          ++r.inside;
          if (std::fabs(got - best) > 1e-15) ++r.wrong;
        } else {
          ++r.beyond;
          if (got != 1e30) ++r.wrong;
        }
      }
  return r;
}
}  // namespace

TEST_CASE("wall distance: the nearest point within the reach, +inf beyond, as a brute-force search") {
  const auto g = fluid::rectilinear_grid{fluid::axis::refined(-1, 1, -0.3, 0.3, 0.05, 1.2),
                                         fluid::axis::uniform(20, -0.5, 0.5), fluid::axis::uniform(12, 0, 0.6)};
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ux(-0.8, 0.8), uy(-0.5, 0.5), uz(0.0, 0.6);
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < 40; ++i) pts.emplace_back(ux(rng), uy(rng), uz(rng));
  const double reach = 0.2;
  std::vector<double> d(std::size_t(g.total_cells()), -7.0);
  fluid::distance_to_points(g, pts, reach, d);
  const auto [inside, beyond, wrong] = compare_brute_force(g, pts, reach, d, false);
  MESSAGE(inside, " cells within the reach, ", beyond, " beyond, ", wrong, " differ");
  CHECK(inside > 100);
  CHECK(beyond > 100);
  CHECK(wrong == 0);
  CHECK(d[std::size_t(g.index(-1, 0, 0))] == -7.0);  // a ghost cell is left alone
}

TEST_CASE("wall distance with ghosts: points outside the grid within and beyond the reach, as a brute force") {
  // A block-sized grid and points spread over a region three times as wide: the points
  // farther than the reach outside its cells are skipped, the others still count.
  const auto g = fluid::rectilinear_grid::uniform({8, 8, 8}, {0.0, 0.0, 0.0}, {0.4, 0.4, 0.4});
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.4, 0.8);
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < 300; ++i) pts.emplace_back(u(rng), u(rng), u(rng));
  const double reach = 0.12;
  std::vector<double> d(std::size_t(g.total_cells()), -7.0);
  fluid::distance_to_points(g, pts, reach, d, true);
  const auto [inside, beyond, wrong] = compare_brute_force(g, pts, reach, d, true);
  MESSAGE(inside, " cells (ghosts included) within the reach, ", beyond, " beyond, ", wrong, " differ");
  CHECK(inside > 100);
  CHECK(beyond > 10);
  CHECK(wrong == 0);
}

TEST_CASE("wall distance: points on a sphere bound the distance to the sphere") {
  const double R = 0.3, pi = std::numbers::pi;
  const int nth = 40, nph = 80;  // spacing ≤ π R / 40 ≈ 0.024 m
  std::vector<Eigen::Vector3d> pts;
  for (int a = 0; a <= nth; ++a)
    for (int b = 0; b < nph; ++b) {
      const double th = pi * a / nth, ph = 2 * pi * b / nph;
      pts.emplace_back(R * std::sin(th) * std::cos(ph), R * std::sin(th) * std::sin(ph), R * std::cos(th));
    }
  const double s = 2 * pi * R / nph;  // the largest spacing (along the equator)
  const auto g = fluid::rectilinear_grid::uniform({32, 32, 32}, {-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
  std::vector<double> d(std::size_t(g.total_cells()));
  const double reach = 0.12;
  fluid::distance_to_points(g, pts, reach, d);
  double worst_low = 0, worst_high = 0;
  int n = 0;
  for (index_t k = 0; k < 32; ++k)
    for (index_t j = 0; j < 32; ++j)
      for (index_t i = 0; i < 32; ++i) {
        const Eigen::Vector3d x(g.centre(0, i), g.centre(1, j), g.centre(2, k));
        const double exact = std::fabs(x.norm() - R);
        if (exact + s > reach) continue;
        const double got = d[std::size_t(g.index(i, j, k))];
        worst_low = std::max(worst_low, exact - got);
        worst_high = std::max(worst_high, got - exact);
        ++n;
      }
  MESSAGE(n, " cells near the sphere: the field is below |r - R| by at most ", worst_low, " m and above it by at most ",
          worst_high, " m (point spacing ", s, " m)");
  CHECK(n > 1000);
  CHECK(worst_low < 1e-12);
  CHECK(worst_high < s / std::sqrt(2.0));
}

TEST_CASE("wall distance: bad input is named") {
  const auto g = fluid::rectilinear_grid::uniform({4, 4, 4}, {0, 0, 0}, {1, 1, 1});
  std::vector<double> d(std::size_t(g.total_cells()));
  std::vector<Eigen::Vector3d> pts{{0.5, 0.5, 0.5}};
  CHECK_THROWS_WITH_AS(fluid::distance_to_points(g, pts, 0.0, d), doctest::Contains("reach must be"), invalid_input);
  std::vector<double> small(10);
  CHECK_THROWS_WITH_AS(fluid::distance_to_points(g, pts, 0.1, small), doctest::Contains("values for a grid"),
                       invalid_input);
  pts.emplace_back(std::nan(""), 0.0, 0.0);
  CHECK_THROWS_WITH_AS(fluid::distance_to_points(g, pts, 0.1, d), doctest::Contains("not finite"), invalid_input);
}
