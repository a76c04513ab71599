/// \file structure.hpp
/// Umbrella header of the structural dynamics: nodes, fabric and cable materials,
/// membranes (CST triangle, Belytschko–Tsay quad), cables/tapes, rigid body and its
/// attachment, assembly with the central-difference update, energy ledger, relaxation
/// helper, closed-form references.
#pragma once

#include "assembly.hpp"
#include "attachment.hpp"
#include "cable.hpp"
#include "central_difference.hpp"
#include "energy.hpp"
#include "material/cable.hpp"
#include "material/fabric.hpp"
#include "membrane_quad.hpp"
#include "membrane_tri.hpp"
#include "nodes.hpp"
#include "reference/catenary.hpp"
#include "reference/hencky.hpp"
#include "relax.hpp"
#include "rigid_body.hpp"
