/// \file gas.hpp
/// Ideal (calorically perfect) gas:  p = (γ − 1) ρ e,  c² = γ p / ρ,  T = p / (ρ R).
/// Defaults are dry air: γ = 1.4, R = 287.05 J/(kg K).
#pragma once
#include "../core/error.hpp"
#include "../core/policy.hpp"
#include "../core/simd.hpp"

namespace parafsi::gas {

struct ideal {
  double gamma = 1.4;  ///< ratio of specific heats (-)
  double R = 287.05;   ///< specific gas constant (J/(kg K))

  using policy_kind = kind::gas;
  static constexpr const char* name() noexcept { return "ideal_gas"; }

  void validate() const {
    require(gamma > 1.0 && gamma < 5.0, "gas::ideal: gamma must lie in (1, 5), got ", gamma);
    require(R > 0.0, "gas::ideal: R must be positive, got ", R);
  }
  double cp() const noexcept { return gamma * R / (gamma - 1.0); }

  template <class V>
  PARAFSI_INLINE V sound_speed(const V& rho, const V& p) const noexcept {
    return simd::sqrt(V(gamma) * p / rho);
  }
  template <class V>
  PARAFSI_INLINE V temperature(const V& rho, const V& p) const noexcept {
    return p / (rho * V(R));
  }
  /// Pressure from density, momentum and total energy per volume.
  template <class V>
  PARAFSI_INLINE V pressure(const V& rho, const V& mx, const V& my, const V& mz, const V& E) const noexcept {
    return V(gamma - 1.0) * (E - V(0.5) * (mx * mx + my * my + mz * mz) / rho);
  }
  /// Total energy per volume from primitives.
  template <class V>
  PARAFSI_INLINE V total_energy(const V& rho, const V& u, const V& v, const V& w, const V& p) const noexcept {
    return p / V(gamma - 1.0) + V(0.5) * rho * (u * u + v * v + w * w);
  }
};

}  // namespace parafsi::gas
