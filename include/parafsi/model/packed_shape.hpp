/// \file packed_shape.hpp
/// Initial (packed) canopy shapes: positions only. The reference (stress-free) geometry
/// stays the flat cut pattern of flat_circular_canopy.hpp, which also sets the lumped
/// masses and fibre axes (methods note §9: "do not scale the reference").
///
/// Frame: the canopy's vent centre at the origin, its axis +z (confluence below, z < 0).
///
///   - `constructed`: the cut pattern itself (a flat circular canopy's constructed shape
///     is flat); zero initial strain.
///   - `reduced_radius{s}`: the constructed shape scaled radially, (x, y, z) → (s x, s y, z),
///     s in (0, 1] (0.1–0.3 typical). The axial length is kept (zero for the flat pattern),
///     so the canopy becomes a disk of diameter s·D0 whose elements are shorter than their
///     reference in every direction and carry no stress under no-compression.
///   - `star_fold{θ_s}`: a slender isometric star fold. Each half-gore (a planar piece of
///     the pattern bounded by a seam and the gore centreline) is moved rigidly: the seams
///     go onto a cone of half-angle θ_s about −z, the centrelines onto an outer cone of
///     half-angle θ_m, pleating each gore into an outward lobe. With a = cos(π/N), θ_m is
///     the outer root of  cos θ_s cos θ_m + a sin θ_s sin θ_m = a  (the angle between a seam
///     and its gore's centreline, π/N, is preserved), so every element keeps its
///     reference shape exactly (zero strain). θ_s → 0 gives the tightest fold, with
///     θ_m → π/N. A point of half-gore (k, side) at p = α e_k + β m_k in the pattern
///     (e_k the seam direction, m_k = a n_k the centreline point at unit seam distance)
///     goes to α S_k + β M_k with S_k = sin θ_s e_k − cos θ_s e_z and
///     M_k = a (sin θ_m n_k − cos θ_m e_z).
///   - `bundle{d}`: the canopy at line stretch as it leaves its deployment bag, gathered
///     into a slender bundle along the axis: the vent centre at the top (the origin), the
///     gores running down the axis, the skirt below with its N corners (the line
///     attachments) on the mouth circle of diameter d (d/D0 in [0.01, 0.5], 0.05–0.1 typical;
///     the elements' areas shrink to ≈ d/D0 of their reference, so a smaller mouth is refused).
///     Each half-gore is mapped linearly like the star fold, p = α e_k + β m_k ↦ α S_k + β M_k,
///     with the seams on a cone and the centrelines a times as far out and down:
///         S_k = ρ e_k − ζ e_z,   M_k = a (ρ n_k − ζ e_z),   ρ = d / (2 R_s),
///         ζ = cos(π/2N) √(1 − ρ²).
///     With G = [[1, a²], [a², a²]] the reference Gram matrix of (e_k, m_k) and G' that of
///     (S_k, M_k), G − G' = [[A, B], [B, a² A]] with A = (1 − ρ²)(1 − a)/2 > 0 and
///     B = −a A, so G − G' is positive semi-definite with one null direction: no element is
///     longer than its reference in any direction, and each is at its reference length in
///     exactly one (near the meridian: the seam and centreline lines are at
///     √(ρ² + ζ²) ≈ cos(π/2N) of their reference length, 0.981 for N = 8, 0.998 for
///     N = 28); across the gore (in hoop) the cloth is gathered to ≈ ρ of its width,
///     stress-free under no-compression (up to the wrinkling model's residual r_c of the
///     compressive stress, docs/model.md). ζ is the largest meridional extent a map that is
///     linear on each half-gore allows (a longer one stretches the half-gore along the
///     bisector of seam and centreline), so the vent → skirt-corner height ζ (R_s − R_v) is
///     0.976–0.980 of the seam length for N = 8 and d = 0.1–0.05 D0. Element area ratio
///     ≈ ρ (no degenerate element); the normals point outwards from the axis. The
///     suspension lines (suspension_lines.hpp) then meet at the confluence √(Ls² − d²/4)
///     below the skirt corners: every line straight and exactly Ls long, at stretch.
///   The "pulled" shape (structure-only pre-simulation) needs the solver and is built by
///   the drop program from one of these.
#pragma once
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "flat_circular_canopy.hpp"

namespace parafsi::model {

enum class packed_kind { constructed, reduced_radius, star_fold, bundle };

struct packed_shape {
  packed_kind kind = packed_kind::reduced_radius;
  double scale = 0.2;                                       ///< s of reduced_radius
  double seam_half_angle = 5.0 * std::numbers::pi / 180.0;  ///< θ_s of star_fold (rad)
  double mouth_diameter = 0.1;                              ///< d / D0 of bundle

