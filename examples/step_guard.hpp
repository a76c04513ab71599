/// \file step_guard.hpp
/// The guard of every example loop that advances time: each stable step must be finite,
/// positive and at least `min_fraction` of the run length, and the run may take at most
/// `max_steps` steps; otherwise parafsi::numerical_failure names the program, the cause,
/// the step and the time, instead of a run that never ends (a viscous step of 1e-300 s)
/// or reports a result it never computed.
///
///   examples::step_guard guard("bluff_body_drag", t_end);
///   while (s.time() < t_end) s.step(std::min(guard(s.stable_dt(cfl), s.time()), t_end - s.time()));
#pragma once
#include <cmath>
#include <string>
#include <utility>

#include <parafsi/core/error.hpp>

namespace examples {

class step_guard {
 public:
  explicit step_guard(std::string program, double t_end, long max_steps = 100'000'000, double min_fraction = 1e-12)
      : program_(std::move(program)), t_end_(t_end), max_steps_(max_steps), min_dt_(min_fraction * t_end) {}

  /// The stable step `dt` at time `t`, checked; counts a step.
  double operator()(double dt, double t) {
    if (!(std::isfinite(dt) && dt > 0 && dt >= min_dt_))
      throw parafsi::numerical_failure(parafsi::detail::concat(program_, ": the stable step collapsed to ", dt,
                                                               " s at t = ", t, " s (run length ", t_end_,
                                                               " s); stopping"),
                                       -1, t);
    if (++steps_ > max_steps_)
      throw parafsi::numerical_failure(parafsi::detail::concat(program_, ": more than ", max_steps_,
                                                               " steps before t_end = ", t_end_, " s (t = ", t,
                                                               " s, stable step ", dt, " s); stopping"),
                                       -1, t);
    return dt;
  }
  long steps() const noexcept { return steps_; }

 private:
  std::string program_;
  double t_end_;
  long max_steps_;
  double min_dt_;
  long steps_ = 0;
};

}  // namespace examples
