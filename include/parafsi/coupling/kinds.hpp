/// \file kinds.hpp
/// Policy kinds of the coupling module: `kind::porosity` (how a fabric lets air
/// through) and `kind::coupling` (how the structure and the air exchange forces).
/// They live beside core/policy.hpp's kinds and work with its `pick_t`/`pick_value`.
#pragma once
#include "../core/policy.hpp"

namespace parafsi::kind {
struct porosity {};
struct coupling {};
}  // namespace parafsi::kind
