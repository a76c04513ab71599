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
#include <span>

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

template <class L>
struct soa_of;
template <class... Tags>
struct soa_of<meta::list<Tags...>> {
  using type = soa<Tags...>;
};
/// soa container holding exactly the fields of a type list.
template <class L>
using soa_of_t = typename soa_of<L>::type;

}  // namespace parafsi
