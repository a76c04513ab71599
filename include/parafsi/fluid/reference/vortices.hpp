/// \file vortices.hpp
/// Closed-form vortex flows used for verification (tests, examples, benchmarks):
/// - Shu/Yee isentropic vortex: free stream (u∞, v∞), ρ∞, p∞, strength ε:
///     δu = −ε/(2π) e^{(1−r²)/2} Δy,  δv = ε/(2π) e^{(1−r²)/2} Δx,
///     T = T∞ − (γ−1) ε² /(8γπ²) e^{1−r²},  ρ = ρ∞ (T/T∞)^{1/(γ−1)},  p = p∞ (T/T∞)^{γ/(γ−1)};
///   an exact steady solution advected with the free stream.
/// - Gresho vortex on [0,1]² (peak azimuthal speed 1 at r = 0.2, ρ = 1,
///   p₀ = 1/(γ M²) so that M is the peak Mach number):
///     u_φ = 5r, p = p₀ + 12.5 r²                                  (r < 0.2)
///     u_φ = 2 − 5r, p = p₀ + 12.5 r² + 4 − 20 r + 4 ln(5r)         (0.2 ≤ r < 0.4)
///     u_φ = 0, p = p₀ − 2 + 4 ln 2                                 (r ≥ 0.4).
/// - 2-D Taylor–Green vortex: u = U sin x cos y, v = −U cos x sin y,
///   p = p₀ + ρU²/4 (cos 2x + cos 2y); viscous kinetic energy decays as e^{−4νt}.
/// References: Yee H.C., Sandham N.D., Djomehri M.J. (1999) J. Comput. Phys. 150:199;
///   Gresho P.M., Chan S.T. (1990) Int. J. Numer. Methods Fluids 11:621;
///   Miczek F., Röpke F.K., Edelmann P.V.F. (2015) A&A 576:A50 (low-Mach Gresho);
///   Taylor G.I., Green A.E. (1937) Proc. R. Soc. A 158:499.
#pragma once
#include <cmath>
#include <numbers>

#include "../state.hpp"

namespace parafsi::fluid::reference {

struct isentropic_vortex {
  double eps = 5.0, rho_inf = 1.0, p_inf = 1.0, u_inf = 1.0, v_inf = 1.0;
  double cx = 0.0, cy = 0.0;
  double gamma = 1.4;
  double period = 0.0;  ///< periodic box length (0: no wrapping); nearest image used

  prim<double> operator()(double x, double y) const {
    double dx = x - cx, dy = y - cy;
    if (period > 0.0) {
      dx -= period * std::floor(dx / period + 0.5);
      dy -= period * std::floor(dy / period + 0.5);
    }
    const double r2 = dx * dx + dy * dy, pi = std::numbers::pi;
    const double a = eps / (2.0 * pi) * std::exp(0.5 * (1.0 - r2));
    const double T_inf = p_inf / rho_inf;
    const double T = T_inf - (gamma - 1.0) * eps * eps / (8.0 * gamma * pi * pi) * std::exp(1.0 - r2);
    const double ratio = T / T_inf;
    return {rho_inf * std::pow(ratio, 1.0 / (gamma - 1.0)),
            {u_inf - a * dy, v_inf + a * dx, 0.0},
            p_inf * std::pow(ratio, gamma / (gamma - 1.0))};
  }
};

struct gresho_vortex {
  double mach = 0.1, gamma = 1.4;
  double cx = 0.5, cy = 0.5;

  prim<double> operator()(double x, double y) const {
    const double dx = x - cx, dy = y - cy, r = std::hypot(dx, dy);
    const double p0 = 1.0 / (gamma * mach * mach);
    double uphi, p;
    if (r < 0.2) {
      uphi = 5.0 * r;
      p = p0 + 12.5 * r * r;
    } else if (r < 0.4) {
      uphi = 2.0 - 5.0 * r;
      p = p0 + 12.5 * r * r + 4.0 - 20.0 * r + 4.0 * std::log(5.0 * r);
    } else {
      uphi = 0.0;
      p = p0 - 2.0 + 4.0 * std::log(2.0);
    }
    const double s = r > 0.0 ? uphi / r : 0.0;
    return {1.0, {-s * dy, s * dx, 0.0}, p};
  }
};

struct taylor_green_2d {
  double U = 1.0, rho = 1.0, p0 = 100.0;
  prim<double> operator()(double x, double y) const {
    return {rho,
            {U * std::sin(x) * std::cos(y), -U * std::cos(x) * std::sin(y), 0.0},
            p0 + 0.25 * rho * U * U * (std::cos(2 * x) + std::cos(2 * y))};
  }
  /// Kinetic energy ratio E(t)/E(0) of the viscous decay (incompressible limit).
  static double kinetic_energy_ratio(double nu, double t) { return std::exp(-4.0 * nu * t); }
};

}  // namespace parafsi::fluid::reference
