/// \file fabric_catalogue.hpp
/// The three canopy fabrics of the drop study (plain data, no solver types).
///
/// Source: the paper's Table 2 ("Material properties of canopy fabric used"):
///
///   |                          | 544 kam silk  | 59,225 kam silk | 509 kam silk |
///   |--------------------------|---------------|-----------------|--------------|
///   | weight (g/m²)            | 54            | 80              | 56           |
///   | thickness (mm)           | 0.11          | 0.24            | 0.17         |
///   | break strength (N/5 cm)  | 450           | 950             | 560          |
///   | elongation (%)           | 26            | 24              | 22           |
///   | air permeability (L/m²s) | 20            | 200             | 650          |
///   | α (kg m⁻³ s⁻¹)           | 22,498,098.80 | 852,254.72      | 299,337.56   |
///   | β (kg m⁻⁴)               | 11,458,696.49 | 947,059.73      | 235,617.12   |
///
/// The air permeabilities are the Ergun law Δp/t = αV + βV² at Δp = 50 Pa
/// (checked by tests/test_coupling_porosity.cpp to 1 %).
///
/// Derived membrane moduli (`derived_moduli`). Table 2 gives no moduli, only the strip
/// break strength F_b (N per 5 cm strip) and the elongation at break ε_b. The membrane
/// only sees the product E·t, and the secant stiffness of the strip up to break is
///     E·t ≈ (F_b / w) / ε_b,   w = 0.05 m,      E = (E·t)/t
/// (mat544: 9000 N/m / 0.26 = 34.6 kN/m, E = 0.315 GPa; mat59225: 79.2 kN/m, 0.330 GPa;
/// mat509: 50.9 kN/m, 0.299 GPa). Uncertainty: woven nylon is not linear to break
/// (crimp interchange makes the low-strain modulus lower, the yarn phase stiffer), the
/// strip test is a warp (or unspecified-direction) value, and Table 2 gives one value
/// for both directions; the secant is a load-weighted average good to about a factor
/// of 2, so moduli enter the sensitivity study. Defaults for what Table 2 does not give:
/// E22 = E11 (balanced plain weave), ν12 = 0.2 (woven fabrics: 0.1–0.4 in biaxial
/// tests), G12 = E11/(2(1+ν12)) (isotropic-equivalent; the measured in-plane shear
/// modulus of open woven nylon is far lower, 1–10 % of E, which a caller can set with
/// `moduli_options::shear_ratio`). Source of the rule: the standard secant-modulus
/// estimate from a strip tensile test (ASTM D5035 strip method; Knacke, Parachute
/// Recovery Systems Design Manual, NWC TP 6575, ch. 4 on textile load–elongation).
#pragma once
#include <array>
#include <cmath>
#include <string_view>

#include "../core/error.hpp"

