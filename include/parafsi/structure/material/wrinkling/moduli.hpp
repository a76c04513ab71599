/// \file moduli.hpp
/// Plane-stress constants of an orthotropic fabric in its warp/weft axes, passed to
/// the wrinkling policies (which may need the directional modulus).
#pragma once
#include "../../../core/error.hpp"

namespace parafsi::structure {

struct fabric_moduli {
  double E1, E2, nu12, G12;   ///< warp/weft Young's moduli, major Poisson ratio, shear modulus (Pa)
  double Q11, Q12, Q22, Q66;  ///< plane-stress stiffness [S11,S22,S12] = Q [E11,E22,2E12]
};

}  // namespace parafsi::structure
