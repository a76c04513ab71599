/// \file far_field.hpp
/// Reflection-free far field by Riemann invariants on a (moving) face with outward
/// normal n and grid normal speed w_n; interior state i, far-field state ∞:
///   U_i = u_i·n − w_n,  U_∞ = u_∞·n − w_n,
///   R⁺ = U_i + 2c_i/(γ−1),  R⁻ = U_∞ − 2c_∞/(γ−1),
///   U_b = ½(R⁺ + R⁻),  c_b = ¼(γ−1)(R⁺ − R⁻);
/// entropy s = p/ρ^γ and tangential velocity from ∞ on inflow (U_b < 0), from the
/// interior on outflow; ρ_b = (c_b²/(γ s))^{1/(γ−1)} (computed as ρ_s (c_b²/c_s²)^{1/(γ−1)},
/// one power), p_b = ρ_b c_b²/γ,
/// u_b = u_t + (U_b + w_n) n. Supersonic faces take the upwind state. Non-reflecting
/// for normally incident acoustic waves; pair it with a sponge layer for vortices.
/// Reference: Blazek J. (2015) Computational Fluid Dynamics: Principles and
///   Applications, 3rd ed., §8.2.
#pragma once
#include <cmath>

#include "../state.hpp"

namespace parafsi::boundary {
struct far_field {
  double rho = 1.18;              ///< far-field density (kg/m³)
  vec3<double> u{0.0, 0.0, 0.0};  ///< far-field velocity (m/s, inertial)
  double p = 101325.0;            ///< far-field pressure (Pa)

  static constexpr const char* name() noexcept { return "far_field"; }
  static constexpr bool layer_invariant = true;  ///< the ghost reads the adjacent cell only

  fluid::prim<double> ghost(const fluid::prim<double>&, const fluid::prim<double>& in, const vec3<double>& n, double wn,
                            const gas::ideal& g, double) const {
    const double gm1 = g.gamma - 1.0;
    const double ci = std::sqrt(g.gamma * in.p / in.rho), cinf = std::sqrt(g.gamma * p / rho);
    const double Ui = dot(in.u, n) - wn, Uinf = dot(u, n) - wn;
    if (Ui >= ci) return in;                             // supersonic outflow
    if (Uinf <= -cinf && Ui <= -ci) return {rho, u, p};  // supersonic inflow
    const double Rp = Ui + 2.0 * ci / gm1, Rm = Uinf - 2.0 * cinf / gm1;
    const double Ub = 0.5 * (Rp + Rm), cb = 0.25 * gm1 * (Rp - Rm);
    const bool inflow = Ub < 0.0;
    const fluid::prim<double>& src = inflow ? fluid::prim<double>{rho, u, p} : in;
    // On the isentrope of src (s = p/ρ^γ = c²ρ^(1−γ)/γ): ρ_b = ρ_src (c_b²/c_src²)^{1/(γ−1)}.
    const double rb = src.rho * std::pow(cb * cb * src.rho / (g.gamma * src.p), 1.0 / gm1);
    const double pb = rb * cb * cb / g.gamma;
    const vec3<double> ut = axpy_n(src.u, -dot(src.u, n), n);
    return {rb, axpy_n(ut, Ub + wn, n), pb};
  }
  fluid::prim<double> state() const { return {rho, u, p}; }
};
}  // namespace parafsi::boundary
