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

enum class packed_kind { constructed, reduced_radius, star_fold };

struct packed_shape {
  packed_kind kind = packed_kind::reduced_radius;
  double scale = 0.2;                                       ///< s of reduced_radius
  double seam_half_angle = 5.0 * std::numbers::pi / 180.0;  ///< θ_s of star_fold (rad)

  static packed_shape constructed() { return {packed_kind::constructed, 1.0, 0.0}; }
  static packed_shape reduced_radius(double s) { return {packed_kind::reduced_radius, s, 0.0}; }
  static packed_shape star_fold(double theta_s) { return {packed_kind::star_fold, 1.0, theta_s}; }

  void validate() const {
    if (kind == packed_kind::reduced_radius)
      require(scale > 0 && scale <= 1 && std::isfinite(scale),
              "model::packed_shape: reduced-radius scale s must be in (0, 1], got ", scale);
    if (kind == packed_kind::star_fold)
      require(seam_half_angle >= 0 && seam_half_angle < 0.5 * std::numbers::pi,
              "model::packed_shape: star-fold seam half-angle must be in [0, pi/2) rad, got ", seam_half_angle);
  }
  const char* name() const {
    switch (kind) {
      case packed_kind::constructed: return "constructed";
      case packed_kind::reduced_radius: return "reduced_radius";
      default: return "star_fold";
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
  const double pi = std::numbers::pi, a = std::cos(pi / N), ts = s.seam_half_angle;
  const double tm = star_fold_centreline_angle(N, ts);
  const Eigen::Vector3d ez = Eigen::Vector3d::UnitZ();
  for (auto& p : x) {
    const double r = p.head<2>().norm();
    if (r == 0.0) continue;  // the vent centre is the fold's apex
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
    const Eigen::Vector3d S = std::sin(ts) * es - std::cos(ts) * ez;
    const Eigen::Vector3d Mk = a * (std::sin(tm) * nm - std::cos(tm) * ez);
    p = ab.x() * S + ab.y() * Mk;
  }
  return x;
}

}  // namespace parafsi::model
