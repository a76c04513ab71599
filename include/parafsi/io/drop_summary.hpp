/// \file drop_summary.hpp
/// The parachute drop's observables and their summary (io/: never included by physics
/// headers; depends on Eigen, the standard library and io/gaussian_filter.hpp).
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
///   open_force_filtered open_force low-pass filtered without phase shift (N): the Gaussian
///                       FIR of io/gaussian_filter.hpp, cut-off `summary_options::force_cutoff`
///                       (10 Hz: σ = 13.25 ms, half-window H = 11 rows at 5 ms), on the row
///                       index (rows `sample_interval` apart); the first and last H rows by
///                       the filter's edge rule (local-linear fit on the truncated window).
///                       A row's value needs the H rows after it: a growing history fills
///                       it as each window completes (`drop_history_filter`), the last H
///                       rows at the end of the run.
///
/// Summary (`summarize`, over a history sorted in time):
///   t_f     first time the canopy diameter reaches its steady-descent value D_s, the mean
///           diameter over the last `window` seconds (full inflation); linear interpolation
///           between the two samples that bracket the crossing
///   t_mo    the inflation overshoot: the first maximum of the canopy diameter after t_f.
///           Scanning the samples from t_f on with the running maximum M, the first sample
///           that lies `overshoot_drop` · D_s (1 %) or more below M ends the scan; t_mo is
///           the (first) sample at M. A wiggle smaller than that band does not end it; a
///           diameter that never falls back by the band gives its largest value after t_f.
///           (The global maximum, often a later breathing peak, is `t_max_diameter`.)
///   t_p, F_p  time and value of the peak of open_force_filtered over the opening, computed
///           here with the same filter (`force_cutoff`, `sample_interval`) as the history
///           column, so the two agree bit for bit; the raw sample maximum over the opening
///           is t_p_raw, F_p_raw. The opening: from the first sample to the one that ends
///           the overshoot scan of t_mo (the diameter fallen back by the band below its
///           overshoot) if that sample lies before the last `window` seconds (where D_s is
///           averaged); the whole history when the canopy does not fall back, never reaches
///           D_s, or the run is too short to have a steady window (a run of the opening
///           alone). A later peak of the ringing in descent (a filtered 18.8 N at 5.7 s
///           above the 18.2 N opening of the permeable mat509) is not the opening load.
///   v_terminal, cd_terminal  means of speed and drag_coefficient over the terminal window
///           `terminal_window`: the last `window` s, or, when the descent swings with a
///           measured period T (`classify_descent` over [t_f, t_end], a whole period seen:
///           three centre crossings or more) and `whole_periods` is set, the last n T
///           seconds, n = ⌈window / T⌉ whole periods, fewer (n ≥ 1) when n T would reach
///           back before t_f (before the first row if D_s is never reached). Speed and drag
///           oscillate with the swing (±0.05 in C_D on the default drop); a window of whole
///           periods takes their mean, one that cuts a period takes a phase of it.
///   attitude_amplitude  peak canopy tilt from the vertical over the last `window` s, the
///           tilt of the axis with angles (φx, φy): atan(√(tan²φx + tan²φy))
///   descent_mode  `classify_descent` over the descent after full inflation, [t_f, t_end]
///           (rule at `classify_descent`): vertical | gliding | coning | planar |
///           undetermined (the window holds fewer than `min_periods` swing periods, or an
///           irregular swing)
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
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "gaussian_filter.hpp"

namespace parafsi::io {

inline constexpr const char* drop_history_header =
    "t,x,y,z,vx,vy,vz,speed,canopy_diameter,open_force,payload_phi_x,payload_phi_y,canopy_phi_x,canopy_phi_y,"
    "flight_path_angle,drag_coefficient,open_force_filtered";
/// The history header of the earlier 16-column format (without open_force_filtered): a
/// restart from such a history is refused naming both headers.
inline constexpr const char* drop_history_header_16 =
    "t,x,y,z,vx,vy,vz,speed,canopy_diameter,open_force,payload_phi_x,payload_phi_y,canopy_phi_x,canopy_phi_y,"
    "flight_path_angle,drag_coefficient";
inline constexpr const char* drop_summary_header =
    "fabric,t_f,t_mo,t_p,F_p,v_terminal,cd_terminal,attitude_amplitude,descent_mode";

struct drop_history_row {
  double t = 0, x = 0, y = 0, z = 0, vx = 0, vy = 0, vz = 0, speed = 0;
  double canopy_diameter = 0, open_force = 0;
  double payload_phi_x = 0, payload_phi_y = 0, canopy_phi_x = 0, canopy_phi_y = 0;
  double flight_path_angle = 90, drag_coefficient = std::numeric_limits<double>::quiet_NaN();
  double open_force_filtered = std::numeric_limits<double>::quiet_NaN();  ///< NaN until its window is complete

