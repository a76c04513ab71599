/// \file duct_screen.hpp
/// A flat sheet across a rectangular duct (plain data, no solver types): the scene of the
/// coupling verification (porous screen, leak box, piston, impedance plate). The duct runs
/// along x from 0 to L with cells × m × 2 cubic cells of size h = L / cells (m = 2 by
/// default, so the square cross-section W = 2 h wide has every cell touching a side wall
/// and the flow stays one-dimensional; m > 2 widens the duct along y to W_y = m h). The
/// sheet spans the whole cross-section through (x_s, W_y/2, ·); upright (incline θ = 0) it
/// lies in the plane x = x_s with edge vectors (0, W_y, 0) and (0, 0, W), triangulated by
/// rect_mesh.hpp with n × n quads (default 2 × 2: 9 nodes, 8 triangles, the 8 rim nodes
/// in `sheet.edge`, node 4 at the centre); its normal is +x. Inclined, it is turned by θ
/// about the z axis: edge vectors (W_y tan θ, W_y, 0) and (0, 0, W), normal
/// (cos θ, −sin θ, 0), area W_y W / cos θ, so air crossing the duct at the mean speed U
/// passes the cloth at the normal velocity U cos θ (mass conservation).
///
/// Use (the fluid grid from `cells`, `lo`, `hi`):
///   const auto d = model::duct_screen(1.0, 40, 0.5);
///   auto grid = fluid::rectilinear_grid::uniform(d.cells, d.lo, d.hi);
///   for (const auto& x : d.sheet.positions) nodes.add(x);   mesh.triangles = d.sheet.triangles;
#pragma once
#include <array>
#include <cmath>
#include <numbers>

#include "../core/config.hpp"
#include "../core/error.hpp"
#include "rect_mesh.hpp"

namespace parafsi::model {

struct duct_screen_scene {
  std::array<index_t, 3> cells;  ///< fluid cells along x, y, z: (cells, m, 2)
  std::array<double, 3> lo, hi;  ///< duct corners (0, 0, 0) and (L, W_y, W) (m)
  double length = 0;             ///< L (m)
  double width = 0;              ///< W = 2 L / cells (m), the duct's extent along z
  double width_y = 0;            ///< W_y = m L / cells (m), its extent along y
  double x_sheet = 0;            ///< x_s (m): the sheet's x at mid-width
  double incline = 0;            ///< θ (rad): the sheet turned about z
  rect_triangulation sheet;      ///< the sheet across the duct

  double area() const { return width_y * width; }                   ///< duct cross-section (m²)
  double sheet_area() const { return area() / std::cos(incline); }  ///< cloth area (m²)
  /// The sheet's unit normal (cos θ, −sin θ, 0).
  std::array<double, 3> sheet_normal() const { return {std::cos(incline), -std::sin(incline), 0.0}; }
};

/// The duct of length L with `cells` cells along it and the sheet at x_s (0 < x_s < L),
/// `divisions` quads across the sheet along each edge (along y: `divisions` × m / 2), the
/// sheet inclined by `incline_deg` degrees about z (|θ| < 80°) and m = `transverse_cells`
/// (even, ≥ 2) cells across the duct along y.
inline duct_screen_scene duct_screen(double length, int cells, double x_sheet, int divisions = 2,
                                     double incline_deg = 0.0, int transverse_cells = 2) {
  require(std::isfinite(length) && length > 0, "model::duct_screen: length must be positive, got ", length);
  require(cells >= 2, "model::duct_screen: need at least 2 cells along the duct, got ", cells);
  require(transverse_cells >= 2 && transverse_cells % 2 == 0,
          "model::duct_screen: transverse cells must be even and >= 2, got ", transverse_cells);
  require(std::isfinite(incline_deg) && std::fabs(incline_deg) < 80.0,
          "model::duct_screen: incline must be within (-80, 80) degrees, got ", incline_deg);
  duct_screen_scene d;
  d.length = length;
  d.width = 2.0 * length / cells;
  d.width_y = transverse_cells * length / cells;
  d.x_sheet = x_sheet;
  d.incline = incline_deg * std::numbers::pi / 180.0;
  const double dx = d.width_y * std::tan(d.incline);  // x extent of the inclined sheet
  require(x_sheet - 0.5 * std::fabs(dx) > 0 && x_sheet + 0.5 * std::fabs(dx) < length,
          "model::duct_screen: the sheet at x = ", x_sheet, " m (x extent ", std::fabs(dx),
          " m when inclined) is not inside the duct (0, ", length, ")");
  d.cells = {index_t(cells), index_t(transverse_cells), 2};
  d.lo = {0.0, 0.0, 0.0};
  d.hi = {length, d.width_y, d.width};
  const int na = divisions * transverse_cells / 2;
  d.sheet = rect_mesh({x_sheet - 0.5 * dx, 0, 0}, {dx, d.width_y, 0}, {0, 0, d.width}, na, divisions);
  return d;
}

}  // namespace parafsi::model
