/// \file relax.hpp
/// Bring a damped structure to rest (static equilibrium by explicit dynamics, "dynamic
/// relaxation"): step at the stable step until the kinetic energy has fallen below
/// `tolerance` × its peak (amplitude ratio √tolerance) or `t_max` is reached.
/// The damping itself is the user's choice (central_difference::mass_damping α ≈ 2ω₁
/// for the slowest mode of interest, or stiffness-proportional element damping).
/// An optional observer `progress(t, kinetic, peak)` is called every `report_every` steps.
/// Guards (numerical_failure naming the cause, never a silent hang): a stable step that
/// is not finite and positive, or that collapses below 1e-6 of the first one; more than
/// `max_steps` steps, refused before the first step when t_max / stable step already
/// exceeds it (a stiffness or mass out of range, e.g. EA = 1e300).
///
/// References: Underwood P. (1983) Dynamic relaxation, in Belytschko & Hughes (eds.)
///   Computational Methods for Transient Analysis, North-Holland, pp. 245–265.
#pragma once
#include <algorithm>
#include <cmath>

#include "../core/error.hpp"

namespace parafsi::structure {

struct relax_options {
  double tolerance = 1e-12;        ///< stop when K < tolerance · K_peak
  double t_min = 0.0;              ///< never stop before this time (s)
  double t_max = 1e30;             ///< give up after this time (s)
  double dt_fraction = 1.0;        ///< step = dt_fraction · stable_dt()
  long report_every = 1000;        ///< observer period in steps
  long max_steps = 1'000'000'000;  ///< step limit (numerical_failure beyond it)
};

struct relax_result {
  bool converged = false;
  double time = 0;
  long steps = 0;
  double kinetic = 0, peak = 0;
};

struct no_progress {
  void operator()(double, double, double) const noexcept {}
};

template <class Assembly, class Progress = no_progress>
relax_result relax(Assembly& a, const relax_options& o = {}, Progress&& progress = {}) {
  require(o.tolerance > 0 && o.tolerance < 1, "structure::relax: tolerance must be in (0, 1), got ", o.tolerance);
  require(o.dt_fraction > 0 && o.dt_fraction <= 1, "structure::relax: dt_fraction must be in (0, 1], got ",
          o.dt_fraction);
  require(o.max_steps > 0, "structure::relax: max_steps must be > 0, got ", o.max_steps);
  require(std::isfinite(o.t_min) && o.t_min >= 0 && std::isfinite(o.t_max) && o.t_max >= o.t_min,
          "structure::relax: need finite 0 <= t_min <= t_max, got t_min ", o.t_min, " s and t_max ", o.t_max, " s");
  relax_result r;
  const double t0 = a.time();
  double dt = o.dt_fraction * a.stable_dt();
  const double dt0 = dt;
  auto collapsed = [&](double h) { return !(std::isfinite(h) && h > 0 && h >= 1e-6 * dt0); };
  if (collapsed(dt))
    throw numerical_failure(detail::concat("structure::relax: the stable step is ", dt, " s at the start"), -1, t0);
  if (o.t_max < 1e30 && o.t_max / dt > double(o.max_steps))
    throw numerical_failure(detail::concat("structure::relax: reaching t_max = ", o.t_max, " s at the stable step ", dt,
                                           " s takes ", o.t_max / dt, " steps, more than max_steps = ", o.max_steps,
                                           " (a stiffness too high or a mass too small?)"),
                            -1, t0);
  for (;;) {
    if (r.steps % 100 == 0) {
      dt = o.dt_fraction * a.stable_dt();  // current geometry
      if (collapsed(dt))
        throw numerical_failure(detail::concat("structure::relax: the stable step collapsed from ", dt0, " s to ", dt,
                                               " s at t = ", a.time() - t0, " s after ", r.steps, " steps"),
                                -1, a.time());
    }
    if (r.steps >= o.max_steps)
      throw numerical_failure(detail::concat("structure::relax: not at rest after max_steps = ", o.max_steps,
                                             " steps, t = ", a.time() - t0, " s (stable step ", dt, " s)"),
                              -1, a.time());
    a.step(dt);
    ++r.steps;
    r.kinetic = a.kinetic_energy();
    r.peak = std::max(r.peak, r.kinetic);
    const double t = a.time() - t0;
    if (o.report_every > 0 && r.steps % o.report_every == 0) progress(t, r.kinetic, r.peak);
    if (t >= o.t_min && r.peak > 0 && r.kinetic < o.tolerance * r.peak) {
      r.converged = true;
      break;
    }
    if (t >= o.t_max) break;
  }
  r.time = a.time() - t0;
  return r;
}

}  // namespace parafsi::structure
