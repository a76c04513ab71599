/// \file fluid.hpp
/// All fluid components: gas, states, fluxes, reconstructions, closures, frames,
/// boundaries, the solver and the exact Riemann solver.
#pragma once

#include "boundary/condition.hpp"
#include "exact_riemann.hpp"
#include "flux/ale.hpp"
#include "flux/ausm_plus_up.hpp"
#include "flux/hllc.hpp"
#include "flux/hllc_lm.hpp"
#include "flux/rusanov.hpp"
#include "frame/fixed.hpp"
#include "frame/follow_payload.hpp"
#include "frame/rigid.hpp"
#include "frame/translate.hpp"
#include "gas.hpp"
#include "grid.hpp"
#include "reconstruction/first_order.hpp"
#include "reconstruction/muscl.hpp"
#include "reference/vortices.hpp"
#include "solver.hpp"
#include "state.hpp"
#include "turbulence/none.hpp"
#include "turbulence/prandtl_mixing_length.hpp"
#include "turbulence/smagorinsky.hpp"
#include "viscosity/constant.hpp"
#include "viscosity/inviscid.hpp"
#include "viscosity/sutherland.hpp"
