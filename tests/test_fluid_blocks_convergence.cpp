// The block-structured fluid mesh, convergence through coarse-fine interfaces (slow:
// about half a minute in the release build).
#include <doctest/doctest.h>

#include "fluid_test_util.hpp"

using namespace parafsi;
namespace fb = parafsi::fluid::blocks;

TEST_CASE("the isentropic vortex keeps second-order convergence through coarse-fine interfaces") {
  // The vortex moves from x = 3.5 to 6.5 through a band x in [3.75, 6.25] of blocks one
  // level finer: it enters and leaves the band. L1(rho) error against the exact solution
  // on two meshes (root blocks of 4^3 cells: 32 and 64 coarse cells across).
  fluid::reference::isentropic_vortex v{};
  v.cx = 3.5;
  v.cy = 5.0;
  v.u_inf = 1.0;
  v.v_inf = 0.0;
  v.period = 10.0;
  const double t_end = 3.0;
  double err[2];
  for (int g = 0; g < 2; ++g) {
    const index_t nb = index_t(8) << g;
    fluid::block_layout lay{{0, 0, 0}, {10, 10, 10.0 / double(nb)}, {nb, nb, 1}, 4};
    fb::tree t({nb, nb, 1}, {true, true, true});
    t.refine_where(1, [&](const fb::location& q) {
      const double w = lay.block_width(0, q.level), a = w * double(q.l[0]);
      return q.level == 0 && a >= 3.75 - 1e-12 && a + w <= 6.25 + 1e-12;
    });
    fluid::block_solver s{t, lay, boundary::set::all(boundary::periodic{}), recon::muscl<limiter::mc>{}};
    s.initialize_averaged([&](const Eigen::Vector3d& x) { return v(x[0], x[1]); }, 3);
    pft::run_to(s, t_end, 0.5);
    fluid::reference::isentropic_vortex ve = v;
    ve.cx = v.cx + v.u_inf * t_end;
    double e = 0, vol = 0;
    s.for_each_cell([&](const auto& b, index_t i, index_t j, index_t k) {
      const auto q = fluid::detail::load_cons(fluid::detail::conserved_ptrs(b.U), b.grid.index(i, j, k));
      double exact = 0;  // cell average by 3x3 midpoint quadrature (2-D flow)
      for (int bb = 0; bb < 3; ++bb)
        for (int a = 0; a < 3; ++a)
          exact += ve(b.grid.face(0, i) + b.grid.width(0, i) * (a + 0.5) / 3,
                      b.grid.face(1, j) + b.grid.width(1, j) * (bb + 0.5) / 3)
                       .rho /
                   9.0;
      const double cv = b.grid.cell_volume(i, j, k);
      e += std::fabs(q.rho - exact) * cv;
      vol += cv;
    });
    err[g] = e / vol;
    const index_t across = 4 * nb;
    MESSAGE(across, " coarse cells across (", s.block_count(), " blocks): L1(rho) = ", err[g]);
  }
  const double order = std::log2(err[0] / err[1]);
  MESSAGE("observed order ", order);
  CHECK(order > 1.8);
}
