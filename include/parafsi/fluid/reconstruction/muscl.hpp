/// \file muscl.hpp
/// Piecewise-linear (MUSCL) reconstruction of the primitive variables
/// W = (ρ, u, v, w, p), direction by direction:
///   W_{i±½}^∓ = W_i ± (Δx_i/2) · limiter(a, b),
/// with the gradients a, b of limiters.hpp. Where a reconstructed density or
/// pressure would be non-positive the solver falls back to the cell value
/// (first order) on that side.
/// References: van Leer B. (1979) J. Comput. Phys. 32:101; Toro (2009) §13.4.
#pragma once
#include "../../core/policy.hpp"
#include "limiters.hpp"

namespace parafsi::recon {

template <class Limiter = limiter::van_leer>
struct muscl {
  Limiter limiter{};
  static constexpr bool second_order = true;
  using policy_kind = kind::reconstruction;
  static constexpr const char* name() noexcept { return Limiter::name(); }
  /// Limited slope (per unit length) from the left and right gradients.
  template <class V>
  PARAFSI_INLINE V slope(const V& a, const V& b) const noexcept {
    return limiter(a, b);
  }
};

}  // namespace parafsi::recon
