/// \file config.hpp
/// Version macros and small compiler helpers. No physics here.
#pragma once

#define PARAFSI_VERSION_MAJOR 0
#define PARAFSI_VERSION_MINOR 1
#define PARAFSI_VERSION_PATCH 0

#if defined(__GNUC__) || defined(__clang__)
#define PARAFSI_INLINE inline __attribute__((always_inline))
#define PARAFSI_RESTRICT __restrict__
#else
#define PARAFSI_INLINE inline
#define PARAFSI_RESTRICT
#endif

namespace parafsi {
using real = double;   ///< floating-point type of every state (SI units)
using index_t = long;  ///< signed index type for cells, nodes and elements
}  // namespace parafsi
