/// \file hllc.hpp
/// HLLC approximate Riemann solver (Toro, Spruce & Speares 1994) with Einfeldt
/// wave speeds:
///   F = F_L (S_L ≥ 0);  F_L + S_L (U*_L − U_L) (S_L ≤ 0 ≤ S*);
///       F_R + S_R (U*_R − U_R) (S* ≤ 0 ≤ S_R);  F_R (S_R ≤ 0).
/// Exact for isolated contacts and shear waves; dissipation scales like 1/M at low Mach.
/// References: Toro E.F. (2009) Riemann Solvers and Numerical Methods, 3rd ed., §10.4;
///   Batten P. et al. (1997) SIAM J. Sci. Comput. 18:1553.
#pragma once
#include "../../core/policy.hpp"
#include "hllc_common.hpp"

namespace parafsi::flux {

struct hllc {
  using policy_kind = kind::flux;
  static constexpr const char* name() noexcept { return "hllc"; }

  template <class V>
  PARAFSI_INLINE fluid::cons<V> operator()(const fluid::prim<V>& L, const fluid::prim<V>& R, const vec3<double>& n,
                                           const gas::ideal& g) const noexcept {
    using fluid::select;
    const auto h = detail::hllc_prepare(L, R, n, g);
    const auto FsL = h.FL + (h.UsL - h.UL) * h.SL;
    const auto FsR = h.FR + (h.UsR - h.UR) * h.SR;
    const auto inner = select<V>(h.Sstar >= V(0.0), FsL, FsR);
    return select<V>(h.SL >= V(0.0), h.FL, select<V>(h.SR <= V(0.0), h.FR, inner));
  }
};

}  // namespace parafsi::flux