  static constexpr std::size_t columns = 17;
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
            drag_coefficient,
            open_force_filtered};
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
    r.open_force_filtered = v[16];
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
  double window = 2.0;              ///< the "last seconds" of D_s and (at least) of the terminal means (s)
  bool whole_periods = true;        ///< terminal means over whole swing periods (file comment)
  double force_cutoff = 10.0;       ///< −3 dB frequency of the open-force filter (Hz; io/gaussian_filter.hpp)
  double sample_interval = 0.0;     ///< row interval (s) the filter assumes; 0 = (t_last − t_first)/(rows − 1)
  double overshoot_drop = 0.01;     ///< fall from the running maximum, / D_s, that ends the t_mo scan
  double vertical_tilt = 10.0;      ///< degrees
  double vertical_drift = 0.1;      ///< mean horizontal speed / v_T below which the descent is vertical
  double glide_fraction = 0.5;      ///< |mean v_h| / mean |v_h| at or above which it is gliding
  double swing_tilt = 2.0;          ///< swing amplitude (degrees) below which the attitude is steady
  double min_periods = 2.0;         ///< swing periods the mode window must hold to call a swing
  double cone_turn_fraction = 0.5;  ///< |swept turns| / periods at or above which a swing is coning
  double planar_ratio = 0.25;       ///< λ2/λ1 (minor/major tilt variance) at or below which it is planar
  double centre_band = 0.3;         ///< turning counted only where |q| >= centre_band · q_rms
};

/// The numbers behind the descent mode (`classify_descent`), over the mode window.
struct descent_statistics {
  std::string mode = "vertical";
  double t_start = 0, duration = 0;  ///< the window [t_start, t_start + duration] (s)
  double peak_tilt = 0;              ///< largest tilt of the canopy axis (deg)
  double mean_tilt = 0;              ///< tilt of the mean tilt vector, atan|p̄| (deg)
  double swing_amplitude = 0;        ///< atan √(2 λ1) (deg): a sinusoid's amplitude along the principal direction
  double principal_ratio = 0;        ///< λ2 / λ1 of the tilt vector's covariance (0: a line, 1: a circle)
  double swing_period = std::numeric_limits<double>::quiet_NaN();  ///< s (NaN: not measured)
  double periods = 0;                                              ///< duration / swing_period
  long centre_crossings = 0;    ///< crossings of the mean along the principal direction
  double swept_turns = 0;       ///< signed turns of q about the mean (counted off the centre band)
  double turn_fraction = 0;     ///< |swept_turns| / periods
  double drift_speed = 0;       ///< |mean v_h| (m/s)
  double horizontal_speed = 0;  ///< mean |v_h| (m/s)
};

struct drop_summary {
  std::string fabric;
  double t_f = std::numeric_limits<double>::quiet_NaN(), t_mo = std::numeric_limits<double>::quiet_NaN();
  double t_p = 0, F_p = 0;          ///< peak of the filtered open force
  double t_p_raw = 0, F_p_raw = 0;  ///< the raw sample maximum of open_force
  double v_terminal = 0, cd_terminal = 0, attitude_amplitude = 0;
  double steady_diameter = 0;                   ///< D_s
  double terminal_window = 0;                   ///< the span of v_terminal, cd_terminal (s)
  double overshoot_diameter = 0;                ///< the diameter at t_mo
  double max_diameter = 0, t_max_diameter = 0;  ///< the largest diameter and its (first) time
  descent_statistics descent;
  std::string descent_mode = "vertical";

  /// One CSV row in the order of `drop_summary_header`.
  std::string csv_row() const {
    char buf[512];
    std::snprintf(buf, sizeof buf, "%s,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%s", fabric.c_str(), t_f, t_mo, t_p, F_p,
                  v_terminal, cd_terminal, attitude_amplitude, descent_mode.c_str());
    return buf;
  }
};

