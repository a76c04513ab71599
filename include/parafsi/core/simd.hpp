/// \file simd.hpp
/// Thin layer over xsimd (Debian's xsimd 8.1 API): the pack type, loads and
/// stores, the few math functions pointwise physics needs, an aligned allocator
/// and the vector-body + scalar-tail loop helper.
///
/// Pointwise physics is written once on a value type `V` that is either `double`
/// or `pack<double>`; the helpers below are overloaded for both, so the same code
/// instantiates for scalars (tails, tests, reference) and for SIMD lanes.
/// No intrinsics appear anywhere else in parafsi.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <new>
#include <type_traits>
#include <vector>

#include <xsimd/xsimd.hpp>

#include "config.hpp"

namespace parafsi::simd {

/// The SIMD pack of T for the architecture selected by the compiler flags.
template <class T>
using pack = xsimd::batch<T>;

/// Lanes in a pack of doubles (1 when compiled without SIMD flags would still be >= 2 for SSE2).
inline constexpr std::size_t width = pack<double>::size;

template <class V>
struct is_pack : std::false_type {};
template <class T, class A>
struct is_pack<xsimd::batch<T, A>> : std::true_type {};
template <class V>
inline constexpr bool is_pack_v = is_pack<V>::value;

/// Mask type of V: bool for scalars, batch_bool for packs.
template <class V>
using mask_t = decltype(std::declval<V>() < std::declval<V>());

// ---------------------------------------------------------------- load/store
template <class V>
PARAFSI_INLINE V load(const double* p) noexcept {
  if constexpr (is_pack_v<V>) return V::load_unaligned(p);
  else return *p;
}
template <class V>
PARAFSI_INLINE V load_aligned(const double* p) noexcept {
  if constexpr (is_pack_v<V>) return V::load_aligned(p);
  else return *p;
}
PARAFSI_INLINE void store(double* p, double v) noexcept { *p = v; }
template <class A>
PARAFSI_INLINE void store(double* p, const xsimd::batch<double, A>& v) noexcept {
  v.store_unaligned(p);
}
/// A pack filled with one value (or the value itself for scalars).
template <class V>
PARAFSI_INLINE V broadcast(double x) noexcept {
  return V(x);
}
/// Lane-index pack {0, 1, 2, ...} (0 for scalars).
template <class V>
PARAFSI_INLINE V iota() noexcept {
  if constexpr (is_pack_v<V>) {
    alignas(64) double a[V::size];
    for (std::size_t i = 0; i < V::size; ++i) a[i] = double(i);
    return V::load_aligned(a);
  } else {
    return 0.0;
  }
}

// ---------------------------------------------------------------- math on V
PARAFSI_INLINE double select(bool c, double a, double b) noexcept { return c ? a : b; }
template <class A>
PARAFSI_INLINE xsimd::batch<double, A> select(const xsimd::batch_bool<double, A>& c, const xsimd::batch<double, A>& a,
                                              const xsimd::batch<double, A>& b) noexcept {
  return xsimd::select(c, a, b);
}
PARAFSI_INLINE double min(double a, double b) noexcept { return a < b ? a : b; }
PARAFSI_INLINE double max(double a, double b) noexcept { return a > b ? a : b; }
PARAFSI_INLINE double abs(double a) noexcept { return std::fabs(a); }
PARAFSI_INLINE double sqrt(double a) noexcept { return std::sqrt(a); }
PARAFSI_INLINE double sin(double a) noexcept { return std::sin(a); }
PARAFSI_INLINE double pow(double a, double b) noexcept { return std::pow(a, b); }
PARAFSI_INLINE double copysign(double a, double b) noexcept { return std::copysign(a, b); }
/// a b + c rounded once.
PARAFSI_INLINE double fma(double a, double b, double c) noexcept { return std::fma(a, b, c); }
template <class A>
PARAFSI_INLINE auto min(const xsimd::batch<double, A>& a, const xsimd::batch<double, A>& b) noexcept {
  return xsimd::min(a, b);
}
template <class A>
PARAFSI_INLINE auto max(const xsimd::batch<double, A>& a, const xsimd::batch<double, A>& b) noexcept {
  return xsimd::max(a, b);
}
template <class A>
PARAFSI_INLINE auto abs(const xsimd::batch<double, A>& a) noexcept {
  return xsimd::abs(a);
}
template <class A>
PARAFSI_INLINE auto sqrt(const xsimd::batch<double, A>& a) noexcept {
  return xsimd::sqrt(a);
}
template <class A>
PARAFSI_INLINE auto sin(const xsimd::batch<double, A>& a) noexcept {
  return xsimd::sin(a);
}
template <class A>
PARAFSI_INLINE auto pow(const xsimd::batch<double, A>& a, const xsimd::batch<double, A>& b) noexcept {
  return xsimd::pow(a, b);
}
template <class A>
PARAFSI_INLINE auto copysign(const xsimd::batch<double, A>& a, const xsimd::batch<double, A>& b) noexcept {
  return xsimd::copysign(a, b);
}
template <class A>
PARAFSI_INLINE auto fma(const xsimd::batch<double, A>& a, const xsimd::batch<double, A>& b,
                        const xsimd::batch<double, A>& c) noexcept {
  return xsimd::fma(a, b, c);
}

/// True if any / all lanes of a mask are set.
PARAFSI_INLINE bool any(bool m) noexcept { return m; }
PARAFSI_INLINE bool all(bool m) noexcept { return m; }
template <class A>
PARAFSI_INLINE bool any(const xsimd::batch_bool<double, A>& m) noexcept {
  return xsimd::any(m);
}
template <class A>
PARAFSI_INLINE bool all(const xsimd::batch_bool<double, A>& m) noexcept {
  return xsimd::all(m);
}

/// Horizontal sum (xsimd 8.1 names it `hadd`).
PARAFSI_INLINE double hsum(double a) noexcept { return a; }
template <class A>
PARAFSI_INLINE double hsum(const xsimd::batch<double, A>& a) noexcept {
  return xsimd::hadd(a);
}
/// Horizontal max.
PARAFSI_INLINE double hmax(double a) noexcept { return a; }
template <class A>
PARAFSI_INLINE double hmax(const xsimd::batch<double, A>& a) noexcept {
  alignas(64) double t[xsimd::batch<double, A>::size];
  a.store_aligned(t);
  double m = t[0];
  for (std::size_t i = 1; i < xsimd::batch<double, A>::size; ++i) m = t[i] > m ? t[i] : m;
  return m;
}
/// True when every lane is finite.
PARAFSI_INLINE bool all_finite(double a) noexcept { return std::isfinite(a); }
template <class A>
PARAFSI_INLINE bool all_finite(const xsimd::batch<double, A>& a) noexcept {
  return xsimd::all(xsimd::isfinite(a));
}

// ---------------------------------------------------------------- storage
/// Allocator returning 64-byte aligned memory (cache line, AVX-512 pack).
template <class T, std::size_t Align = 64>
struct aligned_allocator {
  using value_type = T;
  template <class U>
  struct rebind {
    using other = aligned_allocator<U, Align>;
  };
  aligned_allocator() noexcept = default;
  template <class U>
  aligned_allocator(const aligned_allocator<U, Align>&) noexcept {}
  T* allocate(std::size_t n) {
    std::size_t bytes = ((n * sizeof(T) + Align - 1) / Align) * Align;
    void* p = std::aligned_alloc(Align, bytes == 0 ? Align : bytes);
    if (!p) throw std::bad_alloc();
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t) noexcept { std::free(p); }
  template <class U>
  bool operator==(const aligned_allocator<U, Align>&) const noexcept {
    return true;
  }
};
template <class T>
using aligned_vector = std::vector<T, aligned_allocator<T>>;

/// Round n up to a whole number of packs.
constexpr std::size_t padded(std::size_t n) noexcept { return (n + width - 1) / width * width; }

/// Loop over [begin, end): full packs first (f(std::type_identity<pack<double>>{}, i)),
/// then the scalar tail (f(std::type_identity<double>{}, i)). The body is one generic
/// lambda, so the same pointwise physics serves both.
template <class F>
PARAFSI_INLINE void for_each_pack(index_t begin, index_t end, F&& f) {
  constexpr index_t W = static_cast<index_t>(width);
  index_t i = begin;
  for (; i + W <= end; i += W) f(std::type_identity<pack<double>>{}, i);
  for (; i < end; ++i) f(std::type_identity<double>{}, i);
}
/// Same loop, scalar only (the reference instantiation used by tests and by
/// policies that are not vectorizable).
template <class F>
PARAFSI_INLINE void for_each_scalar(index_t begin, index_t end, F&& f) {
  for (index_t i = begin; i < end; ++i) f(std::type_identity<double>{}, i);
}

}  // namespace parafsi::simd
