/// \file flat_circular_canopy.hpp
/// Flat circular canopy (plain data, no solver types): N gores, vent, skirt and vent
/// tapes, radial reinforcing bands, tags.
///
/// Cut pattern. A flat circular canopy laid flat is a regular N-gon with a regular
/// N-gon vent (Knacke, Parachute Recovery Systems Design Manual, NWC TP 6575, §5.2,
/// "flat circular": constructed shape = flat polygon, Dc/D0 = 1). Gore k is the
/// trapezoid between seams k and k+1, seam k along the angle θ_k = 2πk/N, from the vent
/// corner at radius R_v to the skirt corner at radius R_s. The pattern lies in z = 0;
/// triangles are counter-clockwise seen from +z (element normal +z).
///
/// Diameter basis (`diameter_basis`). D0 is the nominal diameter, defined by the cloth
/// area including the vent, S0 = πD0²/4 (Knacke §5.2); by default the corner radii are
/// chosen so that the polygons have exactly the nominal areas:
///     R_s = (D0/2) k_N,  R_v = (Dv/2) k_N,  k_N = √((2π/N) / sin(2π/N))
///     A_ref = (N/2) sin(2π/N) (R_s² − R_v²) = π/4 (D0² − Dv²)      (exact)
/// (k_8 = 1.0539, k_28 = 1.0042). `diameter_basis::corners` puts the corners on the
/// circle of diameter D0 instead (R_s = D0/2): then A_ref = (N/2) sin(2π/N)(D0² − Dv²)/4,
/// i.e. sin(2π/N)/(2π/N) of the circle's area (0.9003 for N = 8, 0.9916 for N = 28).
///
/// Mesh. Each gore is split along its centreline into two half-gores, each meshed in
/// rows: row i (i = 0 vent … n_r skirt) is the chord at seam distance
/// r_i = R_v + (R_s − R_v) i/n_r; a half-gore's row i holds m_i = max(1, round(r_i sin(π/N)/h))
/// segments (h the target element size), so elements keep their size from vent to skirt;
/// adjacent rows are joined by the advancing-front merge of two monotone point rows.
/// Seams and centrelines are mesh lines (needed by the star fold and the bundle, packed_shape.hpp,
/// which map each half-gore linearly).
///
/// Fibre directions. Warp along the gore centreline (radial at the gore's middle),
/// rotated by `fibre_angle` about the normal (π/4: bias construction, Knacke §6). The
/// paper does not state the layout; a block-construction gore with warp along its
/// centreline is the common choice for small solid flat circular canopies.
///
/// Tapes and bands (cable data, rest length = distance in the cut pattern):
///   - skirt tape: the closed skirt polygon (length = N-gon perimeter 2 N R_s sin(π/N));
///   - vent tape:  the closed vent polygon (2 N R_v sin(π/N));
///   - radial bands along every seam; with N even and `bands_cross_vent`, band j
///     (j < N/2) runs skirt corner j → seam j → vent corner j → straight across the vent
///     through the vent centre node (shared by all bands: bands are sewn together where
///     they cross) → vent corner j+N/2 → seam j+N/2 → skirt corner j+N/2, so both ends
///     meet a suspension line (the paper: "four radial reinforcing belts run through the
///     vent and are connected with the suspension line at both ends", 8 gores).
///     With N odd or `bands_cross_vent = false` each seam carries its own band.
///
/// Tags: skirt and vent loops (ordered counter-clockwise), seam and centreline paths
/// (vent → skirt), line attachment nodes (the N skirt corners, seam k → line k), vent
/// centre node, and a bit mask per node (`node_tag`).
#pragma once
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "../core/config.hpp"
#include "../core/error.hpp"

namespace parafsi::model {

enum class diameter_basis { nominal_area, corners };

struct canopy_parameters {
  int gores = 8;                  ///< N
  double nominal_diameter = 1.0;  ///< D0 (m)
  double vent_ratio = 0.1;        ///< Dv/D0, in (0, 1)
  diameter_basis basis = diameter_basis::nominal_area;
  double element_size = 0.05;    ///< target element edge h (m)
  int radial_divisions = 0;      ///< rows along a seam n_r (0: round((R_s − R_v)/h))
  double fibre_angle = 0.0;      ///< warp angle from the gore centreline (rad)
  bool radial_bands = true;      ///< bands along the seams
  bool bands_cross_vent = true;  ///< bands join opposite seams across the vent (N even)
  int vent_band_divisions = 0;   ///< segments per half vent crossing (0: from h, >= 1)
  double max_triangles = 1e8;    ///< largest mesh accepted (estimated before it is built)

