/// \file gaussian_filter.hpp
/// Zero-phase low-pass filter of a uniformly sampled signal x_i (sample interval Δt): the
/// symmetric Gaussian FIR
///
///   y_i = Σ_{k=−H}^{H} w_k x_{i+k} / Σ_k w_k,   w_k = exp(−(kΔt)² / (2σ²)),
///   σ = √(ln 2) / (2π f_c),   H = ⌈4σ/Δt⌉ samples (the half-window),
///
/// whose frequency response (of the continuous kernel) G(f) = exp(−2π²σ²f²) is real and
/// positive: no phase shift (a peak stays where it is), no overshoot or ringing of its own
/// (the weights are positive, so y never exceeds the samples it averages). G is 1/√2
/// (−3 dB) at the cut-off f_c, 1/2 at √2 f_c, 0.1 at 2.58 f_c and 0.01 at 3.65 f_c. A
/// Gaussian pulse of standard deviation s keeps its area and its time of peak, its peak
/// lowered by the factor s / √(s² + σ²). Truncating at 4σ drops weights below e⁻⁸ = 3.4e−4;
/// the sampled kernel's aliases G(f − m/Δt) add at most exp(−π²σ²/(2Δt²)) up to the Nyquist
/// frequency (9e−16 at 10 Hz and 5 ms, σ = 2.65 Δt); measured, the truncated sampled filter
/// has the response G to 2e−5 (tests/test_drop_summary.cpp).
///
/// Edges (the first and last H samples, where the window is cut by the ends of the
/// series): the weighted least-squares straight line a + b k through the available samples
/// k ∈ [kl, kr] with the same weights gives y_i = a,
///
///   a = (S2 T0 − S1 T1) / (S0 S2 − S1²),  S_j = Σ w_k k^j,  T_j = Σ w_k k^j x_{i+k},
///
/// (the local-linear kernel estimate): it equals the Gaussian average when the window is
/// whole (S1 = 0), and passes a constant and a straight line unchanged at the edges too,
/// where the plain renormalised average Σ w x / Σ w would bend a slope. A series of one
/// sample is returned as it is. `at(x, i)` sums over k from kl to kr in increasing order,
/// so the value of sample i depends only on the samples in its window: a series filtered
/// piecewise, as it grows (a window complete once H later samples exist), gives the same
/// bits as the whole series filtered at once. Every product-and-sum is an explicit
/// std::fma, so the bits do not depend on where the compiler inlines `at` either: with
/// FMA instructions (-march=native, -ffp-contract=fast, GCC's default) an `a * b + c` may
/// be fused in one inlined copy and not in another, and a history column filled row by
/// row then differed from the whole series in the last bit.
///
///   io::gaussian_lowpass f(10.0, 0.005);   // f_c = 10 Hz, Δt = 5 ms: σ = 13.25 ms, H = 11
///   std::vector<double> y = f.apply(x);
///   double y7 = f.at(x, 7);                // one sample
///
/// io/ is never included by physics headers; this one needs the standard library only.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <span>
#include <vector>

#include "../core/error.hpp"

namespace parafsi::io {

class gaussian_lowpass {
 public:
  /// The filter of cut-off `cutoff` (Hz, the −3 dB frequency) for samples `dt` (s) apart.
  gaussian_lowpass(double cutoff, double dt) : cutoff_(cutoff), dt_(dt) {
    require(std::isfinite(cutoff) && cutoff > 0,
            "io::gaussian_lowpass: the cut-off must be a finite frequency > 0 Hz, got ", cutoff);
    require(std::isfinite(dt) && dt > 0, "io::gaussian_lowpass: the sample interval must be finite and > 0 s, got ",
            dt);
    sigma_ = std::sqrt(std::numbers::ln2) / (2.0 * std::numbers::pi * cutoff);
    const double h = std::ceil(4.0 * sigma_ / dt);
    require(h <= 1e6, "io::gaussian_lowpass: cut-off ", cutoff, " Hz at samples ", dt,
            " s apart needs a half-window of ", h, " samples, more than 1e6");
    half_ = std::size_t(h);
    w_.resize(2 * half_ + 1);
    for (std::size_t j = 0; j < w_.size(); ++j) {
      const double tk = (double(j) - double(half_)) * dt;
      w_[j] = std::exp(-tk * tk / (2.0 * sigma_ * sigma_));
    }
    double s0 = 0;
    for (double w : w_) s0 += w;
    wn_.resize(w_.size());
    for (std::size_t j = 0; j < w_.size(); ++j) wn_[j] = w_[j] / s0;
  }

  double cutoff() const noexcept { return cutoff_; }
  double sample_interval() const noexcept { return dt_; }
  double sigma() const noexcept { return sigma_; }            ///< the kernel's standard deviation (s)
  std::size_t half_window() const noexcept { return half_; }  ///< H: samples after i that y_i needs
  /// G(f), the response of the continuous kernel at frequency f (Hz).
  double response(double f) const noexcept {
    return std::exp(-2.0 * std::numbers::pi * std::numbers::pi * sigma_ * sigma_ * f * f);
  }

  /// y_i of the samples x(0), …, x(n − 1) (a callable j → x_j; rules in the file comment).
  template <class X>
  double at(std::size_t n, std::size_t i, X&& x) const {
    const std::ptrdiff_t H = std::ptrdiff_t(half_), ii = std::ptrdiff_t(i);
    const std::ptrdiff_t kl = -std::min(H, ii), kr = std::min(H, std::ptrdiff_t(n) - 1 - ii);
    if (kl == -H && kr == H) {
      double y = 0;
      for (std::ptrdiff_t k = -H; k <= H; ++k) y = std::fma(wn_[std::size_t(k + H)], x(std::size_t(ii + k)), y);
      return y;
    }
    double S0 = 0, S1 = 0, S2 = 0, T0 = 0, T1 = 0;
    for (std::ptrdiff_t k = kl; k <= kr; ++k) {
      const double w = w_[std::size_t(k + H)], dk = double(k), xk = x(std::size_t(ii + k)), wk = w * dk;
      S0 += w;
      S1 += wk;
      S2 = std::fma(wk, dk, S2);
      T0 = std::fma(w, xk, T0);
      T1 = std::fma(wk, xk, T1);
    }
    const double det = std::fma(S0, S2, -(S1 * S1));
    return det > 0 ? std::fma(S2, T0, -(S1 * T1)) / det : x(i);
  }
  double at(std::span<const double> x, std::size_t i) const {
    return at(x.size(), i, [&](std::size_t j) { return x[j]; });
  }

  /// The whole series filtered.
  std::vector<double> apply(std::span<const double> x) const {
    std::vector<double> y(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) y[i] = at(x, i);
    return y;
  }

 private:
  double cutoff_, dt_, sigma_ = 0;
  std::size_t half_ = 0;
  std::vector<double> w_, wn_;  ///< weights w_k and w_k / Σ w, k = −H … H
};

}  // namespace parafsi::io
