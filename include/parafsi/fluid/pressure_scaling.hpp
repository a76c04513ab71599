/// \file pressure_scaling.hpp
/// Pressure-gradient scaling (PGS) for slow flows: the acoustic speed lowered by α ≥ 1 so
/// an explicit compressible solver takes α times larger steps.
///
/// PGS (Ramshaw, O'Rourke & Stein 1985) divides the pressure gradient in the momentum
/// equation by α² and leaves the pressure equation alone:
///     ρ Du/Dt = −∇p / α²,   Dp/Dt = −γ p ∇·u,   Dρ/Dt = −ρ ∇·u.
/// With q = p / α² this is, term by term,
///     ρ Du/Dt = −∇q,        Dq/Dt = −γ q ∇·u,   Dρ/Dt = −ρ ∇·u,
/// the Euler equations of the same ideal gas at the ambient pressure p∞/α² and the same
/// density: sound speed c/α, Mach number αM, identical velocity field. So PGS needs no
/// change to the solver, its fluxes or its boundaries: the fluid is simply initialised and
/// held at the scaled ambient q∞ = p∞/α². The pressure *differences* that move the flow
/// and load a structure, q − q∞, are those of the physical low-Mach flow (to O((αM)²));
/// the physical pressure of a cell is p∞ + (q − q∞) (what `physical_pressure` returns and
/// the outputs should show).
///
/// What it costs: compressibility errors grow from O(M²) to O((αM)²) (density
/// perturbations α² larger), acoustic phenomena (pressure waves, the piston's ρcv) are
/// α times slower and α times weaker, and anything tied to the bulk modulus γp (a penalty
/// coupling's stiffness, methods §4.4) is α² softer. Keep αM ≲ 0.2; measure the effect on
/// every answer that matters (docs/fluid_theory.md §11, docs/validation.md).
/// The temperature q/(ρR) is α² lower: use it only with a constant (or temperature-free)
/// viscosity. Density perturbations are those of the scaled gas (α² larger than the
/// physical ones); only pressure has a mapping back.
///
/// References: Ramshaw J.D., O'Rourke P.J., Stein L.R. (1985) J. Comput. Phys. 58:361
///   (pressure gradient scaling); Wang Y., Trouvé A. (2004) Combust. Flame 139:37 (PGS
///   for low-Mach compressible simulation).
#pragma once
#include <cmath>

#include "../core/error.hpp"

namespace parafsi::fluid {

struct pressure_gradient_scaling {
  double alpha = 1.0;  ///< acoustic-speed reduction factor α ≥ 1 (1 = off)

  void validate() const {
    require(std::isfinite(alpha) && alpha >= 1.0 && alpha <= 1e3,
            "fluid::pressure_gradient_scaling: alpha must lie in [1, 1000], got ", alpha);
  }
  /// Ambient pressure the scaled fluid is initialised and held at: p∞ / α².
  double scaled_ambient(double p_ambient) const noexcept { return p_ambient / (alpha * alpha); }
  /// Physical pressure of a scaled cell pressure q: p∞ + (q − p∞/α²).
  double physical_pressure(double q, double p_ambient) const noexcept {
    return p_ambient + (q - scaled_ambient(p_ambient));
  }
  /// Offset to add to scaled pressures to obtain physical ones: p∞ (1 − 1/α²).
  double pressure_offset(double p_ambient) const noexcept { return p_ambient - scaled_ambient(p_ambient); }
  /// Mach number of the scaled flow, α M.
  double effective_mach(double mach) const noexcept { return alpha * mach; }
};

}  // namespace parafsi::fluid