/// The open-force filter of `o` for the history `h`: cut-off `o.force_cutoff`, sample
/// interval `o.sample_interval` or, when 0, the mean interval of h (1 s for fewer than
/// two rows).
inline gaussian_lowpass open_force_lowpass(std::span<const drop_history_row> h, const summary_options& o = {}) {
  double dt = o.sample_interval;
  if (dt == 0.0)
    dt = h.size() >= 2 && h.back().t > h.front().t ? (h.back().t - h.front().t) / double(h.size() - 1) : 1.0;
  return gaussian_lowpass(o.force_cutoff, dt);
}

/// open_force_filtered of a growing history: `complete(h)` fills the rows whose filter
/// window is complete (H rows after them exist) and returns them; `finish(h)` fills the
/// rest with the edge rule at the end of the run. Each row is filled once, in order; a
/// history filled this way piecewise equals one filled at once (gaussian_filter.hpp).
///   io::drop_history_filter filt(io::gaussian_lowpass(10.0, 0.005));
///   history.push_back(row);  for (const auto& r : filt.complete(history)) writer.write(r);
///   for (const auto& r : filt.finish(history)) writer.write(r);
class drop_history_filter {
 public:
  explicit drop_history_filter(gaussian_lowpass f) : f_(std::move(f)) {}
  const gaussian_lowpass& lowpass() const noexcept { return f_; }
  std::size_t filled() const noexcept { return done_; }  ///< rows filled so far

  std::span<const drop_history_row> complete(std::vector<drop_history_row>& h) { return fill(h, false); }
  std::span<const drop_history_row> finish(std::vector<drop_history_row>& h) { return fill(h, true); }

 private:
  std::span<const drop_history_row> fill(std::vector<drop_history_row>& h, bool end) {
    const std::size_t n = h.size(), H = f_.half_window();
    const std::size_t upto = end ? n : (n > H ? n - H : 0);
    const std::size_t from = std::min(done_, upto);
    for (std::size_t i = from; i < upto; ++i)
      h[i].open_force_filtered = f_.at(n, i, [&](std::size_t j) { return h[j].open_force; });
    done_ = std::max(done_, upto);
    return std::span<const drop_history_row>(h.data() + from, upto - from);
  }
  gaussian_lowpass f_;
  std::size_t done_ = 0;
};

namespace detail {

/// The samples where q·e crosses zero, each counted once q·e has gone past ±h on the other
/// side (hysteresis against noise); the time by linear interpolation of the last sign change.
inline std::vector<double> centre_crossings(std::span<const double> t, std::span<const double> s, double h) {
  std::vector<double> c;
  int state = 0;
  double last_zero = t.empty() ? 0.0 : t[0];
  for (std::size_t k = 0; k < s.size(); ++k) {
    if (k > 0 && ((s[k - 1] <= 0 && s[k] > 0) || (s[k - 1] >= 0 && s[k] < 0))) {
      const double f = s[k - 1] / (s[k - 1] - s[k]);
      last_zero = t[k - 1] + std::clamp(f, 0.0, 1.0) * (t[k] - t[k - 1]);
    }
    const int side = s[k] > h ? 1 : (s[k] < -h ? -1 : 0);
    if (side != 0 && side != state) {
      if (state != 0) c.push_back(last_zero);
      state = side;
    }
  }
  return c;
}

}  // namespace detail

