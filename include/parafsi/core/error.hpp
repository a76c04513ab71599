/// \file error.hpp
/// Error types with messages that name the offending value.
///
/// - `invalid_input`: a non-physical parameter or inconsistent set-up (thrown at set-up).
/// - `numerical_failure`: a run that went non-finite or unstable; it carries where
///   (cell/element index) and when (simulated time) so the user can act on it.
#pragma once
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace parafsi {

/// Base of every exception thrown by parafsi.
struct error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Bad input: a parameter outside its physical range, an inconsistent mesh, ...
struct invalid_input : error {
  using error::error;
};

/// The state became non-finite or violated a physical bound during a run.
struct numerical_failure : error {
  numerical_failure(std::string what, long where, double time) : error(std::move(what)), index(where), t(time) {}
  long index;  ///< offending cell/element/node index (-1 if not applicable)
  double t;    ///< simulated time of the failure (s)
};

namespace detail {
template <class... Args>
std::string concat(Args&&... args) {
  std::ostringstream os;
  os.precision(17);
  (os << ... << args);
  return os.str();
}
}  // namespace detail

/// Throw `invalid_input` with the concatenated message unless `cond` holds.
template <class... Args>
inline void require(bool cond, Args&&... args) {
  if (!cond) throw invalid_input(detail::concat(std::forward<Args>(args)...));
}

}  // namespace parafsi
