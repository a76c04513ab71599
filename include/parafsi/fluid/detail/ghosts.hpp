/// \file ghosts.hpp
/// Ghost cells of every box face from its boundary condition (boundary/*.hpp): x faces
/// over interior (j, k); y faces over all i (ghosts included) and interior k; z faces
/// over all (i, j), so edges and corners get filled. Periodic faces copy the opposite
/// interior layers; the others get cond.ghost(W_mirror, W_adjacent, n_out, w_n, gas, t)
/// with w_n the grid's outward normal speed at the boundary face centre (once per face for a
/// condition that reads only the adjacent cell: the same state in each ghost layer).
/// On a block mesh a block fills only its faces on the box boundary (`fill`), and only
/// their face slabs (`edges` false: interior transverse ranges; the blocks' exchange,
/// blocks/exchange.hpp, leaves edge and corner ghosts too, as only the viscous pass reads
/// them, and with it the block solver passes `edges` true and `edge_depth` 1: the edge
/// ghosts one cell deep on both axes, which is all the viscous pass's fluxes read).
#pragma once
#include <array>
#include <type_traits>
#include <utility>
#include <variant>

#include "../boundary/condition.hpp"
#include "../gas.hpp"
#include "../grid.hpp"
#include "stage.hpp"

namespace parafsi::fluid::detail {

inline constexpr std::array<bool, 6> all_faces{true, true, true, true, true, true};

/// A boundary condition whose ghost state does not read the mirror cell (far field, inflow,
/// outflow: `static constexpr bool layer_invariant = true`), so every ghost layer of a face
/// gets the same state.
template <class C>
inline constexpr bool layer_invariant = requires {
  requires C::layer_invariant;
};

inline void fill_ghosts(const rectilinear_grid& grid, const boundary::set& bcs, const gas::ideal& gas,
                        const stage_geometry& geo, double t, const fields5<double>& U, bool threaded,
                        const std::array<bool, 6>& fill = all_faces, bool edges = true,
                        index_t edge_depth = rectilinear_grid::ghosts) {
  constexpr index_t ng = rectilinear_grid::ghosts;
  const index_t n[3] = {grid.n(0), grid.n(1), grid.n(2)};
  for (int d = 0; d < 3; ++d) {
    const int a = (d + 1) % 3, b = (d + 2) % 3;
    // Ranges of the two transverse axes: include the ghosts already filled (axes done
    // before this one, and faces filled from neighbouring blocks).
    auto range = [&](int axis) -> std::pair<index_t, index_t> {
      const bool lo = edges && (axis < d || !fill[std::size_t(2 * axis)]),
                 hi = edges && (axis < d || !fill[std::size_t(2 * axis + 1)]);
      return {lo ? -edge_depth : 0, hi ? n[axis] + edge_depth : n[axis]};
    };
    const auto ra = range(a), rb = range(b);
    for (int hi = 0; hi < 2; ++hi) {
      if (!fill[std::size_t(2 * d + hi)]) continue;
      const auto& bc = bcs.face[std::size_t(2 * d + hi)];
      const vec3<double> nout = geo.n[std::size_t(d)] * (hi ? 1.0 : -1.0);
      std::visit(
          [&](const auto& cond) {
        using C = std::decay_t<decltype(cond)>;
        // The boundary (adjacent) interior cell at transverse (pidx, q), written to ijk: its
        // primitives and the grid's outward normal speed at its boundary face centre.
        [[maybe_unused]] auto adjacent = [&](index_t pidx, index_t q, index_t(&ijk)[3]) {
          ijk[a] = pidx;
          ijk[b] = q;
          ijk[d] = hi ? n[d] - 1 : 0;
          const auto wa = to_prim(load_cons(U, grid.index(ijk[0], ijk[1], ijk[2])), gas);
          Eigen::Vector3d xi{grid.centre(0, ijk[0]), grid.centre(1, ijk[1]), grid.centre(2, ijk[2])};
          xi[d] = hi ? grid.face(d, n[d]) : grid.face(d, 0);
          const double wn = (hi ? 1.0 : -1.0) * (geo.vh[d] + geo.oh.cross(xi)[d]);
          return std::pair{wa, wn};
        };
        par_for(threaded, rb.first, rb.second, [&](index_t q) {
          for (index_t pidx = ra.first; pidx < ra.second; ++pidx) {
            // A condition whose ghost depends on the adjacent cell only (no mirror): computed
            // once for the face and stored in every ghost layer.
            if constexpr (layer_invariant<C>) {
              index_t ijk[3];
              const auto [wa, wn] = adjacent(pidx, q, ijk);
              const auto qg = to_cons(cond.ghost(wa, wa, nout, wn, gas, t), gas);
              for (index_t g = 1; g <= ng; ++g) {
                ijk[d] = hi ? n[d] - 1 + g : -g;
                store_cons(U, grid.index(ijk[0], ijk[1], ijk[2]), qg);
              }
            } else {
              for (index_t g = 1; g <= ng; ++g) {
                index_t ijk_g[3], ijk_m[3];
                ijk_g[a] = ijk_m[a] = pidx;
                ijk_g[b] = ijk_m[b] = q;
                ijk_g[d] = hi ? n[d] - 1 + g : -g;
                if constexpr (std::is_same_v<C, boundary::periodic>) {
                  ijk_m[d] = hi ? g - 1 : n[d] - g;
                  const index_t cg = grid.index(ijk_g[0], ijk_g[1], ijk_g[2]);
                  const index_t cm = grid.index(ijk_m[0], ijk_m[1], ijk_m[2]);
                  store_cons(U, cg, load_cons(U, cm));
                } else {
                  ijk_m[d] = hi ? n[d] - g : g - 1;  // mirror image of the ghost
                  const index_t cg = grid.index(ijk_g[0], ijk_g[1], ijk_g[2]);
                  const auto wm = to_prim(load_cons(U, grid.index(ijk_m[0], ijk_m[1], ijk_m[2])), gas);
                  index_t ijk_a[3];
                  const auto [wa, wn] = adjacent(pidx, q, ijk_a);
                  store_cons(U, cg, to_cons(cond.ghost(wm, wa, nout, wn, gas, t), gas));
                }
              }
            }
          }
        });
          },
          bc);
    }
  }
}

}  // namespace parafsi::fluid::detail
