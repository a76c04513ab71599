/// \file spectrum.hpp
/// The dominant frequency of one or more signals x_j(t) sampled at increasing, possibly
/// uneven times t_i (a solver's steps): the peak of their summed Hann-windowed power
/// spectrum,
///
///   P(f) = Σ_j |X_j(f)|²,  X_j(f) = Σ_{n=0}^{N−1} w_n (x_j(τ_n) − x̄_j) e^{−2πi f τ_n},
///   w_n = sin²(π n/(N−1)),  τ_n = t_0 + n T/(N−1),  T = t_last − t_0,
///
/// with x_j(τ_n) linearly interpolated and x̄_j its mean over the τ_n. P is evaluated by a
/// direct DFT on a grid of spacing 1/(`pad` T) in [f_min, f_max] (zero padding, `pad` = 8
/// by default) and the peak refined by the parabola through log P at the best grid point
/// and its two neighbours (Gaussian interpolation; the Hann main lobe is close to a
/// Gaussian, so a pure tone's frequency comes out to a small fraction of 1/T).
///
/// Returned with the peak: the amplitude A = 4|X|/(N−1) of the tone (a pure sine
/// x = A sin(2πft) of whole or fractional period count gives A within the Hann window's
/// scalloping, < 1.5 % once `pad` ≥ 8), the number of periods T·f the record holds (below
/// about 3 the peak is not a measurement) and the fraction of the spectrum's power in the
/// peak's main lobe (|f − f_peak| < 2/T): near 1 for a clean tone, small for broadband
/// noise. Cost: O(N · (f_max − f_min) · pad T) operations, N ≤ `max_samples`.
///
///   std::vector<double> t = ..., cy = ..., cz = ...;
///   auto pk = io::dominant_frequency(t, {cy, cz}, 0.5, 200.0);   // Hz
///   double St = pk.frequency * D / U;
///
/// io/ is never included by physics headers; this one needs the standard library only.
#pragma once
#include "../core/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <initializer_list>
#include <numbers>
#include <span>
#include <vector>

namespace parafsi::io {

struct spectral_peak {
  double frequency = 0.0;       ///< Hz (or 1 / the unit of t)
  double amplitude = 0.0;       ///< of the tone, √(Σ_j A_j²) over the signals
  double periods = 0.0;         ///< T · frequency: periods the record holds
  double power_fraction = 0.0;  ///< share of the spectrum's power in the peak's main lobe
};

struct spectrum_options {
  int pad = 8;                     ///< frequency grid spacing 1/(pad T)
  std::size_t max_samples = 8192;  ///< uniform resampling points N (fewer if the record has fewer)
};

/// Dominant frequency in [f_min, f_max] of the signals `xs` (each as long as `t`); rules above.
inline spectral_peak dominant_frequency(std::span<const double> t, std::initializer_list<std::span<const double>> xs,
                                        double f_min, double f_max, const spectrum_options& o = {}) {
  const std::size_t m = t.size();
  require(m >= 8, "io::dominant_frequency: needs at least 8 samples, got ", m);
  require(f_min >= 0 && f_max > f_min && std::isfinite(f_max), "io::dominant_frequency: bad band [", f_min, ", ", f_max,
          "]");
  require(o.pad >= 1 && o.max_samples >= 8, "io::dominant_frequency: pad >= 1 and max_samples >= 8");
  for (std::size_t i = 1; i < m; ++i)
    require(t[i] > t[i - 1], "io::dominant_frequency: times must increase (sample ", i, ")");
  for (const auto& x : xs) require(x.size() == m, "io::dominant_frequency: a signal has ", x.size(), " samples, t ", m);
  const double t0 = t.front(), T = t.back() - t0;
  const std::size_t N = std::min(m, o.max_samples);
  // Resample each signal to N uniform points, remove the mean, window.
  std::vector<double> w(N);
  for (std::size_t n = 0; n < N; ++n) {
    const double s = std::sin(std::numbers::pi * double(n) / double(N - 1));
    w[n] = s * s;
  }
  std::vector<std::vector<double>> ys;
  for (const auto& x : xs) {
    std::vector<double> y(N);
    std::size_t k = 0;
    for (std::size_t n = 0; n < N; ++n) {
      const double tau = n + 1 == N ? t.back() : t0 + T * double(n) / double(N - 1);
      while (k + 2 < m && t[k + 1] < tau) ++k;
      const double a = std::clamp((tau - t[k]) / (t[k + 1] - t[k]), 0.0, 1.0);
      y[n] = x[k] + a * (x[k + 1] - x[k]);
    }
    double mean = 0;
    for (double v : y) mean += v;
    mean /= double(N);
    for (std::size_t n = 0; n < N; ++n) y[n] = (y[n] - mean) * w[n];
    ys.push_back(std::move(y));
  }
  // Power on the frequency grid.
  const double df = 1.0 / (o.pad * T);
  const auto nf = std::size_t(std::floor((f_max - f_min) / df)) + 1;
  require(nf >= 3, "io::dominant_frequency: the band [", f_min, ", ", f_max, "] is narrower than 2/(pad T)");
  std::vector<double> P(nf, 0.0);
  const double dtau = T / double(N - 1);
  for (std::size_t k = 0; k < nf; ++k) {
    const double f = f_min + df * double(k);
    // Rotating phasor e^{−iωτ_n} by recurrence, re-anchored every 64 samples.
    const double th = -2.0 * std::numbers::pi * f * dtau;
    const double cr = std::cos(th), ci = std::sin(th);
    for (const auto& y : ys) {
      double re = 0, im = 0, pr = 1, pi = 0;
      for (std::size_t n = 0; n < N; ++n) {
        if (n % 64 == 0) {
          pr = std::cos(th * double(n));
          pi = std::sin(th * double(n));
        }
        re += y[n] * pr;
        im += y[n] * pi;
        const double npr = pr * cr - pi * ci;
        pi = pr * ci + pi * cr;
        pr = npr;
      }
      P[k] += re * re + im * im;
    }
  }
  const auto kb = std::size_t(std::max_element(P.begin(), P.end()) - P.begin());
  spectral_peak r;
  double f_peak = f_min + df * double(kb), P_peak = P[kb];
  if (kb > 0 && kb + 1 < nf && P[kb - 1] > 0 && P[kb + 1] > 0 && P[kb] > 0) {
    const double a = std::log(P[kb - 1]), b = std::log(P[kb]), c = std::log(P[kb + 1]);
    const double den = a - 2 * b + c;
    if (den < 0) {
      const double d = 0.5 * (a - c) / den;  // in (−½, ½) grid steps
      f_peak += d * df;
      P_peak = std::exp(b - 0.25 * (a - c) * d);
    }
  }
  r.frequency = f_peak;
  // Σ w_n = (N−1)/2: a tone of amplitude A gives |X| = A (N−1)/4 at its frequency.
  r.amplitude = 4.0 * std::sqrt(P_peak) / double(N - 1);
  r.periods = T * f_peak;
  double total = 0, lobe = 0;
  for (std::size_t k = 0; k < nf; ++k) {
    total += P[k];
    if (std::abs(f_min + df * double(k) - f_peak) < 2.0 / T) lobe += P[k];
  }
  r.power_fraction = total > 0 ? lobe / total : 0.0;
  return r;
}

}  // namespace parafsi::io
