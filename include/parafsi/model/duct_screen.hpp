/// \file duct_screen.hpp
/// A flat sheet across a square duct (plain data, no solver types): the quasi-1-D scene of
/// the coupling verification (porous screen, leak box, piston, impedance plate). The duct
/// runs along x from 0 to L with cells × 2 × 2 cubic cells of size h = L / cells, so its
/// square cross-section is W = 2 h wide (two cells: every cell touches a side wall and the
/// flow stays one-dimensional). The sheet spans the whole cross-section at x = x_s, in the
/// plane x = x_s with edge vectors (0, W, 0) and (0, 0, W), triangulated by
/// rect_mesh.hpp with n × n quads (default 2 × 2: 9 nodes, 8 triangles, the 8 rim nodes in
/// `sheet.edge`, node 4 at the centre); its normal is +x.
///
/// Use (the fluid grid from `cells`, `lo`, `hi`):
///   const auto d = model::duct_screen(1.0, 40, 0.5);
///   auto grid = fluid::rectilinear_grid::uniform(d.cells, d.lo, d.hi);
///   for (const auto& x : d.sheet.positions) nodes.add(x);   mesh.triangles = d.sheet.triangles;
#pragma once
#include <array>

#include "../core/config.hpp"
#include "../core/error.hpp"
#include "rect_mesh.hpp"

namespace parafsi::model {

struct duct_screen_scene {
  std::array<index_t, 3> cells;  ///< fluid cells along x, y, z: (cells, 2, 2)
  std::array<double, 3> lo, hi;  ///< duct corners (0, 0, 0) and (L, W, W) (m)
  double length = 0;             ///< L (m)
  double width = 0;              ///< W = 2 L / cells (m)
  double x_sheet = 0;            ///< x_s (m)
  rect_triangulation sheet;      ///< the sheet across the duct at x = x_s

  double area() const { return width * width; }  ///< cross-section = sheet area (m²)
};

/// The duct of length L with `cells` cells along it and the sheet at x_s (0 < x_s < L),
/// `divisions` × `divisions` quads in the sheet.
inline duct_screen_scene duct_screen(double length, int cells, double x_sheet, int divisions = 2) {
  require(length > 0, "model::duct_screen: length must be positive, got ", length);
  require(cells >= 2, "model::duct_screen: need at least 2 cells along the duct, got ", cells);
  require(x_sheet > 0 && x_sheet < length, "model::duct_screen: the sheet at x = ", x_sheet,
          " m is not inside the duct (0, ", length, ")");
  duct_screen_scene d;
  d.length = length;
  d.width = 2.0 * length / cells;
  d.x_sheet = x_sheet;
  d.cells = {index_t(cells), 2, 2};
  d.lo = {0.0, 0.0, 0.0};
  d.hi = {length, d.width, d.width};
  d.sheet = rect_mesh({x_sheet, 0, 0}, {0, d.width, 0}, {0, 0, d.width}, divisions, divisions);
  return d;
}

}  // namespace parafsi::model