/// The descent mode of the rows `w` (the mode window, sorted in time), v_T = `v_terminal`.
/// Tilt vector of the canopy axis a: p = (a_x, a_y)/a_z = (tan φy, −tan φx) (the axis's
/// lean, its direction turned by 90° from (tan φx, tan φy)); q = p − mean(p); λ1 ≥ λ2 and
/// e1 the eigen-pairs of the covariance mean(q qᵀ); v_h the horizontal payload velocity.
///   1. vertical   if the peak tilt < `vertical_tilt` (10°) and mean |v_h| < `vertical_drift`
///                 (0.1) × v_T. Otherwise:
///   2. the swing: amplitude A = atan √(2 λ1); if A >= `swing_tilt` (2°), its period from
///                 the crossings of q·e1 through 0 (hysteresis ± 0.5 rms(q·e1)): with m ≥ 2
///                 crossings c_1 … c_m, T = (c_k − c_1)/((k − 1)/2) with k the last crossing
///                 in the direction of c_1 (k − 1 even: whole periods, so an offset of the
///                 centre, which moves rising and falling crossings apart, cancels), or
///                 T = 2 (c_2 − c_1) from two crossings. The window must hold
///                 `min_periods` (2) periods of the swing: duration ≥ 2 T and m ≥ 2 × 2 = 4
///                 crossings (three half periods seen between the first and the last, so a
///                 swing that only starts late in the window does not pass on the window's
///                 length); if it does not, undetermined: a swing seen for less than that
///                 could still be a glide, a cone or a planar swing.
///   3. gliding    if |mean v_h| ≥ `glide_fraction` (0.5) × mean |v_h| (the payload drifts one
///                 way), or if there is no swing (A < 2°: a steady tilt or drift).
///   4. coning     if the tilt vector turns one way round: the signed angle q sweeps about
///                 the mean, Σ atan2(q_k × q_{k+1}, q_k · q_{k+1}) over the steps with both
///                 |q| ≥ `centre_band` (0.3) × rms|q| (the turn a swing makes through the
///                 centre is not counted), is at least `cone_turn_fraction` (0.5) of a turn per
///                 period: |turns| / (duration / T) ≥ 0.5. An elliptic path with minor/major
///                 axis ratio above ≈ 0.3 counts as a cone.
///   5. planar     otherwise, if the swing has a dominant direction: λ2/λ1 ≤ `planar_ratio`
///                 (0.25, minor/major rms axis ≤ 0.5): the tilt swings back and forth along a
///                 line.
///   6. undetermined otherwise (an irregular swing, neither turning nor along a line).
inline descent_statistics classify_descent(std::span<const drop_history_row> w, double v_terminal,
                                           const summary_options& o = {}) {
  descent_statistics d;
  if (w.empty()) return d;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  d.t_start = w.front().t;
  d.duration = w.back().t - w.front().t;
  const std::size_t n = w.size();
  std::vector<double> t(n), s(n);
  std::vector<Eigen::Vector2d> q(n);
  Eigen::Vector2d pm = Eigen::Vector2d::Zero(), vm = Eigen::Vector2d::Zero();
  double vh = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const auto& r = w[k];
    t[k] = r.t;
    q[k] = Eigen::Vector2d(std::tan(rad(r.canopy_phi_y)), -std::tan(rad(r.canopy_phi_x)));
    pm += q[k];
    vm += Eigen::Vector2d(r.vx, r.vy);
    vh += std::hypot(r.vx, r.vy);
    d.peak_tilt = std::max(d.peak_tilt, tilt_from_angles(r.canopy_phi_x, r.canopy_phi_y));
  }
  pm /= double(n);
  d.drift_speed = (vm / double(n)).norm();
  d.horizontal_speed = vh / double(n);
  d.mean_tilt = deg(std::atan(pm.norm()));
  if (d.peak_tilt < o.vertical_tilt && d.horizontal_speed < o.vertical_drift * v_terminal) {
    d.mode = "vertical";
    return d;
  }
  Eigen::Matrix2d C = Eigen::Matrix2d::Zero();
  for (auto& x : q) {
    x -= pm;
    C += x * x.transpose();
  }
  C /= double(n);
  // Eigen-pairs of the symmetric 2×2 covariance in closed form.
  const double tr = C(0, 0) + C(1, 1), df = 0.5 * (C(0, 0) - C(1, 1)), od = C(0, 1);
  const double rr = std::hypot(df, od), l1 = 0.5 * tr + rr, l2 = std::max(0.0, 0.5 * tr - rr);
  const double ang = 0.5 * std::atan2(2.0 * od, C(0, 0) - C(1, 1));
  const Eigen::Vector2d e1(std::cos(ang), std::sin(ang));
  d.principal_ratio = l1 > 0 ? l2 / l1 : 0.0;
  d.swing_amplitude = deg(std::atan(std::sqrt(2.0 * l1)));
  const bool swings = d.swing_amplitude >= o.swing_tilt;
  if (swings) {
    double ss = 0;
    for (std::size_t k = 0; k < n; ++k) {
      s[k] = q[k].dot(e1);
      ss += s[k] * s[k];
    }
    const auto c = detail::centre_crossings(t, s, 0.5 * std::sqrt(ss / double(n)));
    d.centre_crossings = long(c.size());
    if (c.size() >= 3) {
      const std::size_t k = (c.size() - 1) / 2 * 2;  // crossings c[0], c[2], … go the same way
      d.swing_period = (c[k] - c[0]) / double(k / 2);
      d.periods = d.duration / d.swing_period;
    } else if (c.size() == 2) {
      d.swing_period = 2.0 * (c.back() - c.front());
      d.periods = d.duration / d.swing_period;
    }
    // Signed turning of q about the mean, off the centre band (reported also when the
    // window is too short to judge).
    const double band = o.centre_band * std::sqrt(tr);
    double turn = 0;
    for (std::size_t k = 0; k + 1 < n; ++k)
      if (q[k].norm() >= band && q[k + 1].norm() >= band)
        turn += std::atan2(q[k].x() * q[k + 1].y() - q[k].y() * q[k + 1].x(), q[k].dot(q[k + 1]));
    d.swept_turns = turn / (2.0 * std::numbers::pi);
    d.turn_fraction = d.periods > 0 ? std::fabs(d.swept_turns) / d.periods : 0.0;
    if (!(double(c.size()) >= 2.0 * o.min_periods && d.periods >= o.min_periods)) {
      d.mode = "undetermined";
      return d;
    }
  } else {
    d.swing_period = nan;
  }
  if (!swings || d.drift_speed >= o.glide_fraction * d.horizontal_speed) d.mode = "gliding";
  else if (d.turn_fraction >= o.cone_turn_fraction) d.mode = "coning";
  else if (d.principal_ratio <= o.planar_ratio) d.mode = "planar";
  else d.mode = "undetermined";
  return d;
}

