/// \file exact_riemann.hpp
/// Exact solution of the 1-D Riemann problem of the Euler equations for an ideal
/// gas (Toro 2009, ch. 4): Newton iteration for the star pressure with the
/// two-rarefaction initial guess, then sampling of the self-similar solution at
/// ξ = (x − x0)/t. Used for verification (shock tubes) and as a reference.
/// Reference: Toro E.F. (2009) Riemann Solvers and Numerical Methods for Fluid
///   Dynamics, 3rd ed., Springer, §4.2–4.5.
#pragma once
#include <algorithm>
#include <cmath>

#include "../core/error.hpp"

namespace parafsi::fluid {

struct riemann_state {
  double rho, u, p;
};

class exact_riemann {
 public:
  exact_riemann(riemann_state L, riemann_state R, double gamma = 1.4) : L_(L), R_(R), g_(gamma) {
    require(L.rho > 0 && R.rho > 0 && L.p > 0 && R.p > 0, "exact_riemann: states must have rho, p > 0");
    cL_ = std::sqrt(g_ * L.p / L.rho);
    cR_ = std::sqrt(g_ * R.p / R.rho);
    require(2.0 / (g_ - 1.0) * (cL_ + cR_) > R.u - L.u,
            "exact_riemann: the initial data generate vacuum (pressure positivity condition fails)");
    solve_star();
  }
  double p_star() const noexcept { return ps_; }
  double u_star() const noexcept { return us_; }

  /// Solution at similarity coordinate s = (x − x0)/t.
  riemann_state sample(double s) const noexcept {
    const double g = g_;
    if (s <= us_) {      // left of the contact
      if (ps_ > L_.p) {  // left shock
        const double SL = L_.u - cL_ * std::sqrt((g + 1) / (2 * g) * ps_ / L_.p + (g - 1) / (2 * g));
        if (s <= SL) return L_;
        const double r = L_.rho * ((ps_ / L_.p + (g - 1) / (g + 1)) / ((g - 1) / (g + 1) * ps_ / L_.p + 1));
        return {r, us_, ps_};
      }
      const double SHL = L_.u - cL_;
      if (s <= SHL) return L_;
      const double csL = cL_ * std::pow(ps_ / L_.p, (g - 1) / (2 * g));
      const double STL = us_ - csL;
      if (s > STL) return {L_.rho * std::pow(ps_ / L_.p, 1 / g), us_, ps_};
      const double f = 2 / (g + 1) + (g - 1) / ((g + 1) * cL_) * (L_.u - s);
      return {L_.rho * std::pow(f, 2 / (g - 1)), 2 / (g + 1) * (cL_ + (g - 1) / 2 * L_.u + s),
              L_.p * std::pow(f, 2 * g / (g - 1))};
    }
    if (ps_ > R_.p) {  // right shock
      const double SR = R_.u + cR_ * std::sqrt((g + 1) / (2 * g) * ps_ / R_.p + (g - 1) / (2 * g));
      if (s >= SR) return R_;
      const double r = R_.rho * ((ps_ / R_.p + (g - 1) / (g + 1)) / ((g - 1) / (g + 1) * ps_ / R_.p + 1));
      return {r, us_, ps_};
    }
    const double SHR = R_.u + cR_;
    if (s >= SHR) return R_;
    const double csR = cR_ * std::pow(ps_ / R_.p, (g - 1) / (2 * g));
    const double STR = us_ + csR;
    if (s < STR) return {R_.rho * std::pow(ps_ / R_.p, 1 / g), us_, ps_};
    const double f = 2 / (g + 1) - (g - 1) / ((g + 1) * cR_) * (R_.u - s);
    return {R_.rho * std::pow(f, 2 / (g - 1)), 2 / (g + 1) * (-cR_ + (g - 1) / 2 * R_.u + s),
            R_.p * std::pow(f, 2 * g / (g - 1))};
  }

 private:
  // Pressure function f_K and its derivative (Toro eq. 4.6–4.7, 4.37).
  void fK(double p, const riemann_state& K, double c, double& f, double& df) const {
    const double g = g_;
    if (p > K.p) {
      const double A = 2 / ((g + 1) * K.rho), B = (g - 1) / (g + 1) * K.p;
      const double q = std::sqrt(A / (p + B));
      f = (p - K.p) * q;
      df = q * (1 - (p - K.p) / (2 * (B + p)));
    } else {
      const double r = p / K.p;
      f = 2 * c / (g - 1) * (std::pow(r, (g - 1) / (2 * g)) - 1);
      df = 1 / (K.rho * c) * std::pow(r, -(g + 1) / (2 * g));
    }
  }
  void solve_star() {
    const double g = g_, du = R_.u - L_.u;
    const double z = (g - 1) / (2 * g);
    // Two-rarefaction guess.
    double p = std::pow((cL_ + cR_ - 0.5 * (g - 1) * du) / (cL_ / std::pow(L_.p, z) + cR_ / std::pow(R_.p, z)), 1 / z);
    p = std::max(p, 1e-12);
    for (int it = 0; it < 100; ++it) {
      double fl, dfl, fr, dfr;
      fK(p, L_, cL_, fl, dfl);
      fK(p, R_, cR_, fr, dfr);
      double pn = p - (fl + fr + du) / (dfl + dfr);
      if (pn < 1e-14) pn = 1e-14;
      const double change = 2 * std::fabs(pn - p) / (pn + p);
      p = pn;
      if (change < 1e-14) break;
    }
    double fl, dfl, fr, dfr;
    fK(p, L_, cL_, fl, dfl);
    fK(p, R_, cR_, fr, dfr);
    ps_ = p;
    us_ = 0.5 * (L_.u + R_.u) + 0.5 * (fr - fl);
  }

  riemann_state L_, R_;
  double g_, cL_, cR_, ps_ = 0, us_ = 0;
};

}  // namespace parafsi::fluid
