/// \file disk_quad_mesh.hpp
/// Structured all-quadrilateral mesh of a flat disk (plain data, no solver types), an
/// "O-grid": an inner square [−s, s]² of n×n cells (s = `inner` · R) surrounded by a ring
/// of 4n × m cells whose radial lines join the square's boundary nodes to equally spaced
/// points of the circle. Quads are counter-clockwise seen from +z. With n even the
/// centre is a node (`centre`). The least regular cells are the ring cells at the
/// square's corners (a 135° corner angle).
#pragma once
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include <Eigen/Core>

#include "../core/config.hpp"
#include "../core/error.hpp"

namespace parafsi::model {

struct disk_quadrangulation {
  std::vector<Eigen::Vector3d> positions;
  std::vector<std::array<index_t, 4>> quads;
  std::vector<index_t> rim;  ///< nodes on the circle
  index_t centre = -1;       ///< node at the origin (n even), else −1
};

/// Disk of radius R in the plane z = z0: n (even, ≥ 2) cells along the inner square's
/// side, m radial cells in the ring (m ≤ 0: chosen so ring cells match the inner cells).
inline disk_quadrangulation disk_quad_mesh(double R, int n, int m = 0, double inner = 0.5, double z0 = 0.0) {
  require(R > 0 && std::isfinite(R), "model::disk_quad_mesh: radius must be > 0, got ", R);
  require(n >= 2 && n % 2 == 0, "model::disk_quad_mesh: n must be even and >= 2, got ", n);
  require(inner > 0.1 && inner < 0.7, "model::disk_quad_mesh: inner square fraction must be in (0.1, 0.7), got ",
          inner);
  const double s = inner * R;
  if (m <= 0) m = std::max(1, int(std::lround((R - s) / (2.0 * s / n))));
  disk_quadrangulation d;
  auto sq = [&](int i, int j) -> index_t { return index_t(j) * (n + 1) + i; };
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) d.positions.push_back({s * (-1.0 + 2.0 * i / n), s * (-1.0 + 2.0 * j / n), z0});
  // Perimeter of the square, counter-clockwise from the corner (s, −s): P ∈ [0, 4n).
  const int np = 4 * n;
  std::vector<index_t> perim(static_cast<std::size_t>(np));
  for (int P = 0; P < np; ++P) {
    const int side = P / n, k = P % n;
    index_t id = 0;
    if (side == 0) id = sq(n, k);
    else if (side == 1) id = sq(n - k, n);
    else if (side == 2) id = sq(0, n - k);
    else id = sq(k, 0);
    perim[std::size_t(P)] = id;
  }
  const index_t base = index_t(d.positions.size());
  auto ring = [&](int P, int r) -> index_t {
    P = ((P % np) + np) % np;
    return r == 0 ? perim[std::size_t(P)] : base + index_t(r - 1) * np + P;
  };
  for (int r = 1; r <= m; ++r)
    for (int P = 0; P < np; ++P) {
      const Eigen::Vector3d pin = d.positions[std::size_t(perim[std::size_t(P)])];
      const double th = -0.25 * std::numbers::pi + 2.0 * std::numbers::pi * P / np;
      const Eigen::Vector3d pout{R * std::cos(th), R * std::sin(th), z0};
      d.positions.push_back(r == m ? pout : Eigen::Vector3d(pin + (double(r) / m) * (pout - pin)));
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) d.quads.push_back({sq(i, j), sq(i + 1, j), sq(i + 1, j + 1), sq(i, j + 1)});
  for (int r = 0; r < m; ++r)
    for (int P = 0; P < np; ++P) d.quads.push_back({ring(P, r), ring(P, r + 1), ring(P + 1, r + 1), ring(P + 1, r)});
  for (int P = 0; P < np; ++P) d.rim.push_back(ring(P, m));
  d.centre = sq(n / 2, n / 2);
  return d;
}

}  // namespace parafsi::model
