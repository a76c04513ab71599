// Relative comparisons for the tests.
//
// doctest::Approx(x).epsilon(e) passes when |a − x| < e (1 + max(|a|, |x|)): its scale of 1
// makes the tolerance absolute (e) on numbers far below 1, so a check of 0.078 "to 2 %"
// passes anything within 28 %, and one of 5e-15 "to 1e-9" anything below 1e-9 in size.
// rel(x, e) drops the scale: |a − x| < e max(|a|, |x|), relative at every size. (It keeps a
// floor of the least normal double, e · scale = DBL_MIN, so that a == x == 0 passes, also
// where subnormals flush to zero.) For x = 0 it passes a == 0 only; bound |a| directly where
// a round-off zero is expected.
#pragma once
#include <doctest/doctest.h>

#include <limits>

namespace pft {

/// a == rel(x, e): a within the relative tolerance e of x, whatever their size.
inline doctest::Approx rel(double x, double e) {
  const double floor = std::numeric_limits<double>::min();
  return doctest::Approx(x).epsilon(e).scale(e > 0 ? floor / e : floor);
}

}  // namespace pft