/// The inflation overshoot (rule in the file comment): the index of the first maximum of
/// the canopy diameter at or after index `from`, a scan ended by a fall of `drop` below the
/// running maximum; `end` (if given) receives the index of the sample that ended the scan
/// (h.size() − 1 when none did).
inline std::size_t first_diameter_maximum(std::span<const drop_history_row> h, std::size_t from, double drop,
                                          std::size_t* end = nullptr) {
  std::size_t im = from, i = from;
  for (; i < h.size(); ++i) {
    if (h[i].canopy_diameter > h[im].canopy_diameter) im = i;
    if (h[i].canopy_diameter <= h[im].canopy_diameter - drop) break;
  }
  if (end) *end = std::min(i, h.size() - 1);
  return im;
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
  double nd = 0, sumD = 0;
  for (std::size_t i = first; i < h.size(); ++i) {
    const auto& r = h[i];
    sumD += r.canopy_diameter;
    s.attitude_amplitude = std::max(s.attitude_amplitude, tilt_from_angles(r.canopy_phi_x, r.canopy_phi_y));
    nd += 1;
  }
  s.steady_diameter = sumD / nd;
  // Means of speed and drag coefficient over the rows from `from` on.
  const auto terminal_means = [&](std::size_t from) {
    double n = 0, sumV = 0, sumCd = 0, ncd = 0;
    for (std::size_t i = from; i < h.size(); ++i) {
      sumV += h[i].speed;
      n += 1;
      if (std::isfinite(h[i].drag_coefficient)) {
        sumCd += h[i].drag_coefficient;
        ncd += 1;
      }
    }
    s.v_terminal = sumV / n;
    s.cd_terminal = ncd > 0 ? sumCd / ncd : std::numeric_limits<double>::quiet_NaN();
    s.terminal_window = t_end - h[from].t;
  };
  terminal_means(first);
  // The largest diameter.
  std::size_t imax = 0;
  for (std::size_t i = 0; i < h.size(); ++i)
    if (h[i].canopy_diameter > h[imax].canopy_diameter) imax = i;
  s.t_max_diameter = h[imax].t;
  s.max_diameter = h[imax].canopy_diameter;
  // Full inflation: first crossing of the steady diameter.
  std::size_t i_f = h.size();
  for (std::size_t i = 0; i < h.size(); ++i) {
    if (h[i].canopy_diameter >= s.steady_diameter) {
      if (i == 0) {
        s.t_f = h[0].t;
      } else {
        const double d0 = h[i - 1].canopy_diameter, d1 = h[i].canopy_diameter;
        const double f = d1 > d0 ? (s.steady_diameter - d0) / (d1 - d0) : 1.0;
        s.t_f = h[i - 1].t + std::clamp(f, 0.0, 1.0) * (h[i].t - h[i - 1].t);
      }
      i_f = i;
      break;
    }
  }
  // The inflation overshoot, from the first sample at or above D_s; the opening ends where
  // its scan ends.
  std::size_t i_open = h.size() - 1;
  if (i_f < h.size()) {
    std::size_t i_scan = i_open;
    const std::size_t imo = first_diameter_maximum(h, i_f, o.overshoot_drop * s.steady_diameter, &i_scan);
    s.t_mo = h[imo].t;
    s.overshoot_diameter = h[imo].canopy_diameter;
    // Only a scan that ends before the window D_s is averaged over closes the opening (a
    // run of the opening alone has no steady diameter to fall back to).
    if (h[i_scan].t < t_w) i_open = i_scan;
  }
  // The opening load: peaks of the raw and the filtered open force (the filter of the
  // history column) over the opening, samples 0 … i_open.
  const gaussian_lowpass lp = open_force_lowpass(h, o);
  const auto force = [&](std::size_t j) { return h[j].open_force; };
  std::size_t ip = 0;
  for (std::size_t i = 0; i <= i_open; ++i) {
    if (h[i].open_force > h[ip].open_force) ip = i;
    const double Ff = lp.at(h.size(), i, force);
    if (i == 0 || Ff > s.F_p) {
      s.F_p = Ff;
      s.t_p = h[i].t;
    }
  }
  s.t_p_raw = h[ip].t;
  s.F_p_raw = h[ip].open_force;
  // Descent mode over the rows after full inflation.
  const std::size_t i_descent = i_f < h.size() ? i_f : 0;
  s.descent = classify_descent(h.subspan(i_descent), s.v_terminal, o);
  s.descent_mode = s.descent.mode;
  // The terminal means over whole swing periods, when the swing has a period.
  const double T = s.descent.swing_period;
  if (o.whole_periods && std::isfinite(T) && T > 0 && s.descent.centre_crossings >= 3) {
    const double span = t_end - h[i_descent].t;
    double n = std::ceil(o.window / T - 1e-9);
    if (n * T > span) n = std::floor(span / T);
    if (n >= 1) {
      // The row nearest to t_end − n T (the window is the sampled span closest to n T;
      // it never starts before the descent's first row, since n T ≤ span).
      const double t0 = t_end - n * T;
      std::size_t from = h.size() - 1;
      while (from > 0 && h[from - 1].t >= t0 - 1e-12) --from;
      if (from > 0 && t0 - h[from - 1].t < h[from].t - t0) --from;
      terminal_means(from);
    }
  }
  return s;
}

