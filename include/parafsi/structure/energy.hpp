/// \file energy.hpp
/// Energy bookkeeping of an explicit structural run (J):
///   kinetic  K = ½ Σ m |v^{n+½}|² (+ rigid bodies),      strain U = Σ_e U_e(x^n),
///   damping  D = Σ_n Δt̄ (−f_d · v̄ + α m |v̄|²)  (dissipated, ≥ 0),
///   external W = Σ_n Δt̄ ((f_ext + m g) · v̄ + reactions of prescribed nodes),
/// with v̄ = ½(v^{n−½} + v^{n+½}) and Δt̄ the central-difference kick. For leapfrog,
/// ΔK = Δt̄ f·v̄ exactly, so K + U + D − W stays constant up to the O(Δt²) difference
/// between Δt̄ f_int·v̄ and −ΔU: `balance()` is the number tests watch.
#pragma once

namespace parafsi::structure {

struct energy_ledger {
  double kinetic = 0;   ///< at the last half step
  double strain = 0;    ///< at the last force evaluation
  double damping = 0;   ///< dissipated since tracking began
  double external = 0;  ///< work done on the structure since tracking began
  /// K + U + D − W: constant for an exact balance.
  double balance() const { return kinetic + strain + damping - external; }
};

}  // namespace parafsi::structure
