/// \file parallel.hpp
/// OpenMP helpers, optional at build time. Work is split in fixed static chunks
/// and every reduction is done in a fixed order, so results are identical bit for
/// bit for any thread count.
#pragma once
#include <vector>

#include "config.hpp"
#if defined(_OPENMP)
#include <omp.h>
#endif

namespace parafsi::parallel {

/// Threads the next parallel region will use (1 without OpenMP).
inline int max_threads() noexcept {
#if defined(_OPENMP)
  return omp_get_max_threads();
#else
  return 1;
#endif
}

/// Set the thread count (ignored without OpenMP).
inline void set_threads([[maybe_unused]] int n) noexcept {
#if defined(_OPENMP)
  if (n > 0) omp_set_num_threads(n);
#endif
}

/// Index of the calling thread in the current parallel region (0 outside one).
inline int thread_id() noexcept {
#if defined(_OPENMP)
  return omp_get_thread_num();
#else
  return 0;
#endif
}

/// True when compiled with OpenMP.
inline constexpr bool enabled() noexcept {
#if defined(_OPENMP)
  return true;
#else
  return false;
#endif
}

/// for i in [begin, end): f(i), iterations split statically over threads.
/// Use only when iterations write disjoint data. `threaded = false` runs serially
/// without entering a parallel region (small problems, and kernels called per block from
/// a block-parallel loop: an inactive region still costs a runtime call).
template <class F>
inline void for_range(index_t begin, index_t end, F&& f, bool threaded = true) {
#if defined(_OPENMP)
  if (!threaded) {
    for (index_t i = begin; i < end; ++i) f(i);
    return;
  }
#pragma omp parallel for schedule(static)
  for (index_t i = begin; i < end; ++i) f(i);
#else
  (void)threaded;
  for (index_t i = begin; i < end; ++i) f(i);
#endif
}

/// Deterministic reduction: each index contributes f(i) to a per-index slot of
/// `slots` (resized to end − begin; no allocation once large enough) and the slots are
/// combined in index order, so the result does not depend on threads.
template <class T, class F, class Op>
inline T reduce(index_t begin, index_t end, T init, F&& f, Op&& op, bool threaded, std::vector<T>& slots) {
  const std::size_t n = static_cast<std::size_t>(end > begin ? end - begin : 0);
  slots.resize(n);
  for_range(
      begin, end, [&](index_t i) { slots[static_cast<std::size_t>(i - begin)] = f(i); }, threaded);
  T acc = init;
  for (std::size_t i = 0; i < n; ++i) acc = op(acc, slots[i]);
  return acc;
}
/// As above with slots of its own (allocates).
template <class T, class F, class Op>
inline T reduce(index_t begin, index_t end, T init, F&& f, Op&& op, bool threaded = true) {
  std::vector<T> slots;
  return reduce(begin, end, init, std::forward<F>(f), std::forward<Op>(op), threaded, slots);
}

}  // namespace parafsi::parallel