  void validate() const {
    require(gores >= 3, "model::flat_circular_canopy: need at least 3 gores, got ", gores);
    require(nominal_diameter > 0 && std::isfinite(nominal_diameter),
            "model::flat_circular_canopy: nominal diameter D0 must be > 0, got ", nominal_diameter);
    require(vent_ratio > 0 && vent_ratio < 1 && std::isfinite(vent_ratio),
            "model::flat_circular_canopy: vent ratio Dv/D0 must be in (0, 1) (vent smaller than D0), got ", vent_ratio);
    require(element_size > 0 && std::isfinite(element_size),
            "model::flat_circular_canopy: element size must be > 0, got ", element_size);
    require(radial_divisions >= 0, "model::flat_circular_canopy: radial divisions must be >= 0, got ",
            radial_divisions);
    require(vent_band_divisions >= 0, "model::flat_circular_canopy: vent band divisions must be >= 0, got ",
            vent_band_divisions);
    require(std::isfinite(fibre_angle), "model::flat_circular_canopy: fibre angle must be finite, got ", fibre_angle);
    // Counts from doubles, checked before any cast: rows along a seam and segments per
    // half-gore row at the skirt bound the triangles by 2N · nr · 2 m.
    const double Rs = skirt_corner_radius(), Rv = vent_corner_radius();
    const double rows = radial_divisions > 0 ? double(radial_divisions) : std::max(1.0, (Rs - Rv) / element_size);
    const double segments = std::max(1.0, Rs * std::sin(std::numbers::pi / gores) / element_size);
    const double triangles = 4.0 * gores * rows * segments;
    require(triangles <= max_triangles, "model::flat_circular_canopy: element size ", element_size, " m would give ",
            float_text(triangles), " triangles, more than the limit of ", max_triangles, ": use a larger element size");
  }
  /// An estimated count in 3 significant digits (for messages).
  static std::string float_text(double v) {
    if (std::isinf(v)) return std::string("more than 1e308");
    char buf[32];
    std::snprintf(buf, sizeof buf, "about %.3g", v);
    return std::string(buf);
  }
  /// Corner-radius factor k_N of the diameter basis.
  double corner_factor() const {
    if (basis == diameter_basis::corners) return 1.0;
    const double a = 2.0 * std::numbers::pi / gores;
    return std::sqrt(a / std::sin(a));
  }
  double skirt_corner_radius() const { return 0.5 * nominal_diameter * corner_factor(); }
  double vent_corner_radius() const { return 0.5 * vent_ratio * nominal_diameter * corner_factor(); }
};

/// Bits of `canopy_mesh::node_tag`.
namespace canopy_tag {
inline constexpr unsigned skirt = 1u, vent = 2u, seam = 4u, centreline = 8u, line_attachment = 16u, vent_centre = 32u;
}

struct canopy_mesh {
  canopy_parameters params;
  double skirt_radius = 0;                        ///< R_s, skirt corner radius (m)
  double vent_radius = 0;                         ///< R_v, vent corner radius (m)
  std::vector<Eigen::Vector3d> positions;         ///< the flat cut pattern (z = 0)
  std::vector<std::array<index_t, 3>> triangles;  ///< counter-clockwise about +z
  std::vector<Eigen::Vector3d> warp;              ///< warp direction per triangle
  std::vector<int> gore;                          ///< gore of each triangle
  std::vector<unsigned> node_tag;                 ///< canopy_tag bits per node
  std::vector<index_t> skirt, vent;               ///< closed loops, counter-clockwise
  std::vector<std::vector<index_t>> seams;        ///< seam k: vent corner → skirt corner
  std::vector<std::vector<index_t>> centrelines;  ///< gore k: vent → skirt
  std::vector<index_t> line_attachment;           ///< skirt corner of seam k (line k)
  index_t vent_centre = -1;                       ///< band crossing node, −1 if none
  std::vector<std::vector<index_t>> bands;        ///< node paths of the radial bands
  std::vector<std::array<index_t, 2>> skirt_tape, vent_tape, band_segments;

