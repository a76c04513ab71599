/// \file drop_summary.hpp
/// The parachute drop's observables and their summary (io/: never included by physics
/// headers; depends on Eigen and the standard library only).
///
/// History columns (one `drop_history_row` per output instant, SI units, degrees):
///   t, x, y, z          payload mass centre (m)
///   vx, vy, vz, speed   payload mass-centre velocity (m/s)
///   canopy_diameter     2 × mean distance of the skirt nodes from the canopy axis, the
///                       line confluence → vent centre (`canopy_diameter`)
///   open_force          riser tension at the payload (N)
///   payload_phi_x/y     rotation of the payload's body axis (body +z, towards the riser)
///   canopy_phi_x/y      and of the canopy axis about the fixed X and Y axes (`axis_angles`):
///                       φx = atan2(−a_y, a_z), φy = atan2(a_x, a_z) for the axis a, so an
///                       upright axis (0, 0, 1) gives (0, 0); rotating it by θ about +X gives
///                       φx = θ, about +Y gives φy = θ
///   flight_path_angle   angle of the payload velocity below the horizontal (90 = straight
///                       down; `flight_path_angle`, the release value when v = 0)
///   drag_coefficient    C_D = 2 W_T / (ρ v² S0), W_T the total weight, S0 = π D0²/4
///                       (`drag_coefficient`; NaN below `min_speed_for_cd`)
///
/// Summary (`summarize`, over a history sorted in time):
///   t_f     first time the canopy diameter reaches its steady-descent value D_s, the mean
///           diameter over the last `window` seconds (full inflation); linear interpolation
///           between the two samples that bracket the crossing
///   t_mo    time of the maximum canopy diameter
///   t_p, F_p  time and value of the peak open force
///   v_terminal, cd_terminal  means of speed and drag_coefficient over the last `window` s
///   attitude_amplitude  peak canopy tilt from the vertical over the last `window` s, the
///           tilt of the axis with angles (φx, φy): atan(√(tan²φx + tan²φy))
///   descent_mode (`classify_descent`, over the last `window` s, v_T = v_terminal):
///           vertical  if attitude_amplitude < `vertical_tilt` (10°) and the mean
///                     horizontal speed mean(|v_h|) < `vertical_drift` (0.1) × v_T;
///           gliding   otherwise, if the net horizontal velocity |mean(v_h)| is at least
///                     `glide_fraction` (0.5) of mean(|v_h|): the canopy drifts one way;
///           coning    otherwise: the canopy swings or cones about the vertical, its
///                     horizontal velocity turning so that the drift averages out.
#pragma once
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace parafsi::io {

inline constexpr const char* drop_history_header =
    "t,x,y,z,vx,vy,vz,speed,canopy_diameter,open_force,payload_phi_x,payload_phi_y,canopy_phi_x,canopy_phi_y,"
    "flight_path_angle,drag_coefficient";
inline constexpr const char* drop_summary_header =
    "fabric,t_f,t_mo,t_p,F_p,v_terminal,cd_terminal,attitude_amplitude,descent_mode";

struct drop_history_row {
  double t = 0, x = 0, y = 0, z = 0, vx = 0, vy = 0, vz = 0, speed = 0;
  double canopy_diameter = 0, open_force = 0;
  double payload_phi_x = 0, payload_phi_y = 0, canopy_phi_x = 0, canopy_phi_y = 0;
  double flight_path_angle = 90, drag_coefficient = std::numeric_limits<double>::quiet_NaN();

  static constexpr std::size_t columns = 16;
  std::array<double, columns> values() const {
    return {t,
            x,
            y,
            z,
            vx,
            vy,
            vz,
            speed,
            canopy_diameter,
            open_force,
            payload_phi_x,
            payload_phi_y,
            canopy_phi_x,
            canopy_phi_y,
            flight_path_angle,
            drag_coefficient};
  }
  static drop_history_row from(const std::array<double, columns>& v) {
    drop_history_row r;
    r.t = v[0];
    r.x = v[1];
    r.y = v[2];
    r.z = v[3];
    r.vx = v[4];
    r.vy = v[5];
    r.vz = v[6];
    r.speed = v[7];
    r.canopy_diameter = v[8];
    r.open_force = v[9];
    r.payload_phi_x = v[10];
    r.payload_phi_y = v[11];
    r.canopy_phi_x = v[12];
    r.canopy_phi_y = v[13];
    r.flight_path_angle = v[14];
    r.drag_coefficient = v[15];
    return r;
  }
};

inline constexpr double deg(double rad) noexcept { return rad * 180.0 / std::numbers::pi; }
inline constexpr double rad(double degrees) noexcept { return degrees * std::numbers::pi / 180.0; }

/// 2 × mean distance of the points `skirt` from the line through `a` and `b` (the canopy
/// axis confluence → vent centre). A degenerate axis (a = b) measures from a.
inline double canopy_diameter(std::span<const Eigen::Vector3d> skirt, const Eigen::Vector3d& a,
                              const Eigen::Vector3d& b) {
  if (skirt.empty()) return 0.0;
  Eigen::Vector3d e = b - a;
  const double L = e.norm();
  if (L > 0) e /= L;
  double sum = 0;
  for (const auto& x : skirt) {
    Eigen::Vector3d r = x - a;
    if (L > 0) r -= r.dot(e) * e;
    sum += r.norm();
  }
  return 2.0 * sum / double(skirt.size());
}

/// Rotation of the axis `a` about the fixed X and Y axes (degrees): {φx, φy}.
inline std::array<double, 2> axis_angles(const Eigen::Vector3d& a) {
  return {deg(std::atan2(-a.y(), a.z())), deg(std::atan2(a.x(), a.z()))};
}

/// Tilt of an axis from the vertical given its angles about X and Y (degrees).
inline double tilt_from_angles(double phi_x_deg, double phi_y_deg) {
  const double tx = std::tan(rad(phi_x_deg)), ty = std::tan(rad(phi_y_deg));
  // Past 90° the tangents change sign; measure from the axis itself instead.
  const double cx = std::cos(rad(phi_x_deg)), cy = std::cos(rad(phi_y_deg));
  if (cx <= 0 || cy <= 0) {
    // a ∝ (sin φy cos φx, −sin φx cos φy, cos φx cos φy) has these angles for any signs.
    const Eigen::Vector3d a(std::sin(rad(phi_y_deg)) * cx, -std::sin(rad(phi_x_deg)) * cy, cx * cy);
    return deg(std::acos(std::clamp(a.normalized().z(), -1.0, 1.0)));
  }
  return deg(std::atan(std::sqrt(tx * tx + ty * ty)));
}

/// Angle of the velocity below the horizontal (degrees); `at_rest` when |v| = 0.
inline double flight_path_angle(const Eigen::Vector3d& v, double at_rest = 90.0) {
  const double h = std::hypot(v.x(), v.y());
  if (h == 0.0 && v.z() == 0.0) return at_rest;
  return deg(std::atan2(-v.z(), h));
}

/// C_D = 2 W / (ρ v² S0); NaN below `min_speed` (the quasi-steady C_D means nothing there).
inline double drag_coefficient(double weight, double rho, double speed, double S0, double min_speed = 0.5) {
  if (!(speed >= min_speed)) return std::numeric_limits<double>::quiet_NaN();
  return 2.0 * weight / (rho * speed * speed * S0);
}

struct summary_options {
  double window = 2.0;          ///< the "last seconds" of the terminal means (s)
  double vertical_tilt = 10.0;  ///< degrees
  double vertical_drift = 0.1;  ///< mean horizontal speed / v_T below which the descent is vertical
  double glide_fraction = 0.5;  ///< |mean v_h| / mean |v_h| at or above which it is gliding
};

struct drop_summary {
  std::string fabric;
  double t_f = std::numeric_limits<double>::quiet_NaN(), t_mo = 0, t_p = 0, F_p = 0;
  double v_terminal = 0, cd_terminal = 0, attitude_amplitude = 0;
  double steady_diameter = 0, max_diameter = 0;
  double drift_speed = 0, horizontal_speed = 0;  ///< |mean v_h| and mean |v_h| over the window
  std::string descent_mode = "vertical";

  /// One CSV row in the order of `drop_summary_header`.
  std::string csv_row() const {
    char buf[512];
    std::snprintf(buf, sizeof buf, "%s,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%s", fabric.c_str(), t_f, t_mo, t_p, F_p,
                  v_terminal, cd_terminal, attitude_amplitude, descent_mode.c_str());
    return buf;
  }
};

/// The descent mode from the window's numbers (rule in the file comment).
inline std::string classify_descent(double attitude_amplitude, double drift_speed, double horizontal_speed,
                                    double v_terminal, const summary_options& o = {}) {
  if (attitude_amplitude < o.vertical_tilt && horizontal_speed < o.vertical_drift * v_terminal) return "vertical";
  if (horizontal_speed > 0 && drift_speed >= o.glide_fraction * horizontal_speed) return "gliding";
  return "coning";
}

/// Summary of a history sorted in time (see the file comment). An empty history gives
/// the default summary; a history shorter than the window averages over all of it.
inline drop_summary summarize(std::span<const drop_history_row> h, std::string fabric_name = "",
                              const summary_options& o = {}) {
  drop_summary s;
  s.fabric = std::move(fabric_name);
  if (h.empty()) return s;
  const double t_end = h.back().t;
  const double t_w = t_end - o.window;
  std::size_t first = 0;
  while (first + 1 < h.size() && h[first].t < t_w - 1e-12) ++first;
  double nd = 0, sumD = 0, sumV = 0, sumCd = 0, ncd = 0, sumVh = 0;
  Eigen::Vector2d sumVhv = Eigen::Vector2d::Zero();
  for (std::size_t i = first; i < h.size(); ++i) {
    const auto& r = h[i];
    sumD += r.canopy_diameter;
    sumV += r.speed;
    if (std::isfinite(r.drag_coefficient)) {
      sumCd += r.drag_coefficient;
      ncd += 1;
    }
    sumVh += std::hypot(r.vx, r.vy);
    sumVhv += Eigen::Vector2d(r.vx, r.vy);
    s.attitude_amplitude = std::max(s.attitude_amplitude, tilt_from_angles(r.canopy_phi_x, r.canopy_phi_y));
    nd += 1;
  }
  s.steady_diameter = sumD / nd;
  s.v_terminal = sumV / nd;
  s.cd_terminal = ncd > 0 ? sumCd / ncd : std::numeric_limits<double>::quiet_NaN();
  s.horizontal_speed = sumVh / nd;
  s.drift_speed = (sumVhv / nd).norm();
  // Peaks.
  std::size_t imo = 0, ip = 0;
  for (std::size_t i = 0; i < h.size(); ++i) {
    if (h[i].canopy_diameter > h[imo].canopy_diameter) imo = i;
    if (h[i].open_force > h[ip].open_force) ip = i;
  }
  s.t_mo = h[imo].t;
  s.max_diameter = h[imo].canopy_diameter;
  s.t_p = h[ip].t;
  s.F_p = h[ip].open_force;
  // Full inflation: first crossing of the steady diameter.
  for (std::size_t i = 0; i < h.size(); ++i) {
    if (h[i].canopy_diameter >= s.steady_diameter) {
      if (i == 0) {
        s.t_f = h[0].t;
      } else {
        const double d0 = h[i - 1].canopy_diameter, d1 = h[i].canopy_diameter;
        const double f = d1 > d0 ? (s.steady_diameter - d0) / (d1 - d0) : 1.0;
        s.t_f = h[i - 1].t + std::clamp(f, 0.0, 1.0) * (h[i].t - h[i - 1].t);
      }
      break;
    }
  }
  s.descent_mode = classify_descent(s.attitude_amplitude, s.drift_speed, s.horizontal_speed, s.v_terminal, o);
  return s;
}

/// Append one history row as CSV text (with its '\n') to `line`: the shortest text that
/// reads back to the same double (so a restart that re-reads the history keeps it
/// bit-exact), NaN written as `nan`.
inline void append_history_row(std::string& line, const drop_history_row& r) {
  const auto v = r.values();
  char buf[40];
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i) line += ',';
    if (std::isfinite(v[i])) {
      const auto res = std::to_chars(buf, buf + sizeof buf, v[i]);
      line.append(buf, std::size_t(res.ptr - buf));
    } else {
      line += "nan";
    }
  }
  line += '\n';
}

/// One history row as CSV text on a stream (`append_history_row`).
inline void write_history_row(std::ostream& os, const drop_history_row& r) {
  std::string line;
  append_history_row(line, r);
  os << line;
}

}  // namespace parafsi::io
