/// \file corner_forces.hpp
/// The element-loop side shared by all element parts (cable, membrane_tri,
/// membrane_quad): node data gathered by index into vec3<V>, the chunked element loop
/// with its per-chunk energy partials, and the corner-force buffers (total, damping,
/// external) with their race-free gather to the nodes (scatter.hpp).
///
/// Slot of corner c of element e: c·n_pad + e (n_pad = padded element count), so a
/// SIMD pack of elements stores one contiguous pack per corner and component.
#pragma once
#include <array>
#include <cstddef>
#include <vector>

#include "../../core/simd.hpp"
#include "../../core/simd_gather.hpp"
#include "../../core/vec3.hpp"
#include "../nodes.hpp"
#include "scatter.hpp"

namespace parafsi::structure::impl {

/// Positions x_i of the nodes i = idx[0..lanes) (one per SIMD lane).
template <class V>
PARAFSI_INLINE vec3<V> gather_position(const node_kinematics& k, const index_t* idx) {
  return {simd::gather<V>(k.x, idx), simd::gather<V>(k.y, idx), simd::gather<V>(k.z, idx)};
}
/// Velocities v_i of the nodes i = idx[0..lanes).
template <class V>
PARAFSI_INLINE vec3<V> gather_velocity(const node_kinematics& k, const index_t* idx) {
  return {simd::gather<V>(k.vx, idx), simd::gather<V>(k.vy, idx), simd::gather<V>(k.vz, idx)};
}

/// body(tag, e) over the elements [0, n) in fixed chunks (packs of elements when
/// Vectorize, else one at a time; `typename decltype(tag)::type` is the value type V).
/// The body returns std::array<V, M> of energies; when Track their sums per chunk go to
/// parts[m][chunk] (combined later in chunk order by ordered_sum).
template <bool Track, bool Vectorize, std::size_t M, class Body>
inline void for_each_element(index_t n, const std::array<std::vector<double>*, M>& parts, Body&& body) {
  for_each_chunk(n, [&](index_t begin, index_t end, index_t c) {
    std::array<double, M> acc{};
    auto each = [&](auto tag, index_t e) {
      const auto w = body(tag, e);
      if constexpr (Track)
        for (std::size_t m = 0; m < M; ++m) acc[m] += simd::hsum(w[m]);
    };
    if constexpr (Vectorize) simd::for_each_pack(begin, end, each);
    else simd::for_each_scalar(begin, end, each);
    if constexpr (Track)
      for (std::size_t m = 0; m < M; ++m) (*parts[m])[std::size_t(c)] = acc[m];
  });
}

/// Corner forces of a part with K corners per element: the total, damping and external
/// buffers, the node gather, and the per-chunk strain-energy partials.
template <std::size_t K>
class corner_forces {
 public:
  corner_buffer total, damping, external;
  std::vector<double> energy_part;  ///< per-chunk strain energy of the last tracked pass

  /// Buffers and node map, once conn[c][0..n_elem) holds the node of corner c.
  template <class Conn>
  void build(const std::array<Conn, K>& conn, index_t n_elem, index_t n_pad, index_t n_nodes) {
    n_ = n_elem;
    np_ = n_pad;
    std::array<std::vector<index_t>, K> cn;
    for (std::size_t a = 0; a < K; ++a) cn[a].assign(conn[a].begin(), conn[a].begin() + n_elem);
    scatter_.build(cn, n_elem, n_pad, n_nodes);
    total.resize(std::size_t(index_t(K) * n_pad + simd::width));
    damping.resize(std::size_t(index_t(K) * n_pad + simd::width));
    external.resize(std::size_t(index_t(K) * n_pad + simd::width));
    energy_part.assign(std::size_t(chunk_count(n_elem)), 0.0);
  }

  /// Force on corner c of element e (a pack of elements e.. for a SIMD V) into b.
  template <class V>
  PARAFSI_INLINE void store(corner_buffer& b, index_t c, index_t e, const vec3<V>& f) const {
    const std::size_t s = std::size_t(c * np_ + e);
    simd::store(b.x.data() + s, f.x);
    simd::store(b.y.data() + s, f.y);
    simd::store(b.z.data() + s, f.z);
  }

  /// Add the total force to the nodes, and when Track the damping and external parts.
  template <bool Track>
  void scatter(nodes& nd) const {
    scatter_.scatter<Track>(nd, total, damping, external);
  }

  /// Strain energy of the last tracked pass (J).
  double strain_energy() const { return ordered_sum(energy_part); }

  /// First element with a non-finite corner force (-1 if none), for failure reports.
  index_t first_bad_element() const {
    for (index_t e = 0; e < n_; ++e)
      for (index_t c = 0; c < index_t(K); ++c)
        if (!total.finite_at(std::size_t(c * np_ + e))) return e;
    return -1;
  }

 private:
  corner_scatter scatter_;
  index_t n_ = 0, np_ = 0;
};

}  // namespace parafsi::structure::impl
