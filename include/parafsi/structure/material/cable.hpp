/// \file cable.hpp
/// Materials of tension-only line elements (the paper's Eq. 5):
///   T = max(0, T0 + (EA/L0)(L − L0)) + c_d L̇ [taut],  c_d = 2 ξ √(k m_eff),  k = EA/L0.
/// `material::cable` gives EA and the mass per length directly (suspension lines,
/// risers, steel wire); `material::tape` derives them from a woven tape's modulus,
/// width, thickness and density (skirt/vent tapes, radial bands; seatbelt-style).
/// Both feed the same cable kernel (structure/cable.hpp).
///
/// References: LS-DYNA Keyword Manual, *MAT_CABLE_DISCRETE_BEAM, *MAT_SEATBELT;
///   Belytschko, Liu, Moran (2000) Nonlinear Finite Elements, §2 (bars).
#pragma once
#include <cmath>

#include "../../core/error.hpp"

namespace parafsi::structure::material {

struct cable {
  double EA = 0;               ///< axial stiffness (N)
  double mass_per_length = 0;  ///< ρ_l (kg/m), lumped ρ_l L0/2 per end
  double damping_ratio = 0;    ///< ξ of the axial mode of each element (0.05–0.2 typical)
  double preload = 0;          ///< T0 (N): tension at L = L0 (slack below L0 − T0 L0/EA)

  static constexpr const char* name() { return "cable"; }
  double axial_stiffness() const { return EA; }
  double linear_density() const { return mass_per_length; }
  void validate() const {
    require(EA > 0 && std::isfinite(EA), "material::cable: EA must be > 0, got ", EA);
    require(mass_per_length >= 0 && std::isfinite(mass_per_length),
            "material::cable: mass per length must be >= 0, got ", mass_per_length);
    require(damping_ratio >= 0 && damping_ratio < 1, "material::cable: damping ratio must be in [0, 1), got ",
            damping_ratio);
    require(preload >= 0 && std::isfinite(preload), "material::cable: preload must be >= 0, got ", preload);
  }
};

/// A woven tape: EA = E·w·t, ρ_l = ρ·w·t.
struct tape {
  double E = 0;              ///< effective Young's modulus along the tape (Pa)
  double width = 0;          ///< w (m)
  double thickness = 0;      ///< t (m)
  double density = 0;        ///< ρ (kg/m³)
  double damping_ratio = 0;  ///< ξ
  double preload = 0;        ///< T0 (N)

  static constexpr const char* name() { return "tape"; }
  double axial_stiffness() const { return E * width * thickness; }
  double linear_density() const { return density * width * thickness; }
  void validate() const {
    require(E > 0 && std::isfinite(E), "material::tape: E must be > 0, got ", E);
    require(width > 0 && std::isfinite(width), "material::tape: width must be > 0, got ", width);
    require(thickness > 0 && std::isfinite(thickness), "material::tape: thickness must be > 0, got ", thickness);
    require(density >= 0 && std::isfinite(density), "material::tape: density must be >= 0, got ", density);
    require(damping_ratio >= 0 && damping_ratio < 1, "material::tape: damping ratio must be in [0, 1), got ",
            damping_ratio);
    require(preload >= 0 && std::isfinite(preload), "material::tape: preload must be >= 0, got ", preload);
  }
};

}  // namespace parafsi::structure::material
