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
#pragma once
#include <array>
#include <string_view>

#include "../core/error.hpp"

namespace parafsi::model {

struct fabric_data {
  std::string_view name;
  double areal_density;      ///< kg/m²
  double thickness;          ///< m
  double break_strength;     ///< N per 5 cm strip
  double elongation;         ///< at break, fraction
  double air_permeability;   ///< m/s at the test pressure
  double test_pressure;      ///< Pa
  double alpha;              ///< Ergun α (kg m⁻³ s⁻¹)
  double beta;               ///< Ergun β (kg m⁻⁴)
};

inline constexpr std::array<fabric_data, 3> fabric_catalogue{{
    {"mat544", 54e-3, 0.11e-3, 450.0, 0.26, 20e-3, 50.0, 22498098.80, 11458696.49},
    {"mat59225", 80e-3, 0.24e-3, 950.0, 0.24, 200e-3, 50.0, 852254.72, 947059.73},
    {"mat509", 56e-3, 0.17e-3, 560.0, 0.22, 650e-3, 50.0, 299337.56, 235617.12},
}};

/// The catalogue entry named `name` (mat544, mat59225, mat509).
inline const fabric_data& fabric(std::string_view name) {
  for (const auto& f : fabric_catalogue)
    if (f.name == name) return f;
  throw invalid_input(detail::concat("model::fabric: unknown fabric '", name, "' (known: mat544, mat59225, mat509)"));
}

}  // namespace parafsi::model
