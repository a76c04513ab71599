/// \file coupling.hpp
/// Umbrella header of the coupling module: porosity laws, coupling points, the
/// penalty coupling and `coupling::none`.
#pragma once
#include "coupling_points.hpp"
#include "kinds.hpp"
#include "none.hpp"
#include "penalty.hpp"
#include "porosity/darcy.hpp"
#include "porosity/ergun.hpp"
#include "porosity/impermeable.hpp"
