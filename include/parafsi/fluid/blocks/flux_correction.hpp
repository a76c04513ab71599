/// \file flux_correction.hpp
/// Conservation at coarse–fine faces. With one time step for all levels, the flux through
/// a coarse face that borders four fine faces is replaced, in every stage, by their area
/// mean:
///   dU_c += σ (F̂_c − ¼ Σ_{k=1..4} F̂_f,k) / Δx_c,    σ = +1 (fine block on the coarse
///   cell's high side), −1 (low side),
/// so the coarse cell loses exactly what the fine cells gain and mass, momentum and energy
/// are conserved to round-off; each stage, hence the SSP-RK combination, is conservative.
/// The sweeps leave every block's boundary-face fluxes in its face register
/// (detail/sweep.hpp, face_register); the plan below pairs them, grouped by coarse block
/// so each block's corrections run in a fixed order.
///
/// References: Berger M.J., Colella P. (1989) J. Comput. Phys. 82:64 (refluxing);
///   Stone J.M. et al. (2020) ApJS 249:4 (flux correction every stage, no subcycling).
#pragma once
#include <array>
#include <vector>

#include "exchange.hpp"
#include "tree.hpp"

namespace parafsi::fluid::blocks {

/// One coarse boundary cell's face shared with four fine faces.
struct flux_correction {
  index_t cell;                      ///< the coarse cell (local flat index)
  int axis, side;                    ///< the coarse cell's face: axis, 0 low / 1 high
  index_t coarse_face;               ///< index in the coarse block's register of that side
  index_t fine_block;                ///< the fine block
  std::array<index_t, 4> fine_face;  ///< indices in the fine block's register (other side)
};

/// Register index of a boundary face with transverse cell coordinates (t_a, t_b), a < b
/// the two axes other than the face's.
inline index_t register_index(index_t n, index_t ta, index_t tb) noexcept { return ta + n * tb; }

/// Corrections per coarse block for the leaves of `t` (n cells per block edge).
inline std::vector<std::vector<flux_correction>> build_flux_corrections(const tree& t, index_t n) {
  const block_index at{n};
  std::vector<std::vector<flux_correction>> out(std::size_t(t.size()));
  for (index_t fb = 0; fb < t.size(); ++fb) {
    const location F = t.leaf(fb);
    if (F.level == 0) continue;
    for (int D = 0; D < 3; ++D)
      for (int s = 0; s < 2; ++s) {
        location nb = F;
        nb.l[std::size_t(D)] += s ? 1 : -1;
        const cover c = t.find(nb);
        if (c.kind != cover::leaf || c.level != F.level - 1) continue;
        const location C = t.leaf(c.id);
        const int a = D == 0 ? 1 : 0, b = D == 2 ? 1 : 2;
        const int cside = 1 - s;  // the coarse cell's face towards F
        for (index_t tb = 0; tb < n; tb += 2)
          for (index_t ta = 0; ta < n; ta += 2) {
            // Coarse transverse coordinates of the fine pair (ta, tb) (no wrap across a
            // transverse axis: F and C share their transverse position).
            const index_t ca = (F.l[std::size_t(a)] * n + ta) / 2 - C.l[std::size_t(a)] * n;
            const index_t cb = (F.l[std::size_t(b)] * n + tb) / 2 - C.l[std::size_t(b)] * n;
            index_t ijk[3];
            ijk[D] = cside ? n - 1 : 0;
            ijk[a] = ca;
            ijk[b] = cb;
            flux_correction fc{};
            fc.cell = at(ijk[0], ijk[1], ijk[2]);
            fc.axis = D;
            fc.side = cside;
            fc.coarse_face = register_index(n, ca, cb);
            fc.fine_block = fb;
            fc.fine_face = {register_index(n, ta, tb), register_index(n, ta + 1, tb), register_index(n, ta, tb + 1),
                            register_index(n, ta + 1, tb + 1)};
            out[std::size_t(c.id)].push_back(fc);
          }
      }
  }
  return out;
}

}  // namespace parafsi::fluid::blocks
