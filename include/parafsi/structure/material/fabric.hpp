/// \file fabric.hpp
/// Orthotropic fabric: linear plane-stress law in the warp (1) / weft (2) axes,
/// St Venant–Kirchhoff in the total-Lagrangian setting (the paper's Eq. 4):
///   ν21 = ν12 E2/E1,  D = 1 − ν12 ν21,
///   [S11]   [E1/D      ν12E2/D  0  ] [E11 ]
///   [S22] = [ν12E2/D   E2/D     0  ] [E22 ]
///   [S12]   [0         0        G12] [2E12]
/// S the second Piola–Kirchhoff stress, E the Green–Lagrange strain. Isotropic sheets
/// are the special case E1 = E2 = E, G12 = E/(2(1+ν)) (`fabric::isotropic`).
/// The membrane force per unit reference length is S·t; the mass per unit reference
/// area is the areal density ρ_A. Compression is filtered by a wrinkling policy
/// (default: compressive stress elimination with r_c = 1e-3).
/// Plane-wave speed for the time step: c = √(max(Q11, Q22)/ρ), ρ = ρ_A/t.
///
/// References: Jones R.M. (1999) Mechanics of Composite Materials, 2nd ed., §2.6;
///   Belytschko T., Liu W.K., Moran B. (2000) Nonlinear Finite Elements, §5.4.
#pragma once
#include <algorithm>
#include <cmath>

#include "../../core/error.hpp"
#include "wrinkling/moduli.hpp"
#include "wrinkling/none.hpp"
#include "wrinkling/stress_elimination.hpp"
#include "wrinkling/tension_field.hpp"

namespace parafsi::structure::material {

template <class Wrinkling = wrinkling::stress_elimination>
struct fabric {
  using wrinkling_type = Wrinkling;
  double E11 = 0;            ///< warp Young's modulus (Pa)
  double E22 = 0;            ///< weft Young's modulus (Pa)
  double nu12 = 0;           ///< major Poisson ratio (strain in 2 per strain in 1)
  double G12 = 0;            ///< in-plane shear modulus (Pa)
  double areal_density = 0;  ///< ρ_A, mass per reference area (kg/m²)
  double thickness = 0;      ///< t (m); only E·t and ρ_A enter the dynamics
  Wrinkling wrinkling{};

  /// Isotropic sheet (E, ν) as a special case.
  static fabric isotropic(double E, double nu, double areal_density, double thickness, Wrinkling w = {}) {
    return fabric{E, E, nu, E / (2.0 * (1.0 + nu)), areal_density, thickness, w};
  }

  void validate() const {
    require(E11 > 0 && std::isfinite(E11), "material::fabric: E11 must be > 0, got ", E11);
    require(E22 > 0 && std::isfinite(E22), "material::fabric: E22 must be > 0, got ", E22);
    require(G12 > 0 && std::isfinite(G12), "material::fabric: G12 must be > 0, got ", G12);
    require(thickness > 0 && std::isfinite(thickness), "material::fabric: thickness must be > 0, got ", thickness);
    require(areal_density > 0 && std::isfinite(areal_density), "material::fabric: areal density must be > 0, got ",
            areal_density);
    const double nu21 = nu12 * E22 / E11;
    require(std::isfinite(nu12) && 1.0 - nu12 * nu21 > 0.0, "material::fabric: Poisson ratio nu12 = ", nu12,
            " gives a non-positive-definite law (1 - nu12 nu21 = ", 1.0 - nu12 * nu21, ")");
    if constexpr (requires { wrinkling.validate(); }) wrinkling.validate();
  }

  fabric_moduli moduli() const {
    const double nu21 = nu12 * E22 / E11;
    const double D = 1.0 - nu12 * nu21;
    return {E11, E22, nu12, G12, E11 / D, nu12 * E22 / D, E22 / D, G12};
  }
  /// Volumetric density ρ = ρ_A / t (kg/m³).
  double density() const { return areal_density / thickness; }
  /// Fastest in-plane wave speed √(max(Q11, Q22)/ρ) (m/s).
  double wave_speed() const {
    const fabric_moduli q = moduli();
    return std::sqrt(std::max(q.Q11, q.Q22) / density());
  }
};

}  // namespace parafsi::structure::material
