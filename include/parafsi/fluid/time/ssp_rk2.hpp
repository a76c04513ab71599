/// \file ssp_rk2.hpp
/// Two-stage strong-stability-preserving Runge–Kutta (Heun) in Shu–Osher form:
///   U⁽¹⁾ = Uⁿ + Δt L(Uⁿ, tⁿ),   Uⁿ⁺¹ = ½ Uⁿ + ½ [U⁽¹⁾ + Δt L(U⁽¹⁾, tⁿ⁺¹)].
/// Its stability region does not contain the imaginary axis: with nearly central
/// fluxes (HLLC-LM at M ≲ 0.01) acoustic modes are weakly amplified; prefer ssp_rk3 there.
/// Reference: Gottlieb S., Shu C.-W. (1998) Math. Comp. 67:73.
#pragma once
#include <array>

#include "../../core/policy.hpp"

namespace parafsi::time {

struct ssp_rk2 {
  using policy_kind = kind::time;
  static constexpr const char* name() noexcept { return "ssp_rk2"; }
  static constexpr int stages = 2;
  /// U⁽ˢ⁾ = a_s Uⁿ + b_s (U⁽ˢ⁻¹⁾ + Δt L(U⁽ˢ⁻¹⁾)), evaluated at tⁿ + c_s Δt.
  static constexpr std::array<double, 2> a{0.0, 0.5}, b{1.0, 0.5}, c{0.0, 1.0};
};

}  // namespace parafsi::time
