/// \file none.hpp
/// Wrinkling off: the fabric carries compression like an elastic sheet
/// (for patch tests and for comparison; not for real canopies).
#pragma once
#include "../../../core/simd.hpp"
#include "moduli.hpp"

namespace parafsi::structure::wrinkling {

struct none {
  static constexpr const char* name() { return "none"; }
  void validate() const {}
  template <class V>
  PARAFSI_INLINE void apply(V&, V&, V&, V&, V&, V&, const V&, const V&, const V&, const fabric_moduli&) const noexcept {
  }
};

}  // namespace parafsi::structure::wrinkling
