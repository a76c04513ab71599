/// \file sutherland.hpp
/// Sutherland's law  μ(T) = μ_ref (T/T_ref)^{3/2} (T_ref + S)/(T + S),
/// air: μ_ref = 1.716e-5 Pa s at T_ref = 273.15 K, S = 110.4 K.
/// Reference: Sutherland W. (1893) Phil. Mag. 36:507; White F.M., Viscous Fluid Flow.
#pragma once
#include "../../core/error.hpp"
#include "../../core/policy.hpp"
#include "../../core/simd.hpp"

namespace parafsi::viscosity {

struct sutherland {
  static constexpr bool active = true;
  using policy_kind = kind::viscosity;
  static constexpr const char* name() noexcept { return "sutherland"; }
  double mu_ref = 1.716e-5, T_ref = 273.15, S = 110.4;
  double prandtl = 0.72;
  void validate() const { require(mu_ref > 0.0 && T_ref > 0.0 && S >= 0.0, "viscosity::sutherland: bad constants"); }
  template <class V>
  V mu(const V& T) const noexcept {
    const V r = T / V(T_ref);
    return V(mu_ref) * r * simd::sqrt(r) * V(T_ref + S) / (T + V(S));
  }
};

}  // namespace parafsi::viscosity
