/// \file hencky.hpp
/// Closed-form reference for a clamped circular membrane (radius a, thickness h,
/// Young's modulus E, Poisson ratio ν) under uniform lateral pressure q: the
/// Föppl–Hencky problem. Eliminating the in-plane displacement gives, for the radial
/// stress S(r) (σ_t = (rS)', h S w' = −q r/2):
///   S'' + 3 S'/r = −E q² / (8 h² S²),   S'(0) = 0,   (1 − ν) S(a) + a S'(a) = 0 (u(a) = 0).
/// With S = σ* s(x), x = r/a, σ*³ = E q² a²/(8 h²):
///   s'' + 3 s'/x = −1/s²,   w(r)/a = (q a/(E h))^{1/3} ∫_{r/a}^1 x/s dx,
/// so the centre deflection is w0 = f(ν) a (q a/(E h))^{1/3}, f(ν) = ∫₀¹ x/s dx.
/// s(0) is found by shooting (bisection on the rim condition) with RK4; f(0.3) = 0.662…
/// reproduces Hencky's series value as corrected by Chien (1948)
/// (Timoshenko & Woinowsky-Krieger, Theory of Plates and Shells, §96: w0 = 0.662 a (qa/Eh)^{1/3}).
///
/// References: Hencky H. (1915) Z. Math. Phys. 63:311; Chien W.Z. (1948) Sci. Rep. Tsinghua
///   Univ. 5:71; Fichter W.B. (1997) NASA TP-3658; Timoshenko S., Woinowsky-Krieger S.
///   (1959) Theory of Plates and Shells, 2nd ed., §96.
#pragma once
#include <cmath>
#include <vector>

#include "../../core/error.hpp"

namespace parafsi::structure::reference {

struct hencky_solution {
  double nu;              ///< Poisson ratio
  double s0;              ///< dimensionless centre stress s(0)
  double coefficient;     ///< f(ν) = w0 / (a (qa/Eh)^{1/3})
  std::vector<double> x;  ///< r/a, uniform on [0, 1]
  std::vector<double> w;  ///< w(r) / (a (qa/Eh)^{1/3})
};

namespace hencky_detail {
/// Integrate s'' = −1/s² − 3s'/x from 0 to 1 (series start); returns s(1), s'(1) and
/// optionally the profile of s.
inline void shoot(double s0, int n, double& s1, double& ds1, std::vector<double>* prof) {
  const double x0 = 1e-4;
  double x = x0, s = s0 - x0 * x0 / (8.0 * s0 * s0), d = -x0 / (4.0 * s0 * s0);
  const double h = (1.0 - x0) / n;
  if (prof) {
    prof->assign(1, s0);
  }
  auto f = [](double xx, double ss, double dd, double& a, double& b) {
    a = dd;
    b = -1.0 / (ss * ss) - 3.0 * dd / xx;
  };
  for (int i = 0; i < n; ++i) {
    double k1a, k1b, k2a, k2b, k3a, k3b, k4a, k4b;
    f(x, s, d, k1a, k1b);
    f(x + 0.5 * h, s + 0.5 * h * k1a, d + 0.5 * h * k1b, k2a, k2b);
    f(x + 0.5 * h, s + 0.5 * h * k2a, d + 0.5 * h * k2b, k3a, k3b);
    f(x + h, s + h * k3a, d + h * k3b, k4a, k4b);
    s += h / 6.0 * (k1a + 2 * k2a + 2 * k3a + k4a);
    d += h / 6.0 * (k1b + 2 * k2b + 2 * k3b + k4b);
    x += h;
    if (prof) prof->push_back(s);
    if (!(s > 0)) {
      s1 = -1;
      ds1 = 0;
      return;
    }
  }
  s1 = s;
  ds1 = d;
}
}  // namespace hencky_detail

/// Solve the Föppl–Hencky problem for Poisson ratio ν (n RK4 steps, profile at n+1 points).
inline hencky_solution hencky(double nu, int n = 20000) {
  require(nu > -1.0 && nu < 0.5 + 1e-12, "reference::hencky: Poisson ratio must be in (-1, 0.5], got ", nu);
  // Rim residual g(s0) = (1 − ν) s(1) + s'(1): negative for small s0 (s collapses), positive for large.
  auto g = [&](double s0) {
    double s1, d1;
    hencky_detail::shoot(s0, n / 10, s1, d1, nullptr);
    if (s1 <= 0) return -1.0;
    return (1.0 - nu) * s1 + d1;
  };
  double lo = 0.05, hi = 5.0;
  require(g(lo) < 0 && g(hi) > 0, "reference::hencky: bracket failed for nu = ", nu);
  for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) < 0 ? lo : hi) = mid;
  }
  hencky_solution out{nu, 0.5 * (lo + hi), 0, {}, {}};
  std::vector<double> prof;
  double s1, d1;
  hencky_detail::shoot(out.s0, n, s1, d1, &prof);
  // w(x) = ∫_x^1 t/s dt by the trapezoid rule on the RK4 grid (x_0 = 0 ≈ series start).
  const std::size_t m = prof.size();
  out.x.resize(m);
  out.w.assign(m, 0.0);
  const double x0 = 1e-4, h = (1.0 - x0) / double(m - 1);
  for (std::size_t i = 0; i < m; ++i) out.x[i] = i == 0 ? 0.0 : x0 + h * double(i);
  for (std::size_t i = m - 1; i-- > 0;)
    out.w[i] = out.w[i + 1] + 0.5 * (out.x[i + 1] - out.x[i]) * (out.x[i] / prof[i] + out.x[i + 1] / prof[i + 1]);
  out.coefficient = out.w[0];
  return out;
}

/// w(r)/(a (qa/Eh)^{1/3}) at x = r/a by linear interpolation of the solution's profile.
inline double hencky_profile(const hencky_solution& s, double x) {
  if (x <= 0) return s.w.front();
  if (x >= 1) return 0.0;
  const double h = s.x[2] - s.x[1];
  const double x0 = s.x[1];
  if (x < x0) return s.w[0] + (s.w[1] - s.w[0]) * x / x0;
  const std::size_t i = std::min(s.x.size() - 2, std::size_t(1 + (x - x0) / h));
  const double t = (x - s.x[i]) / (s.x[i + 1] - s.x[i]);
  return s.w[i] + t * (s.w[i + 1] - s.w[i]);
}

}  // namespace parafsi::structure::reference
