/// \file drop_box.hpp
/// The fluid box of a parachute drop as plain data (no solver types): its extents, the
/// refined block around the canopy, the cell size and growth, and its axes, from the scene
/// (`drop_scene`) and a few numbers in units of the nominal diameter D0
/// (`drop_box_parameters`); and the drop's resolution presets (`drop_resolution`).
///
/// Box coordinates ξ (m): the payload mass centre at ξ = 0, box +z along the canopy axis
/// (payload → canopy, against the flight direction), so box −z points along the flight.
/// Extents: |ξx|, |ξy| ≤ width/2 · D0; ξz from −ahead · D0 − fall to (length − ahead) · D0.
/// Refined block (cells of h = cell · D0): the canopy from packed to fully open,
/// |ξx|, |ξy| ≤ `refined_radius` · D0 (0.6) and, along the axis, from `refined_below` · Ls
/// (0.55) above the line confluence (height zc above the payload; the lines meet the skirt
/// about 0.94 Ls above it) to `refined_above` · D0 (0.55) above the point Ls beyond the
/// confluence (above the inflated crown), lowered with the box bottom by `fall`; cells grow
/// by `growth` per cell outwards (fluid::axis::refined builds the faces from these numbers).
/// `fall` > 0 is the fixed box of the following-box study: the following box at the start,
/// lengthened downwards by the fall (m) it must hold, with the refined column lengthened by
/// the same amount.
/// `offset` shifts the whole box (extents and refined block) by offset · h along the axis:
/// the same grid placed differently about the canopy by a fraction of a cell, for an
/// ensemble over the grid's placement (an under-resolved packed canopy's opening depends on
/// where it sits in its cells; docs/validation.md §8.1).
/// Axes: z_b = the scene's canopy axis, x_b = ŷ × z_b normalised (x̂ if the axis is along ŷ),
/// y_b = z_b × x_b; `axes` holds them as columns (the box pose's R).
///
/// Size check: `make_drop_box` estimates the cell count along each axis from the numbers
/// above (doubles, before anything is cast to an integer or allocated) and refuses a box of
/// more than `max_cells` cells, naming the estimate and its memory (≈ `bytes_per_cell`
/// each, measured on the drop with either coupling).
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <string_view>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "drop_scene.hpp"

namespace parafsi::model {

/// Mesh resolution of a drop in units of D0: canopy element size, fluid cell size around
/// the canopy (twice the element), growth factor of the cells outside the refined block.
struct drop_resolution {
  double element = 0.0333;  ///< canopy element size / D0
  double cell = 0.0667;     ///< fluid cell size around the canopy / D0
  double growth = 1.2;      ///< cell growth factor outside the refined block

  /// draft: element D0/20, cell D0/10, growth 1.3 (17 576 cells; the packed canopy's
  /// mouth spans two cells, too few for the embedded coupling to fill it reliably);
  /// coarse: D0/30, D0/15, growth 1.2 (54 872 cells); medium: D0/40, D0/20, growth 1.12
  /// (about the paper's finest validation mesh, ≈ 1.5e5 cells); fine: D0/60, D0/30,
  /// growth 1.1 (≈ 4.4e5 cells); tiny (tests): D0/10, D0/5, growth 1.3.
  /// docs/validation.md §8. Any other name is an error.
  static drop_resolution preset(std::string_view name) {
    if (name == "draft") return {0.05, 0.10, 1.3};
    if (name == "medium") return {0.025, 0.05, 1.12};
    if (name == "fine") return {0.0167, 0.0333, 1.1};
    if (name == "tiny") return {0.1, 0.2, 1.3};
    require(name == "coarse", "model::drop_resolution: unknown resolution '", name,
            "' (draft, coarse, medium, fine or tiny)");
    return {0.0333, 0.0667, 1.2};
  }
};

struct drop_box_parameters {
  double width = 5.0;           ///< cross-section side / D0
  double length = 7.0;          ///< length along the axis / D0
  double ahead = 1.5;           ///< length ahead of the payload mass centre / D0
  double cell = 0.0667;         ///< cell size h on the refined block / D0
  double growth = 1.2;          ///< cell growth factor outside the refined block, in [1, 2]
  double fall = 0.0;            ///< fixed box: fall length (m) below the start it must hold; 0 = following box
  double refined_radius = 0.6;  ///< refined block half-width / D0
  double refined_below = 0.55;  ///< refined block start above the confluence / Ls
  double refined_above = 0.55;  ///< refined block end above the point Ls beyond the confluence / D0
  double offset = 0.0;          ///< shift of the box along its axis, in cells h, in [0, 1)
  double max_cells = 5e7;       ///< largest box accepted (cells)
  double bytes_per_cell = 300;  ///< memory estimate per cell (for the size message)

