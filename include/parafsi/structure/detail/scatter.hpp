/// \file scatter.hpp
/// Race-free force assembly shared by all element parts.
///
/// Element kernels never write to nodes. Each element writes the force on each of its
/// K corners into a corner buffer (SoA, slot = corner·n_pad + element), so any number of
/// threads may run the element loop. A node-ordered pass then adds, for every node, the
/// corner slots that touch it, in a fixed order (CSR built at set-up). Every sum is
/// therefore performed in the same order whatever the thread count or SIMD width:
/// results are bit-identical for 1, 2, ... threads. Work is split into fixed chunks of
/// `chunk` items; per-chunk partial sums are combined in chunk order.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "../../core/parallel.hpp"
#include "../../core/simd.hpp"
#include "../nodes.hpp"

namespace parafsi::structure::impl {

inline constexpr index_t chunk = 1024;  ///< items per work chunk (multiple of every pack width)
/// Fewer chunks than this run serially: a structure substep's loops are short (a chunk of
/// 1024 triangles is tens of µs), and waking a thread costs as much (measured on the
/// default drop, 1488 triangles: two threads made the structure phase 2× slower).
inline constexpr index_t min_parallel_chunks = 4;

inline index_t chunk_count(index_t n) { return (n + chunk - 1) / chunk; }

/// f(begin, end, chunk_id) over fixed chunks of [0, n), statically split over threads.
template <class F>
inline void for_each_chunk(index_t n, F&& f) {
  const index_t nc = chunk_count(n);
  if (nc < min_parallel_chunks) {  // few chunks: no parallel region (its fork/join would dominate)
    for (index_t c = 0; c < nc; ++c) f(c * chunk, std::min(n, (c + 1) * chunk), c);
    return;
  }
  parallel::for_range(0, nc, [&](index_t c) { f(c * chunk, std::min(n, (c + 1) * chunk), c); });
}

/// Three components of per-corner forces, K corners per element.
struct corner_buffer {
  simd::aligned_vector<double> x, y, z;
  void resize(std::size_t n) {
    x.assign(n, 0.0);
    y.assign(n, 0.0);
    z.assign(n, 0.0);
  }
  bool finite_at(std::size_t s) const { return std::isfinite(x[s]) && std::isfinite(y[s]) && std::isfinite(z[s]); }
};

/// Node → corner-slot adjacency (CSR) and the gather that adds corner forces to nodes.
class corner_scatter {
 public:
  /// conn[c][e]: node of corner c of element e; n_pad: padded element count.
  template <std::size_t K>
  void build(const std::array<std::vector<index_t>, K>& conn, index_t n_elem, index_t n_pad, index_t n_nodes) {
    std::vector<index_t> count(std::size_t(n_nodes) + 1, 0);
    for (std::size_t c = 0; c < K; ++c)
      for (index_t e = 0; e < n_elem; ++e) ++count[std::size_t(conn[c][std::size_t(e)]) + 1];
    for (index_t i = 0; i < n_nodes; ++i) count[std::size_t(i) + 1] += count[std::size_t(i)];
    slots_.assign(std::size_t(count.back()), 0);
    std::vector<index_t> pos(count.begin(), count.end() - 1);
    // Slots ordered by node, then element, then corner: a fixed summation order.
    for (index_t e = 0; e < n_elem; ++e)
      for (std::size_t c = 0; c < K; ++c) {
        const index_t node = conn[c][std::size_t(e)];
        slots_[std::size_t(pos[std::size_t(node)]++)] = index_t(c) * n_pad + e;
      }
    // Keep only touched nodes.
    rows_.clear();
    offsets_.clear();
    for (index_t i = 0; i < n_nodes; ++i)
      if (count[std::size_t(i) + 1] > count[std::size_t(i)]) {
        rows_.push_back(i);
        offsets_.push_back(count[std::size_t(i)]);
      }
    offsets_.push_back(count.back());
  }

  /// f[node] += Σ buffer[slot] over the corners of node.
  void add(double* fx, double* fy, double* fz, const corner_buffer& b) const {
    const index_t nr = index_t(rows_.size());
    const index_t* PARAFSI_RESTRICT sl = slots_.data();
    const double* bx = b.x.data();
    const double* by = b.y.data();
    const double* bz = b.z.data();
    for_each_chunk(nr, [&](index_t begin, index_t end, index_t) {
      for (index_t r = begin; r < end; ++r) {
        double sx = 0, sy = 0, sz = 0;
        for (index_t k = offsets_[std::size_t(r)]; k < offsets_[std::size_t(r) + 1]; ++k) {
          const index_t s = sl[k];
          sx += bx[s];
          sy += by[s];
          sz += bz[s];
        }
        const index_t i = rows_[std::size_t(r)];
        fx[i] += sx;
        fy[i] += sy;
        fz[i] += sz;
      }
    });
  }
  /// Gather the total force, and when Track also the damping and external parts.
  template <bool Track>
  void scatter(nodes& n, const corner_buffer& total, const corner_buffer& damping,
               const corner_buffer& external) const {
    auto& s = n.data();
    add(s.get<field::fx>(), s.get<field::fy>(), s.get<field::fz>(), total);
    if constexpr (Track) {
      add(s.get<field::fdx>(), s.get<field::fdy>(), s.get<field::fdz>(), damping);
      add(s.get<field::fex>(), s.get<field::fey>(), s.get<field::fez>(), external);
    }
  }

 private:
  std::vector<index_t> slots_, rows_, offsets_;
};

/// Deterministic sum of per-chunk partials.
inline double ordered_sum(const std::vector<double>& part) {
  double s = 0;
  for (double p : part) s += p;
  return s;
}

}  // namespace parafsi::structure::impl
