/// \file simd_gather.hpp
/// Indexed loads for unstructured kernels (element → node data): `gather<V>(base, idx)`
/// reads base[idx[0..W)] into a pack (or base[idx[0]] for scalars). Indices are
/// `index_t` (64-bit), matching xsimd's 64-bit index batches for doubles.
/// Kept apart from simd.hpp so that the structured (fluid) layer does not depend on it.
#pragma once
#include <cstdint>
#include <type_traits>

#include "simd.hpp"

namespace parafsi::simd {

static_assert(sizeof(index_t) == sizeof(std::int64_t), "gather assumes 64-bit indices");

/// base[idx[i]] for the W lanes starting at idx (unaligned index load).
template <class V>
PARAFSI_INLINE V gather(const double* base, const index_t* idx) noexcept {
  if constexpr (is_pack_v<V>) {
    using ipack = xsimd::batch<std::int64_t, typename V::arch_type>;
    const ipack i = ipack::load_unaligned(reinterpret_cast<const std::int64_t*>(idx));
    return V::gather(base, i);
  } else {
    return base[*idx];
  }
}

}  // namespace parafsi::simd
