/// \file darcy.hpp
/// Linear (Darcy) porosity: Δp / t = α V, i.e. Δp = R V with R = α t (Pa s/m).
/// `from_reference(V_ref, Δp_ref, t)` fits α to one measured point (e.g. an air
/// permeability in L/(m² s) at a test pressure).
/// Reference: Darcy H. (1856); methods §4.7 (linear fit tα ≈ 245 Pa s/m for nylon).
#pragma once
#include <cmath>

#include "../../core/error.hpp"
#include "../../core/simd.hpp"
#include "../kinds.hpp"

namespace parafsi::porosity {

struct darcy {
  double alpha = 0;      ///< α (kg m⁻³ s⁻¹): Δp/t = α V
  double thickness = 0;  ///< t (m)

  using policy_kind = kind::porosity;
  static constexpr bool permeable = true;
  static constexpr const char* name() noexcept { return "darcy"; }

  static darcy from_reference(double v_ref, double dp_ref, double thickness) {
    require(v_ref > 0 && dp_ref > 0 && thickness > 0,
            "porosity::darcy::from_reference: need V_ref, dp_ref, t > 0, got ", v_ref, ", ", dp_ref, ", ", thickness);
    return {dp_ref / (v_ref * thickness), thickness};
  }

  void validate() const {
    require(std::isfinite(alpha) && alpha > 0, "porosity::darcy: alpha must be > 0, got ", alpha);
    require(std::isfinite(thickness) && thickness > 0, "porosity::darcy: thickness must be > 0, got ", thickness);
  }
  template <class V>
  PARAFSI_INLINE V pressure_jump(const V& u) const noexcept {
    return V(alpha * thickness) * u;
  }
  template <class V>
  PARAFSI_INLINE V resistance(const V&) const noexcept {
    return V(alpha * thickness);
  }
  template <class V>
  PARAFSI_INLINE V through_velocity(const V& dp) const noexcept {
    return dp * V(1.0 / (alpha * thickness));
  }
  template <class V>
  PARAFSI_INLINE V compliance(const V&) const noexcept {
    return V(1.0 / (alpha * thickness));
  }
};

}  // namespace parafsi::porosity
