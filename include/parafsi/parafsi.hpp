/// \file parafsi.hpp
/// Umbrella header: every public component of parafsi.
#pragma once

#include "core/config.hpp"
#include "core/error.hpp"
#include "core/meta.hpp"
#include "core/parallel.hpp"
#include "core/policy.hpp"
#include "core/simd.hpp"
#include "core/soa.hpp"
#include "core/vec3.hpp"

#include "fluid/fluid.hpp"
#include "structure/structure.hpp"
