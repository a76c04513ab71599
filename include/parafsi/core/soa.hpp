/// \file soa.hpp
/// Structure-of-arrays storage with fields named by tag types.
///
/// A field tag is an empty struct with a `static constexpr const char* name`.
/// `soa<Tags...>` holds one 64-byte aligned, pack-padded array of doubles per tag;
/// `get<Tag>()` returns its pointer. Asking for a tag the container does not hold is
/// a compile error with a sentence, so a kernel cannot silently read a field a scene
/// left out. `soa_of_t<meta::list<...>>` builds the container from a (union) list.
#pragma once
#include <array>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <span>
#include <utility>

#include "config.hpp"
#include "meta.hpp"
#include "simd.hpp"

namespace parafsi {

template <class... Tags>
class soa {
 public:
  using fields = meta::list<Tags...>;
  static constexpr std::size_t field_count = sizeof...(Tags);

  soa() = default;
  explicit soa(index_t n, double fill = 0.0) { resize(n, fill); }

  /// Resize every field to n entries (storage padded to whole packs; the padding is
  /// filled too so that full-pack loads past the end read finite numbers).
  void resize(index_t n, double fill = 0.0) {
    n_ = n;
    for (auto& a : data_) a.assign(simd::padded(static_cast<std::size_t>(n)) + simd::width, fill);
  }
  index_t size() const noexcept { return n_; }

  template <class Tag>
  static constexpr bool has() noexcept {
    return meta::contains_v<Tag, fields>;
  }

  template <class Tag>
  double* get() noexcept {
    static_assert(has<Tag>(),
                  "this SoA container does not hold the requested field: "
                  "add its tag to the policy's `fields` list");
    return data_[meta::index_of_v<Tag, fields>].data();
  }
  template <class Tag>
  const double* get() const noexcept {
    static_assert(has<Tag>(),
                  "this SoA container does not hold the requested field: "
                  "add its tag to the policy's `fields` list");
    return data_[meta::index_of_v<Tag, fields>].data();
  }
  template <class Tag>
  std::span<double> span() noexcept {
    return {get<Tag>(), static_cast<std::size_t>(n_)};
  }
  template <class Tag>
  std::span<const double> span() const noexcept {
    return {get<Tag>(), static_cast<std::size_t>(n_)};
  }
  /// Field by position (for generic loops over all fields, e.g. checkpointing).
  double* data(std::size_t f) noexcept { return data_[f].data(); }
  const double* data(std::size_t f) const noexcept { return data_[f].data(); }

 private:
  index_t n_ = 0;
  std::array<simd::aligned_vector<double>, sizeof...(Tags)> data_{};
};

/// One array of `n` doubles, zero on allocation, 64-byte aligned, whose memory the
/// operating system backs only where it is first written: it comes from std::calloc, which
/// for a large block maps fresh zero pages instead of clearing memory (glibc and the other
/// common C libraries; elsewhere it is an ordinary zeroed array, the same values). A mesh-
/// wide field of which a process writes only its own blocks then costs the memory of those
/// blocks (block_solver over MPI processes).
class zeroed_array {
 public:
  zeroed_array() = default;
  explicit zeroed_array(std::size_t n) : n_(n) {
    raw_ = std::calloc(n * sizeof(double) + align, 1);
    if (raw_ == nullptr) throw std::bad_alloc();
    const auto a = reinterpret_cast<std::uintptr_t>(raw_);
    data_ = reinterpret_cast<double*>((a + align - 1) / align * align);
  }
  zeroed_array(zeroed_array&& o) noexcept
      : raw_(std::exchange(o.raw_, nullptr)), data_(std::exchange(o.data_, nullptr)), n_(std::exchange(o.n_, 0)) {}
  zeroed_array& operator=(zeroed_array&& o) noexcept {
    if (this != &o) {
      std::free(raw_);
      raw_ = std::exchange(o.raw_, nullptr);
      data_ = std::exchange(o.data_, nullptr);
      n_ = std::exchange(o.n_, 0);
    }
    return *this;
  }
  zeroed_array(const zeroed_array&) = delete;
  zeroed_array& operator=(const zeroed_array&) = delete;
  ~zeroed_array() { std::free(raw_); }
  double* data() noexcept { return data_; }
  const double* data() const noexcept { return data_; }
  std::size_t size() const noexcept { return n_; }

 private:
  static constexpr std::size_t align = 64;
  void* raw_ = nullptr;
  double* data_ = nullptr;
  std::size_t n_ = 0;
};

/// As soa (same get<Tag>(), data(f), size()), every field a zeroed_array: all zero when
/// made, memory only where written. For mesh-wide fields that a process fills in part.
template <class... Tags>
class paged_soa {
 public:
  using fields = meta::list<Tags...>;
  static constexpr std::size_t field_count = sizeof...(Tags);

  paged_soa() = default;
  explicit paged_soa(index_t n) : n_(n) {
    for (auto& a : data_) a = zeroed_array(simd::padded(static_cast<std::size_t>(n)) + simd::width);
  }
  index_t size() const noexcept { return n_; }

  template <class Tag>
  static constexpr bool has() noexcept {
    return meta::contains_v<Tag, fields>;
  }
  template <class Tag>
  double* get() noexcept {
    static_assert(has<Tag>(), "this SoA container does not hold the requested field");
    return data_[meta::index_of_v<Tag, fields>].data();
  }
  template <class Tag>
  const double* get() const noexcept {
    static_assert(has<Tag>(), "this SoA container does not hold the requested field");
    return data_[meta::index_of_v<Tag, fields>].data();
  }
  double* data(std::size_t f) noexcept { return data_[f].data(); }
  const double* data(std::size_t f) const noexcept { return data_[f].data(); }

 private:
  index_t n_ = 0;
  std::array<zeroed_array, sizeof...(Tags)> data_{};
};

/// C<Tags...> for the tags of a type list (C: soa or paged_soa).
template <template <class...> class C, class L>
struct with_fields;
template <template <class...> class C, class... Tags>
struct with_fields<C, meta::list<Tags...>> {
  using type = C<Tags...>;
};
/// soa container holding exactly the fields of a type list.
template <class L>
using soa_of_t = typename with_fields<soa, L>::type;
/// paged_soa container holding exactly the fields of a type list.
template <class L>
using paged_soa_of_t = typename with_fields<paged_soa, L>::type;

}  // namespace parafsi
