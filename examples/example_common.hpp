/// \file example_common.hpp
/// Shared pieces of the example programs: command-line options (CLI11), the
/// one-time dispatch from run-time flux/limiter names to template arguments,
/// a time loop with progress on stderr, and CSV output.
#pragma once
#include <CLI/CLI.hpp>

#include <parafsi/io/checked_file.hpp>
#include <parafsi/parafsi.hpp>

#include "cli_checks.hpp"
#include "step_guard.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace examples {

namespace pf = parafsi;

// ---------------------------------------------------------------- names
inline const std::vector<std::string> flux_names{"hllc_lm", "hllc", "rusanov", "ausm_plus_up"};
inline const std::vector<std::string> limiter_names{"van_leer", "minmod", "mc", "none"};

/// Call f(Flux{}) for the flux named `name` (checked by the option parser already).
template <class F>
decltype(auto) with_flux(const std::string& name, F&& f) {
  if (name == "hllc_lm") return f(pf::flux::hllc_lm{});
  if (name == "hllc") return f(pf::flux::hllc{});
  if (name == "rusanov") return f(pf::flux::rusanov{});
  if (name == "ausm_plus_up") return f(pf::flux::ausm_plus_up{});
  throw std::invalid_argument("unknown flux '" + name + "'");
}

/// Call f(Recon{}) for the limiter named `name` ("none" = first order).
template <class F>
decltype(auto) with_limiter(const std::string& name, F&& f) {
  if (name == "van_leer") return f(pf::recon::muscl<pf::limiter::van_leer>{});
  if (name == "minmod") return f(pf::recon::muscl<pf::limiter::minmod>{});
  if (name == "mc") return f(pf::recon::muscl<pf::limiter::mc>{});
  if (name == "none") return f(pf::recon::first_order{});
  throw std::invalid_argument("unknown limiter '" + name + "'");
}

/// Resolve both names once: f(Flux{}, Recon{}); everything below is compile-time.
template <class F>
decltype(auto) dispatch(const std::string& flux, const std::string& limiter, F&& f) {
  return with_flux(flux, [&](auto fl) { return with_limiter(limiter, [&](auto rc) { return f(fl, rc); }); });
}

// ---------------------------------------------------------------- options
/// Options every example shares.
struct common_options {
  std::string flux = "hllc_lm";
  std::string limiter = "van_leer";
  double cfl = 0.5;
  int threads = 1;  // 0: OpenMP default (OMP_NUM_THREADS)
  bool quiet = false;
};

inline void add_flux_option(CLI::App& app, common_options& o) {
  app.add_option("--flux", o.flux, "Riemann flux")->check(CLI::IsMember(flux_names))->capture_default_str();
}
inline void add_limiter_option(CLI::App& app, common_options& o) {
  app.add_option("--limiter", o.limiter, "MUSCL limiter (none = first order)")
      ->check(CLI::IsMember(limiter_names))
      ->capture_default_str();
}
inline void add_run_options(CLI::App& app, common_options& o) {
  app.add_option("--cfl", o.cfl, "CFL number of the stable step, in (0, 1]")
      ->check(finite)
      ->check(CLI::Range(1e-6, 1.0))
      ->capture_default_str();
  app.add_option("--threads", o.threads,
                 "OpenMP threads; the example grids are small, so 1 by default (0: OMP_NUM_THREADS)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  app.add_flag("--quiet", o.quiet, "no progress messages on stderr");
}
inline CLI::Option* add_cells_option(CLI::App& app, int& cells, const char* what, int min_cells = 1) {
  return app.add_option("--cells", cells, what)->check(CLI::Range(min_cells, 1 << 16))->capture_default_str();
}
inline CLI::Option* add_out_option(CLI::App& app, std::string& out) {
  return app.add_option("--out", out, "CSV output file")->required()->check([](const std::string& s) {
    return s.empty() ? std::string("output file name is empty") : std::string();
  });
}

inline void apply_threads(const common_options& o) {
  if (o.threads > 0) pf::parallel::set_threads(o.threads);
}

// ---------------------------------------------------------------- timing
inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Progress on stderr for runs longer than a second: simulated time, steps/s, ETA.
class progress {
 public:
  progress(std::string label, double t_end, bool quiet)
      : label_(std::move(label)), t_end_(t_end), quiet_(quiet), t0_(std::chrono::steady_clock::now()) {}
  void operator()(double t, long steps) {
    if (quiet_) return;
    const double el = seconds_since(t0_);
    if (el < next_) return;
    next_ = el + 2.0;
    if (el < 1.0) return;
    const double rate = double(steps) / el;
    const double frac = t_end_ > 0 ? t / t_end_ : 0.0;
    const double eta = frac > 0 ? el * (1.0 - frac) / frac : 0.0;
    std::fprintf(stderr, "%s: t = %.6g / %.6g, %ld steps, %.1f steps/s, ETA %.1f s\n", label_.c_str(), t, t_end_, steps,
                 rate, eta);
    printed_ = true;
  }
  void finish(double t, long steps) {
    if (quiet_ || !printed_) return;
    const double el = seconds_since(t0_);
    std::fprintf(stderr, "%s: done, t = %.6g, %ld steps in %.2f s\n", label_.c_str(), t, steps, el);
  }
  double elapsed() const { return seconds_since(t0_); }

 private:
  std::string label_;
  double t_end_;
  bool quiet_;
  std::chrono::steady_clock::time_point t0_;
  double next_ = 1.0;
  bool printed_ = false;
};

/// Advance `s` to t_end with the stable step at `cfl` (the last step lands on t_end),
/// guarded (step_guard: a collapsed step or too many steps stop the run with a message).
template <class Solver>
void run_to(Solver& s, double t_end, double cfl, progress& prog) {
  step_guard guard("run_to", t_end);
  while (s.time() < t_end) {
    double dt = guard(s.stable_dt(cfl), s.time());
    const double left = t_end - s.time();
    if (dt >= left * (1.0 - 1e-12)) dt = left;
    else if (dt > 0.5 * left) dt = 0.5 * left;  // avoid a tiny last step
    s.step(dt);
    prog(s.time(), s.steps());
  }
  prog.finish(s.time(), s.steps());
}

// ---------------------------------------------------------------- CSV
/// Minimal CSV writer: header, then rows of numbers at full precision, through
/// io::checked_file (a failed open, write, flush or close throws io::write_error naming
/// the file and the system's reason; `close()` must be called).
class csv_writer {
 public:
  csv_writer(const std::string& path, const std::string& header) : f_(path) { f_.write(header + '\n'); }
  void row(std::initializer_list<double> values) {
    line_.clear();
    char buf[32];
    bool first = true;
    for (double v : values) {
      if (!first) line_ += ',';
      std::snprintf(buf, sizeof buf, "%.15g", v);
      line_ += buf;
      first = false;
    }
    line_ += '\n';
    f_.write(line_);
  }
  void close() { f_.close(); }

 private:
  pf::io::checked_file f_;
  std::string line_;
};

/// Run `body`, turning exceptions into a message and exit code 1.
template <class F>
int guarded(const char* program, F&& body) {
  try {
    return body();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", program, e.what());
    return 1;
  }
}

}  // namespace examples
