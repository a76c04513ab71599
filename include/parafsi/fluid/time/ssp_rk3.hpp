/// \file ssp_rk3.hpp
/// Three-stage, third-order strong-stability-preserving Runge–Kutta (Shu–Osher):
///   U⁽¹⁾ = Uⁿ + Δt L(Uⁿ),
///   U⁽²⁾ = ¾ Uⁿ + ¼ [U⁽¹⁾ + Δt L(U⁽¹⁾)],
///   Uⁿ⁺¹ = ⅓ Uⁿ + ⅔ [U⁽²⁾ + Δt L(U⁽²⁾)],
/// stage times tⁿ, tⁿ + Δt, tⁿ + Δt/2. Its stability region contains the imaginary
/// axis up to |z| = √3, so it stays stable with the nearly central low-Mach fluxes.
/// Reference: Shu C.-W., Osher S. (1988) J. Comput. Phys. 77:439.
#pragma once
#include <array>

#include "../../core/policy.hpp"

namespace parafsi::time {

struct ssp_rk3 {
  using policy_kind = kind::time;
  static constexpr const char* name() noexcept { return "ssp_rk3"; }
  static constexpr int stages = 3;
  static constexpr std::array<double, 3> a{0.0, 0.75, 1.0 / 3.0}, b{1.0, 0.25, 2.0 / 3.0}, c{0.0, 1.0, 0.5};
};

}  // namespace parafsi::time