namespace parafsi::model {

struct fabric_data {
  std::string_view name;
  double areal_density;     ///< kg/m²
  double thickness;         ///< m
  double break_strength;    ///< N per 5 cm strip
  double elongation;        ///< at break, fraction
  double air_permeability;  ///< m/s at the test pressure
  double test_pressure;     ///< Pa
  double alpha;             ///< Ergun α (kg m⁻³ s⁻¹)
  double beta;              ///< Ergun β (kg m⁻⁴)
};

inline constexpr std::array<fabric_data, 3> fabric_catalogue{{
    {"mat544", 54e-3, 0.11e-3, 450.0, 0.26, 20e-3, 50.0, 22498098.80, 11458696.49},
    {"mat59225", 80e-3, 0.24e-3, 950.0, 0.24, 200e-3, 50.0, 852254.72, 947059.73},
    {"mat509", 56e-3, 0.17e-3, 560.0, 0.22, 650e-3, 50.0, 299337.56, 235617.12},
}};

/// Fabrics outside Table 2 (kept out of `fabric_catalogue`, whose three rows are the
/// paper's). `c9_mil_c_7020`: the C-9 canopy cloth, MIL-C-7020 Type I (PIA-C-7020)
/// 1.1 oz/yd² ripstop nylon: 37.3 g/m², ≈ 0.1 mm, 42 lbf/in (7.36 kN/m) minimum break
/// strength, elongation taken as 0.25 (spec minimum about 20 %), air permeability
/// 100 ft³/ft²/min = 0.508 m/s at ½ in H₂O = 124.5 Pa. Break strength is stored per 5 cm
/// strip like Table 2 (368 N). No permeability curve is known, so the Ergun law is a
/// one-point Darcy fit, β = 0, α = Δp/(t V) = 2.45e6 kg m⁻³ s⁻¹ (exact at 124.5 Pa).
inline constexpr std::array<fabric_data, 1> extra_fabrics{{
    {"c9_mil_c_7020", 37.3e-3, 0.1e-3, 368.0, 0.25, 0.508, 124.5, 124.5 / (0.1e-3 * 0.508), 0.0},
}};

/// The catalogue entry named `name` (mat544, mat59225, mat509, or an `extra_fabrics` name).
inline const fabric_data& fabric(std::string_view name) {
  for (const auto& f : fabric_catalogue)
    if (f.name == name) return f;
  for (const auto& f : extra_fabrics)
    if (f.name == name) return f;
  throw invalid_input(
      detail::concat("model::fabric: unknown fabric '", name, "' (known: mat544, mat59225, mat509, c9_mil_c_7020)"));
}

/// Strip width of the break-strength test (Table 2 gives N per 5 cm).
inline constexpr double strip_width = 0.05;

/// Choices for what the fabric data do not give (see the file comment).
struct moduli_options {
  double nu12 = 0.2;           ///< major Poisson ratio
  double weft_ratio = 1.0;     ///< E22 / E11
  double shear_ratio = 0.0;    ///< G12 / E11; 0 = isotropic-equivalent E11/(2(1+ν12))
  double modulus_scale = 1.0;  ///< multiplies E11, E22, G12 (sensitivity studies)
};

/// Membrane moduli in the order structure::material::fabric takes them:
/// `fabric<>{m.E11, m.E22, m.nu12, m.G12, m.areal_density, m.thickness}`.
struct membrane_moduli {
  double E11;            ///< warp Young's modulus (Pa)
  double E22;            ///< weft Young's modulus (Pa)
  double nu12;           ///< major Poisson ratio
  double G12;            ///< in-plane shear modulus (Pa)
  double areal_density;  ///< kg/m²
  double thickness;      ///< m
  /// Membrane stiffness E11·t (N/m).
  double stiffness() const { return E11 * thickness; }
};

/// Break force per unit width F_b/w (N/m).
inline double break_force_per_width(const fabric_data& f) { return f.break_strength / strip_width; }

/// E·t ≈ (F_b/w)/ε_b, E = E·t / t, and the documented defaults for E22, ν12, G12.
inline membrane_moduli derived_moduli(const fabric_data& f, const moduli_options& o = {}) {
  require(f.thickness > 0 && std::isfinite(f.thickness), "model::derived_moduli: fabric '", f.name, "' has thickness ",
          f.thickness, " (must be > 0)");
  require(f.elongation > 0 && std::isfinite(f.elongation), "model::derived_moduli: fabric '", f.name,
          "' has elongation at break ", f.elongation, " (must be > 0)");
  require(f.break_strength > 0 && std::isfinite(f.break_strength), "model::derived_moduli: fabric '", f.name,
          "' has break strength ", f.break_strength, " (must be > 0)");
  require(o.nu12 >= 0 && o.nu12 < 0.5, "model::derived_moduli: nu12 must be in [0, 0.5), got ", o.nu12);
  require(o.weft_ratio > 0 && std::isfinite(o.weft_ratio), "model::derived_moduli: weft ratio must be > 0, got ",
          o.weft_ratio);
  require(o.shear_ratio >= 0 && std::isfinite(o.shear_ratio), "model::derived_moduli: shear ratio must be >= 0, got ",
          o.shear_ratio);
  require(o.modulus_scale > 0 && std::isfinite(o.modulus_scale),
          "model::derived_moduli: modulus scale must be > 0, got ", o.modulus_scale);
  const double Et = break_force_per_width(f) / f.elongation;
  const double E1 = o.modulus_scale * Et / f.thickness;
  const double G = o.shear_ratio > 0 ? o.shear_ratio * E1 : E1 / (2.0 * (1.0 + o.nu12));
  return {E1, o.weft_ratio * E1, o.nu12, G, f.areal_density, f.thickness};
}

}  // namespace parafsi::model
