/// \file none.hpp
/// `coupling::none`: no exchange between the parts of a stepper (fluid-only,
/// structure-only, or both advanced side by side). Holds nothing, does nothing.
#pragma once
#include "kinds.hpp"

namespace parafsi::coupling {
struct none {
  using policy_kind = kind::coupling;
  static constexpr bool active = false;
  static constexpr const char* name() noexcept { return "none"; }
};
}  // namespace parafsi::coupling