  index_t node_count() const { return index_t(positions.size()); }
  /// Σ triangle areas of the cut pattern.
  double reference_area() const {
    double A = 0;
    for (const auto& t : triangles)
      A += 0.5 * (positions[std::size_t(t[1])] - positions[std::size_t(t[0])])
                     .cross(positions[std::size_t(t[2])] - positions[std::size_t(t[0])])
                     .norm();
    return A;
  }
  /// Closed form of the polygonal pattern: (N/2) sin(2π/N) (R_s² − R_v²).
  double polygon_area() const {
    const int N = params.gores;
    return 0.5 * N * std::sin(2.0 * std::numbers::pi / N) * (skirt_radius * skirt_radius - vent_radius * vent_radius);
  }
  /// Flat-circular closed form π/4 (D0² − Dv²).
  double circle_area() const {
    const double D0 = params.nominal_diameter, Dv = params.vent_ratio * D0;
    return 0.25 * std::numbers::pi * (D0 * D0 - Dv * Dv);
  }
  /// Length of a node path or segment list in the cut pattern.
  double length(const std::vector<std::array<index_t, 2>>& segs) const {
    double L = 0;
    for (const auto& s : segs) L += (positions[std::size_t(s[1])] - positions[std::size_t(s[0])]).norm();
    return L;
  }
};

namespace detail {
/// Advancing-front merge of two monotone rows (parameters a, b in [0, 1], both starting
/// at 0 and ending at 1): emits triangles (lower, lower, upper) or (lower, upper, upper).
template <class Emit>
void merge_rows(const std::vector<index_t>& lo, const std::vector<double>& ulo, const std::vector<index_t>& up,
                const std::vector<double>& uup, Emit emit) {
  std::size_t i = 0, j = 0;
  const std::size_t m = lo.size() - 1, n = up.size() - 1;
  while (i < m || j < n) {
    const bool adv_lo = (j == n) || (i < m && ulo[i + 1] <= uup[j + 1]);
    if (adv_lo) {
      emit(lo[i], lo[i + 1], up[j]);
      ++i;
    } else {
      emit(lo[i], up[j + 1], up[j]);
      ++j;
    }
  }
}
}  // namespace detail

/// Build the flat circular canopy of `p` (throws invalid_input naming a bad value).
inline canopy_mesh flat_circular_canopy(const canopy_parameters& p = {}) {
  p.validate();
  const int N = p.gores;
  const double pi = std::numbers::pi, h = p.element_size;
  canopy_mesh c;
  c.params = p;
  c.skirt_radius = p.skirt_corner_radius();
  c.vent_radius = p.vent_corner_radius();
  const double Rs = c.skirt_radius, Rv = c.vent_radius;
  const int nr = p.radial_divisions > 0 ? p.radial_divisions : std::max(1, int(std::lround((Rs - Rv) / h)));
  auto e = [&](int k) {
    const double th = 2.0 * pi * double(k % N) / N;
    return Eigen::Vector3d(std::cos(th), std::sin(th), 0.0);
  };
  auto r_of = [&](int i) { return Rv + (Rs - Rv) * double(i) / nr; };
  auto add = [&](const Eigen::Vector3d& x, unsigned tag) {
    c.positions.push_back(x);
    c.node_tag.push_back(tag);
    return index_t(c.positions.size()) - 1;
  };
  auto row_tag = [&](int i) { return (i == 0 ? canopy_tag::vent : 0u) | (i == nr ? canopy_tag::skirt : 0u); };
  // Segments per half-gore row.
  std::vector<int> m(std::size_t(nr) + 1);
  for (int i = 0; i <= nr; ++i) m[std::size_t(i)] = std::max(1, int(std::lround(r_of(i) * std::sin(pi / N) / h)));

  // Seam and centreline nodes.
  c.seams.assign(std::size_t(N), {});
  c.centrelines.assign(std::size_t(N), {});
  for (int k = 0; k < N; ++k)
    for (int i = 0; i <= nr; ++i)
      c.seams[std::size_t(k)].push_back(
          add(r_of(i) * e(k), canopy_tag::seam | row_tag(i) | (i == nr ? canopy_tag::line_attachment : 0u)));
  for (int k = 0; k < N; ++k)
    for (int i = 0; i <= nr; ++i)
      c.centrelines[std::size_t(k)].push_back(
          add(r_of(i) * 0.5 * (e(k) + e(k + 1)), canopy_tag::centreline | row_tag(i)));

  // Half-gore rows (interior nodes), then triangles.
  std::vector<std::vector<index_t>> skirt_parts, vent_parts;
  for (int k = 0; k < N; ++k) {
    const Eigen::Vector3d nmid = (e(k) + e(k + 1)).normalized();
    const Eigen::Vector3d warp = std::cos(p.fibre_angle) * nmid +
                                 std::sin(p.fibre_angle) * Eigen::Vector3d::UnitZ().cross(nmid);
    for (int half = 0; half < 2; ++half) {
      std::vector<std::vector<index_t>> rows(std::size_t(nr) + 1);
      std::vector<std::vector<double>> us(std::size_t(nr) + 1);
      for (int i = 0; i <= nr; ++i) {
        const int mi = m[std::size_t(i)];
        const Eigen::Vector3d A = r_of(i) * e(k), B = r_of(i) * e(k + 1);
        auto& row = rows[std::size_t(i)];
        auto& u = us[std::size_t(i)];
        const index_t first = half == 0 ? c.seams[std::size_t(k)][std::size_t(i)]
                                        : c.centrelines[std::size_t(k)][std::size_t(i)];
        const index_t last = half == 0 ? c.centrelines[std::size_t(k)][std::size_t(i)]
                                       : c.seams[std::size_t((k + 1) % N)][std::size_t(i)];
        row.push_back(first);
        u.push_back(0.0);
        for (int j = 1; j < mi; ++j) {
          const double uj = double(j) / mi, v = 0.5 * (half + uj);
          row.push_back(add((1.0 - v) * A + v * B, row_tag(i)));
          u.push_back(uj);
        }
        row.push_back(last);
        u.push_back(1.0);
      }
      for (int i = 0; i < nr; ++i)
        detail::merge_rows(rows[std::size_t(i)], us[std::size_t(i)], rows[std::size_t(i) + 1], us[std::size_t(i) + 1],
                           [&](index_t a, index_t b, index_t d) {
          std::array<index_t, 3> t{a, b, d};
          const auto& X = c.positions;
          const double z = (X[std::size_t(b)] - X[std::size_t(a)]).cross(X[std::size_t(d)] - X[std::size_t(a)]).z();
          if (z < 0) std::swap(t[1], t[2]);
          c.triangles.push_back(t);
          c.warp.push_back(warp);
          c.gore.push_back(k);
        });
      auto sk = rows[std::size_t(nr)];
      auto vt = rows[0];
      sk.pop_back();
      vt.pop_back();
      skirt_parts.push_back(sk);
      vent_parts.push_back(vt);
    }
  }
  for (const auto& s : skirt_parts) c.skirt.insert(c.skirt.end(), s.begin(), s.end());
  for (const auto& s : vent_parts) c.vent.insert(c.vent.end(), s.begin(), s.end());
  for (std::size_t a = 0; a < c.skirt.size(); ++a)
    c.skirt_tape.push_back({c.skirt[a], c.skirt[(a + 1) % c.skirt.size()]});
  for (std::size_t a = 0; a < c.vent.size(); ++a) c.vent_tape.push_back({c.vent[a], c.vent[(a + 1) % c.vent.size()]});
  for (int k = 0; k < N; ++k) c.line_attachment.push_back(c.seams[std::size_t(k)].back());

  // Radial bands.
  if (p.radial_bands) {
    const bool cross = p.bands_cross_vent && N % 2 == 0;
    if (cross) {
      const int nv = p.vent_band_divisions > 0 ? p.vent_band_divisions : std::max(1, int(std::lround(Rv / h)));
      c.vent_centre = add(Eigen::Vector3d::Zero(), canopy_tag::vent_centre);
      for (int j = 0; j < N / 2; ++j) {
        std::vector<index_t> path(c.seams[std::size_t(j)].rbegin(), c.seams[std::size_t(j)].rend());
        const Eigen::Vector3d a = Rv * e(j);
        for (int q = 1; q < nv; ++q) path.push_back(add(a * (1.0 - double(q) / nv), 0u));
        path.push_back(c.vent_centre);
        for (int q = 1; q < nv; ++q) path.push_back(add(-a * (double(q) / nv), 0u));
        const auto& opp = c.seams[std::size_t(j + N / 2)];
        path.insert(path.end(), opp.begin(), opp.end());
        c.bands.push_back(path);
      }
    } else {
      for (int k = 0; k < N; ++k) c.bands.push_back(c.seams[std::size_t(k)]);
    }
    for (const auto& b : c.bands)
      for (std::size_t a = 0; a + 1 < b.size(); ++a) c.band_segments.push_back({b[a], b[a + 1]});
  }
  return c;
}

}  // namespace parafsi::model