/// The read-out behind a summary row as text, two lines each starting with `prefix`: the
/// raw and filtered peak force (filter cut-off `force_cutoff` Hz), the overshoot, the
/// largest diameter and the terminal window; the numbers of the descent mode.
inline std::string summary_report(const drop_summary& m, double force_cutoff, const std::string& prefix = "") {
  const auto& d = m.descent;
  char a[512], b[640];
  std::snprintf(a, sizeof a,
                "F_p %.4g N at %.4g s (filtered at %g Hz; raw maximum %.4g N at %.4g s); t_mo %.4g s (D %.4g m; "
                "largest D %.4g m at %.4g s); v_T %.4g m/s, C_D %.4g over the last %.4g s\n",
                m.F_p, m.t_p, force_cutoff, m.F_p_raw, m.t_p_raw, m.t_mo, m.overshoot_diameter, m.max_diameter,
                m.t_max_diameter, m.v_terminal, m.cd_terminal, m.terminal_window);
  std::snprintf(b, sizeof b,
                "descent %s over [%.4g, %.4g] s: peak tilt %.3g deg, swing amplitude %.3g deg, period %.4g s (%.3g "
                "periods, %ld centre crossings; a mode needs 2 periods and 4 crossings), swept turns %.3g, "
                "minor/major variance %.3g, drift %.3g of mean |v_h| %.3g m/s\n",
                d.mode.c_str(), d.t_start, d.t_start + d.duration, d.peak_tilt, d.swing_amplitude, d.swing_period,
                d.periods, d.centre_crossings, d.swept_turns, d.principal_ratio,
                d.horizontal_speed > 0 ? d.drift_speed / d.horizontal_speed : 0.0, d.horizontal_speed);
  return prefix + a + prefix + b;
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
