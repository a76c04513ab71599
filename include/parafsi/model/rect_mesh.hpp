/// \file rect_mesh.hpp
/// Structured triangulation of a flat rectangle (plain data, no solver types):
/// origin o, edge vectors a and b, na × nb quads, each split into two triangles
/// counter-clockwise about a × b (so the element normal is along a × b). Node (i, j)
/// at o + (i/na) a + (j/nb) b has id i + (na + 1) j; `edge` lists the boundary nodes.
#pragma once
#include <array>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "../core/config.hpp"
#include "../core/error.hpp"

namespace parafsi::model {

struct rect_triangulation {
  std::vector<Eigen::Vector3d> positions;
  std::vector<std::array<index_t, 3>> triangles;
  std::vector<index_t> edge;  ///< nodes on the rectangle's boundary
};

inline rect_triangulation rect_mesh(const Eigen::Vector3d& o, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                    int na, int nb) {
  require(na >= 1 && nb >= 1, "model::rect_mesh: need at least one quad per side, got ", na, " x ", nb);
  require(a.cross(b).norm() > 0, "model::rect_mesh: edge vectors are parallel");
  rect_triangulation m;
  auto id = [&](int i, int j) { return index_t(i + (na + 1) * j); };
  for (int j = 0; j <= nb; ++j)
    for (int i = 0; i <= na; ++i) {
      m.positions.push_back(o + a * (double(i) / na) + b * (double(j) / nb));
      if (i == 0 || j == 0 || i == na || j == nb) m.edge.push_back(id(i, j));
    }
  for (int j = 0; j < nb; ++j)
    for (int i = 0; i < na; ++i) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

}  // namespace parafsi::model
