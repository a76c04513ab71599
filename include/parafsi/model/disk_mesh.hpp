/// \file disk_mesh.hpp
/// Structured triangulation of a flat disk (plain data, no solver types): a centre node
/// and `rings` rings, ring k of radius k·R/rings holding 6k nodes, triangles counter-
/// clockwise seen from +z. 6·rings² triangles of near-uniform size and quality ≥ 0.6.
#pragma once
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include <Eigen/Core>

#include "../core/config.hpp"
#include "../core/error.hpp"

namespace parafsi::model {

struct disk_triangulation {
  std::vector<Eigen::Vector3d> positions;
  std::vector<std::array<index_t, 3>> triangles;
  std::vector<index_t> rim;  ///< nodes of the outer ring
};

/// Disk of radius R in the plane z = z0 centred on the origin.
inline disk_triangulation disk_mesh(double R, int rings, double z0 = 0.0) {
  require(R > 0 && std::isfinite(R), "model::disk_mesh: radius must be > 0, got ", R);
  require(rings >= 1, "model::disk_mesh: need at least 1 ring, got ", rings);
  disk_triangulation d;
  d.positions.push_back({0, 0, z0});
  auto first = [](int k) -> index_t { return k == 0 ? 0 : 1 + 3 * index_t(k) * index_t(k - 1); };
  for (int k = 1; k <= rings; ++k)
    for (int j = 0; j < 6 * k; ++j) {
      const double r = R * k / rings, th = 2.0 * std::numbers::pi * j / (6.0 * k);
      d.positions.push_back({r * std::cos(th), r * std::sin(th), z0});
    }
  auto node = [&](int k, int j) -> index_t {
    if (k == 0) return 0;
    const int n = 6 * k;
    return first(k) + ((j % n) + n) % n;
  };
  // Between ring k−1 and ring k: each of the 6 sectors holds k outer and k−1 inner nodes.
  for (int k = 1; k <= rings; ++k)
    for (int s = 0; s < 6; ++s)
      for (int i = 0; i < k; ++i) {
        const int jo = s * k + i, ji = s * (k - 1) + i;
        d.triangles.push_back({node(k - 1, ji), node(k, jo), node(k, jo + 1)});
        if (i < k - 1) d.triangles.push_back({node(k - 1, ji), node(k, jo + 1), node(k - 1, ji + 1)});
      }
  for (int j = 0; j < 6 * rings; ++j) d.rim.push_back(node(rings, j));
  return d;
}

}  // namespace parafsi::model
