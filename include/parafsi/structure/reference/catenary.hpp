/// \file catenary.hpp
/// Inextensible catenary between two supports at equal height, span S, length L > S:
///   z(x) = a cosh(x/a) − a cosh(S/(2a)),  x ∈ [−S/2, S/2],   L = 2a sinh(S/(2a)),
/// a found by bisection on the monotone length equation.
///
/// References: Irvine H.M. (1981) Cable Structures, MIT Press, §1.
#pragma once
#include <cmath>

#include "../../core/error.hpp"

namespace parafsi::structure::reference {

struct catenary {
  double span, length, a;
  catenary(double S, double L) : span(S), length(L), a(0) {
    require(S > 0 && L > S, "reference::catenary: need length > span > 0, got span ", S, ", length ", L);
    double lo = 1e-6 * S, hi = 1e6 * S;  // length(a) decreases from ∞ to S as a grows
    for (int i = 0; i < 300; ++i) {
      const double mid = std::sqrt(lo * hi);
      (2 * mid * std::sinh(S / (2 * mid)) > L ? lo : hi) = mid;
    }
    a = std::sqrt(lo * hi);
  }
  /// Height below the supports (negative) at horizontal position x from mid-span.
  double z(double x) const { return a * std::cosh(x / a) - a * std::cosh(span / (2 * a)); }
  /// Sag at mid-span (positive).
  double sag() const { return -z(0.0); }
};

}  // namespace parafsi::structure::reference
