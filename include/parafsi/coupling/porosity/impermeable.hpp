/// \file impermeable.hpp
/// An airtight fabric: no through-flow for any pressure jump, u_p(Δp) = 0.
/// (Its pressure jump for a non-zero through-velocity is unbounded, so it has no
/// `pressure_jump`; the penalty spring alone stops the air.)
#pragma once
#include "../../core/simd.hpp"
#include "../kinds.hpp"

namespace parafsi::porosity {

struct impermeable {
  using policy_kind = kind::porosity;
  static constexpr bool permeable = false;
  static constexpr const char* name() noexcept { return "impermeable"; }
  void validate() const noexcept {}

  /// Through-velocity for a pressure jump dp (always 0).
  template <class V>
  PARAFSI_INLINE V through_velocity(const V&) const noexcept {
    return V(0.0);
  }
  /// d u_p / d Δp (always 0).
  template <class V>
  PARAFSI_INLINE V compliance(const V&) const noexcept {
    return V(0.0);
  }
};

}  // namespace parafsi::porosity
