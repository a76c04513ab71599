/// \file progress.hpp
/// A progress-line observer for the user's loop (DESIGN §1: called between steps).
///
///   io::progress bar(t_end);                  // to std::cerr, at most every 0.5 s wall
///   for (...) { stepper.step(dt); bar(stepper.time(), stepper.steps(), {{"F", force}}); }
///   bar.finish(stepper.time(), stepper.steps());
///
/// One line per report:
///   `t = 0.1250 s / 6 s (2.1 %)  steps 1200  2.4e+02 steps/s  0.025 sim-s/s  ETA 3m55s  F = 12.5`
/// steps/s and sim-s/s are measured over the interval since the previous report (the
/// first report: since construction); the ETA is (t_end − t) divided by the simulated
/// seconds per wall second over the whole run. Lines end with '\n' by default (logs
/// stay readable); `carriage_return = true` rewrites one terminal line instead.
/// Reports are rate-limited by wall time (`interval`, default 0.5 s): a call inside the
/// interval costs one clock read. The clock is injectable for tests.
/// io/ is never included by physics headers; this one needs the standard library only.
#pragma once
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <initializer_list>
#include <iostream>
#include <ostream>
#include <string>
#include <string_view>
#include <utility>

#include "../core/error.hpp"

namespace parafsi::io {

struct progress_options {
  double interval = 0.5;           ///< minimum wall seconds between two lines
  std::ostream* out = &std::cerr;  ///< where lines go (stderr by default)
  bool carriage_return = false;    ///< '\r' instead of '\n' (one rewritten terminal line)
  std::string prefix;              ///< text before every line, e.g. the run's name
  /// Wall clock in seconds (monotonic); default std::chrono::steady_clock.
  std::function<double()> clock;
};

/// Format a duration in seconds as "12s", "3m05s" or "2h03m" ("?" if not finite).
inline std::string format_duration(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  char buf[32];
  const long n = long(std::llround(s));
  if (n < 60) std::snprintf(buf, sizeof buf, "%lds", n);
  else if (n < 3600) std::snprintf(buf, sizeof buf, "%ldm%02lds", n / 60, n % 60);
  else std::snprintf(buf, sizeof buf, "%ldh%02ldm", n / 3600, (n % 3600) / 60);
  return buf;
}

class progress {
 public:
  using field = std::pair<std::string_view, double>;

  /// t_end: simulated end time (s) for the percentage and the ETA (<= 0: none shown).
  explicit progress(double t_end, progress_options opt = {}) : t_end_(t_end), opt_(std::move(opt)) {
    require(opt_.interval >= 0 && std::isfinite(opt_.interval), "io::progress: interval must be >= 0, got ",
            opt_.interval);
    require(opt_.out != nullptr, "io::progress: output stream is null");
    if (!opt_.clock)
      opt_.clock = [] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
      };
    start_wall_ = last_wall_ = opt_.clock();
  }

  /// Report if at least `interval` wall seconds passed since the last line. Returns
  /// whether a line was written. `extra`: name/value pairs appended to the line.
  bool operator()(double t, long steps, std::initializer_list<field> extra = {}) {
    const double now = opt_.clock();
    if (lines_ > 0 && now - last_wall_ < opt_.interval) return false;
    if (lines_ == 0 && now - start_wall_ < opt_.interval) {
      // First call(s): remember the starting point, report once the interval is up.
      if (!have_start_) {
        have_start_ = true;
        t0_ = t;
        steps0_ = steps;
        last_t_ = t;
        last_steps_ = steps;
      }
      return false;
    }
    write(now, t, steps, extra);
    return true;
  }

  /// Final line, unconditionally (ends with '\n' even in carriage-return mode).
  void finish(double t, long steps, std::initializer_list<field> extra = {}) {
    write(opt_.clock(), t, steps, extra);
    if (opt_.carriage_return) *opt_.out << '\n';
    opt_.out->flush();
  }

  long lines() const noexcept { return lines_; }
  /// The text of the last line written (without the line end).
  const std::string& last_line() const noexcept { return line_; }

 private:
  void write(double now, double t, long steps, std::initializer_list<field> extra) {
    if (!have_start_) {
      have_start_ = true;
      t0_ = last_t_ = t;
      steps0_ = last_steps_ = steps;
    }
    const double dw = now - last_wall_;
    const double rate = dw > 0 ? double(steps - last_steps_) / dw : 0.0;
    const double sim_rate = dw > 0 ? (t - last_t_) / dw : 0.0;
    const double total_wall = now - start_wall_;
    const double mean_sim_rate = total_wall > 0 ? (t - t0_) / total_wall : 0.0;
    char buf[256];
    std::string s = opt_.prefix;
    if (t_end_ > 0) {
      std::snprintf(buf, sizeof buf, "t = %.4f s / %g s (%.1f %%)", t, t_end_, 100.0 * t / t_end_);
    } else {
      std::snprintf(buf, sizeof buf, "t = %.4f s", t);
    }
    s += buf;
    std::snprintf(buf, sizeof buf, "  steps %ld  %.3g steps/s  %.3g sim-s/s", steps, rate, sim_rate);
    s += buf;
    if (t_end_ > 0) {
      const double eta = mean_sim_rate > 0 ? std::max(0.0, t_end_ - t) / mean_sim_rate : INFINITY;
      s += "  ETA " + format_duration(eta);
    }
    for (const auto& [name, value] : extra) {
      std::snprintf(buf, sizeof buf, "  %.*s = %.6g", int(name.size()), name.data(), value);
      s += buf;
    }
    line_ = s;
    *opt_.out << s << (opt_.carriage_return ? '\r' : '\n');
    opt_.out->flush();
    last_wall_ = now;
    last_t_ = t;
    last_steps_ = steps;
    ++lines_;
  }

  double t_end_;
  progress_options opt_;
  double start_wall_ = 0, last_wall_ = 0;
  bool have_start_ = false;
  double t0_ = 0, last_t_ = 0;
  long steps0_ = 0, last_steps_ = 0;
  long lines_ = 0;
  std::string line_;
};

}  // namespace parafsi::io