  void validate() const {
    auto positive = [](double v) { return v > 0 && std::isfinite(v); };
    require(positive(width), "model::drop_box: box width must be > 0 (D0), got ", width);
    require(positive(length), "model::drop_box: box length must be > 0 (D0), got ", length);
    require(positive(ahead) && ahead < length, "model::drop_box: box length ahead of the payload must be in (0, ",
            length, ") D0, got ", ahead);
    require(positive(cell), "model::drop_box: cell size must be > 0 (D0), got ", cell);
    require(growth >= 1.0 && growth <= 2.0, "model::drop_box: growth must be in [1, 2], got ", growth);
    require(fall >= 0 && std::isfinite(fall), "model::drop_box: fall length must be >= 0 m, got ", fall);
    require(positive(refined_radius), "model::drop_box: refined radius must be > 0 (D0), got ", refined_radius);
    require(std::isfinite(refined_below) && std::isfinite(refined_above),
            "model::drop_box: refined block bounds must be finite, got ", refined_below, " and ", refined_above);
    require(positive(max_cells), "model::drop_box: max_cells must be > 0, got ", max_cells);
    require(offset >= 0.0 && offset < 1.0, "model::drop_box: the grid offset must be in [0, 1) cells, got ", offset);
  }
};

struct drop_box {
  std::array<double, 3> lo{}, hi{};                    ///< box extents in box coordinates ξ (m)
  std::array<double, 3> fine_lo{}, fine_hi{};          ///< refined block (m), inside the extents
  double cell = 0;                                     ///< cell size h on the refined block (m)
  double growth = 1;                                   ///< growth factor outside it
  double fall = 0;                                     ///< fixed box: fall length it holds (m); 0 = following
  std::array<double, 3> cells_estimate{};              ///< estimated cells per axis (before the grid is built)
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  ///< box axes (x_b, y_b, z_b) as columns, world

  double estimated_cells() const { return cells_estimate[0] * cells_estimate[1] * cells_estimate[2]; }
};

namespace detail {
/// Cells of fluid::axis::refined on [lo, hi] with cells of h on [a, b] growing by g
/// outwards, estimated in double (never cast): the block's ⌈(b − a)/h⌉ plus on each side
/// the n with h (g + … + gⁿ) ≥ the side's length.
inline double refined_axis_cells(double lo, double hi, double a, double b, double h, double g) {
  const double nf = std::max(1.0, std::ceil((b - a) / h - 1e-9));
  const double h0 = (b - a) / nf;
  auto side = [&](double L) {
    if (!(L > 0)) return 0.0;
    if (!(h0 > 0)) return L / h;
    if (g <= 1.0) return std::ceil(L / h0);
    return std::ceil(std::log1p(L * (g - 1.0) / (h0 * g)) / std::log(g));
  };
  return nf + side(a - lo) + side(hi - b);
}
}  // namespace detail

/// The fluid box of the scene `s` (rules in the file comment); throws invalid_input
/// naming a bad parameter or a box too large, before anything is allocated.
inline drop_box make_drop_box(const drop_scene& s, const drop_box_parameters& p) {
  p.validate();
  const drop_scene_parameters& P = s.params;
  const double D0 = P.canopy.nominal_diameter;
  drop_box b;
  // Box coordinates: payload mass centre at ξ = 0, box +z against the flight direction
  // (towards the canopy), so box −z follows the payload velocity.
  const double zc = (s.positions[std::size_t(s.suspension.confluence)] - s.payload.position).dot(s.axis()) / D0;
  const double fall = p.fall;
  const double zlo = -p.ahead * D0 - fall, zhi = (p.length - p.ahead) * D0, half = 0.5 * p.width * D0;
  const double rz0 = (zc + p.refined_below * P.line_length_ratio) * D0 - fall;
  const double rz1 = (zc + 1.0 * P.line_length_ratio + p.refined_above) * D0;
  b.lo = {-half, -half, zlo};
  b.hi = {half, half, zhi};
  b.fine_lo = {-p.refined_radius * D0, -p.refined_radius * D0, std::max(zlo, rz0)};
  b.fine_hi = {p.refined_radius * D0, p.refined_radius * D0, std::min(zhi, rz1)};
  const double shift = p.offset * p.cell * D0;
  for (double* z : {&b.lo[2], &b.hi[2], &b.fine_lo[2], &b.fine_hi[2]}) *z += shift;
  b.cell = p.cell * D0;
  b.growth = p.growth;
  b.fall = fall;
  for (std::size_t d = 0; d < 3; ++d) {
    require(b.lo[d] <= b.fine_lo[d] && b.fine_lo[d] <= b.fine_hi[d] && b.fine_hi[d] <= b.hi[d],
            "model::drop_box: the refined block [", b.fine_lo[d], ", ", b.fine_hi[d], "] m does not fit the box [",
            b.lo[d], ", ", b.hi[d], "] m along axis ", d, " (box width ", p.width, " D0, length ", p.length,
            " D0, ahead ", p.ahead, " D0)");
    b.cells_estimate[d] = detail::refined_axis_cells(b.lo[d], b.hi[d], b.fine_lo[d], b.fine_hi[d], b.cell, b.growth);
  }
  const double n = b.estimated_cells();
  auto num = [](double v) {  // 3 significant digits
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return std::string(buf);
  };
  auto about = [&](double v) { return std::isinf(v) ? std::string("more than 1e308") : "about " + num(v); };
  require(n <= p.max_cells, "model::drop_box: the fluid grid would have ", about(n), " cells (",
          num(b.cells_estimate[0]), " x ", num(b.cells_estimate[1]), " x ", num(b.cells_estimate[2]), ", ",
          about(n * p.bytes_per_cell / 1e9), " GB) with cells of ", b.cell, " m (", p.cell, " D0) and growth ",
          p.growth, ", more than the limit of ", p.max_cells, " cells: use a larger cell size or growth");
  // Box axes: +z along the canopy axis (against the flight direction).
  const Eigen::Vector3d zb = s.axis();
  Eigen::Vector3d xb = Eigen::Vector3d::UnitY().cross(zb);
  if (xb.norm() < 1e-9) xb = Eigen::Vector3d::UnitX();
  xb.normalize();
  const Eigen::Vector3d yb = zb.cross(xb);
  b.axes.col(0) = xb;
  b.axes.col(1) = yb;
  b.axes.col(2) = zb;
  return b;
}

}  // namespace parafsi::model
