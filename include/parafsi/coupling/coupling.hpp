/// \file coupling.hpp
/// Umbrella header of the coupling module: porosity laws, coupling points, the
/// penalty and embedded couplings and `coupling::none`.
#pragma once
#include "coupling_points.hpp"
#include "embedded.hpp"
#include "kinds.hpp"
#include "none.hpp"
#include "penalty.hpp"
#include "porosity/darcy.hpp"
#include "porosity/ergun.hpp"
#include "porosity/impermeable.hpp"