  static packed_shape constructed() { return {packed_kind::constructed, 1.0, 0.0}; }
  static packed_shape reduced_radius(double s) { return {packed_kind::reduced_radius, s, 0.0}; }
  static packed_shape star_fold(double theta_s) { return {packed_kind::star_fold, 1.0, theta_s}; }
  /// The bundle at line stretch with a mouth of `mouth_diameter_fraction` · D0 across the skirt corners.
  static packed_shape bundle(double mouth_diameter_fraction) {
    return {packed_kind::bundle, 1.0, 0.0, mouth_diameter_fraction};
  }

  void validate() const {
    if (kind == packed_kind::reduced_radius)
      require(scale > 0 && scale <= 1 && std::isfinite(scale),
              "model::packed_shape: reduced-radius scale s must be in (0, 1], got ", scale);
    if (kind == packed_kind::star_fold)
      require(seam_half_angle >= 0 && seam_half_angle < 0.5 * std::numbers::pi,
              "model::packed_shape: star-fold seam half-angle must be in [0, pi/2) rad, got ", seam_half_angle);
    if (kind == packed_kind::bundle)
      require(mouth_diameter >= 0.01 && mouth_diameter <= 0.5,
              "model::packed_shape: bundle mouth diameter d/D0 must be in [0.01, 0.5], got ", mouth_diameter);
  }
  const char* name() const {
    switch (kind) {
      case packed_kind::constructed: return "constructed";
      case packed_kind::reduced_radius: return "reduced_radius";
      case packed_kind::star_fold: return "star_fold";
      default: return "bundle";
    }
  }
};

/// Outer-cone half-angle θ_m of the star fold for N gores and seam half-angle θ_s.
inline double star_fold_centreline_angle(int gores, double theta_s) {
  const double a = std::cos(std::numbers::pi / gores);
  const double A = std::cos(theta_s), B = a * std::sin(theta_s);
  return std::atan2(B, A) + std::acos(std::clamp(a / std::hypot(A, B), -1.0, 1.0));
}

/// Initial positions of the canopy nodes (indexed like c.positions) in the shape `s`.
inline std::vector<Eigen::Vector3d> packed_positions(const canopy_mesh& c, const packed_shape& s) {
  s.validate();
  std::vector<Eigen::Vector3d> x = c.positions;
  if (s.kind == packed_kind::constructed) return x;
  if (s.kind == packed_kind::reduced_radius) {
    for (auto& p : x) p.head<2>() *= s.scale;
    return x;
  }
  const int N = c.params.gores;
  const double pi = std::numbers::pi, a = std::cos(pi / N);
  const Eigen::Vector3d ez = Eigen::Vector3d::UnitZ();
  // Images S of the unit seam vector e_s and M of the unit centreline point a n_m of a half-gore.
  double Sh, Sz, Mh, Mz;  // S = Sh e_s − Sz e_z, M = a (Mh n_m − Mz e_z)
  if (s.kind == packed_kind::star_fold) {
    const double ts = s.seam_half_angle, tm = star_fold_centreline_angle(N, ts);
    Sh = std::sin(ts), Sz = std::cos(ts), Mh = std::sin(tm), Mz = std::cos(tm);
  } else {  // bundle; ρ <= 0.5 since R_s >= D0/2
    const double rho = 0.5 * s.mouth_diameter * c.params.nominal_diameter / c.skirt_radius;
    Sh = Mh = rho;
    Sz = Mz = std::cos(0.5 * pi / N) * std::sqrt(1.0 - rho * rho);
  }
  for (auto& p : x) {
    const double r = p.head<2>().norm();
    if (r == 0.0) continue;  // the vent centre is the apex
    double phi = std::atan2(p.y(), p.x());
    if (phi < 0) phi += 2.0 * pi;
    const double w = 2.0 * pi / N;
    const int k = std::min(N - 1, int(std::floor(phi / w)));
    const bool second = phi - k * w > 0.5 * w;  // half next to seam k+1
    const double th_seam = (second ? k + 1 : k) * w, th_mid = (k + 0.5) * w;
    const Eigen::Vector3d es(std::cos(th_seam), std::sin(th_seam), 0.0), nm(std::cos(th_mid), std::sin(th_mid), 0.0);
    const Eigen::Vector3d mk = a * nm;
    // Solve p = α es + β mk in the plane.
    Eigen::Matrix2d M;
    M << es.x(), mk.x(), es.y(), mk.y();
    const Eigen::Vector2d ab = M.colPivHouseholderQr().solve(p.head<2>());
    const Eigen::Vector3d S = Sh * es - Sz * ez;
    const Eigen::Vector3d Mk = a * (Mh * nm - Mz * ez);
    p = ab.x() * S + ab.y() * Mk;
  }
  return x;
}

}  // namespace parafsi::model
