// Shared set-ups for the fluid tests.
#pragma once
#include <parafsi/parafsi.hpp>

#include <algorithm>
#include <cmath>
#include <functional>

namespace pft {
namespace pf = parafsi;
using prim = pf::fluid::prim<double>;

/// Run a solver to t_end with the stable step at CFL `cfl`.
template <class S>
void run_to(S& s, double t_end, double cfl = 0.5) {
  while (s.time() < t_end - 1e-14) s.step(std::min(s.stable_dt(cfl), t_end - s.time()));
}

/// Toro's Riemann problems: left/right states, interface position and end time.
struct riemann_case {
  const char* name;
  pf::fluid::riemann_state L, R;
  double x0, t_end;
};
inline const riemann_case toro_cases[] = {
    {"sod", {1.0, 0.0, 1.0}, {0.125, 0.0, 0.1}, 0.5, 0.2},
    {"lax", {0.445, 0.698, 3.528}, {0.5, 0.0, 0.571}, 0.5, 0.14},
    {"toro2", {1.0, -2.0, 0.4}, {1.0, 2.0, 0.4}, 0.5, 0.15},
    {"toro3", {1.0, 0.0, 1000.0}, {1.0, 0.0, 0.01}, 0.5, 0.012},
};
/// Largest relative difference of the conserved state between a block mesh and a box
/// solver on the same uniform cells (scaled by |E| + |ρ| of the box cell).
template <class B, class S>
double max_block_box_difference(const B& blk, const S& box) {
  double e = 0;
  blk.for_each_cell([&](const auto& b, pf::index_t i, pf::index_t j, pf::index_t k) {
    const auto q = pf::fluid::detail::load_cons(pf::fluid::detail::conserved_ptrs(b.U), b.grid.index(i, j, k));
    const double x[3] = {b.grid.centre(0, i), b.grid.centre(1, j), b.grid.centre(2, k)};
    const auto& g = box.grid();
    pf::index_t I[3];
    for (int d = 0; d < 3; ++d) {
      const double h = (g.face(d, g.n(d)) - g.face(d, 0)) / double(g.n(d));
      I[d] = pf::index_t(std::floor((x[d] - g.face(d, 0)) / h));
    }
    const auto r = box.conserved(I[0], I[1], I[2]);
    const double scale = std::fabs(r.E) + std::fabs(r.rho);
    e = std::max({e, std::fabs(q.rho - r.rho) / scale, std::fabs(q.m.x - r.m.x) / scale,
                  std::fabs(q.m.y - r.m.y) / scale, std::fabs(q.m.z - r.m.z) / scale, std::fabs(q.E - r.E) / scale});
  });
  return e;
}

/// A block tree of root grid nb whose blocks overlapping the sphere (centre, radius) are
/// refined up to max_level (2:1 balanced).
inline parafsi::fluid::blocks::tree refined_tree(std::array<pf::index_t, 3> nb, std::array<bool, 3> periodic,
                                                 const pf::fluid::block_layout& lay, const Eigen::Vector3d& centre,
                                                 double radius, int max_level) {
  namespace fb = pf::fluid::blocks;
  fb::tree t(nb, periodic);
  t.refine_where(max_level, [&](const fb::location& q) {
    double d2 = 0;
    for (int d = 0; d < 3; ++d) {
      const double w = lay.block_width(d, q.level);
      const double a = lay.lo[std::size_t(d)] + w * double(q.l[std::size_t(d)]), b = a + w;
      const double c = std::clamp(centre[d], a, b) - centre[d];
      d2 += c * c;
    }
    return d2 < radius * radius;
  });
  return t;
}

/// Level 2 on the blocks within 1 of a vortex moving with (u_inf, v_inf) from (cx, cy) on
/// the periodic 10 × 10 layout `lay`, level 1 within 2.5, at the solver's time.
template <class S>
auto moving_vortex_target(const S& s, const pf::fluid::block_layout& lay,
                          const pf::fluid::reference::isentropic_vortex& v) {
  return [&s, &lay, v](const pf::fluid::blocks::location& q) {
    const double t = s.time();
    const Eigen::Vector3d c(std::fmod(v.cx + v.u_inf * t, 10.0), std::fmod(v.cy + v.v_inf * t, 10.0), 1.25);
    double d2 = 0;
    for (int d = 0; d < 2; ++d) {
      const double w = lay.block_width(d, q.level), a = w * double(q.l[std::size_t(d)]);
      double e = std::clamp(c[d], a, a + w) - c[d];
      e -= 10.0 * std::round(e / 10.0);
      d2 += e * e;
    }
    return d2 < 1.0 ? 2 : (d2 < 6.25 ? 1 : 0);
  };
}

}  // namespace pft
