/// \file first_order.hpp
/// Piecewise-constant reconstruction (Godunov's first-order scheme): W_{i±½}^∓ = W_i.
/// The sweep skips slope computation entirely for this policy.
/// Reference: Godunov S.K. (1959) Mat. Sb. 47:271.
#pragma once
#include "../../core/policy.hpp"
#include "../../core/simd.hpp"

namespace parafsi::recon {

struct first_order {
  static constexpr bool second_order = false;
  using policy_kind = kind::reconstruction;
  static constexpr const char* name() noexcept { return "none"; }
  template <class V>
  PARAFSI_INLINE V slope(const V&, const V&) const noexcept {
    return V(0.0);
  }
};

}  // namespace parafsi::recon
