/// \file constant.hpp
/// Constant dynamic viscosity μ and Prandtl number Pr (heat conductivity
/// k = c_p μ / Pr). The paper's air: μ = 1.79e-5 Pa s.
#pragma once
#include "../../core/error.hpp"
#include "../../core/policy.hpp"

namespace parafsi::viscosity {

struct constant {
  static constexpr bool active = true;
  using policy_kind = kind::viscosity;
  static constexpr const char* name() noexcept { return "constant_viscosity"; }
  double mu_value = 1.79e-5;  ///< dynamic viscosity (Pa s)
  double prandtl = 0.72;      ///< molecular Prandtl number (-)
  void validate() const {
    require(mu_value >= 0.0, "viscosity::constant: mu must be >= 0, got ", mu_value);
    require(prandtl > 0.0, "viscosity::constant: Prandtl number must be > 0, got ", prandtl);
  }
  template <class V>
  V mu(const V&) const noexcept {
    return V(mu_value);
  }
};

}  // namespace parafsi::viscosity
