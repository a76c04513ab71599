/// \file slip_wall.hpp
/// Inviscid (slip) wall moving with the box: the ghost state mirrors the interior
/// with its normal velocity reflected about the wall's normal speed w_n,
///   u_g = u − 2 (u·n − w_n) n,  ρ_g = ρ,  p_g = p,
/// so the Riemann problem at the wall has zero relative normal velocity.
#pragma once
#include "../state.hpp"

namespace parafsi::boundary {
struct slip_wall {
  static constexpr const char* name() noexcept { return "slip_wall"; }
  fluid::prim<double> ghost(const fluid::prim<double>& mirror, const fluid::prim<double>&, const vec3<double>& n,
                            double wn, const gas::ideal&, double) const {
    fluid::prim<double> g = mirror;
    g.u = axpy_n(mirror.u, -2.0 * (dot(mirror.u, n) - wn), n);
    return g;
  }
};
}  // namespace parafsi::boundary
