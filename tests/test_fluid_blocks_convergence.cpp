// The block-structured fluid mesh, convergence through coarse-fine interfaces (slow:
// about half a minute in the release build).
#include <doctest/doctest.h>

#include <array>
#include <string>

#include "fluid_test_util.hpp"

using namespace parafsi;
namespace fb = parafsi::fluid::blocks;

namespace {
/// The vortex moves from x = 3.5 to 6.5 through a band x in [3.75, 6.25] of blocks one
/// level finer: it enters and leaves the band. L1(rho) error against the exact solution
/// on two meshes (root blocks of 4^3 cells: 32 and 64 coarse cells across), with one time
/// step for both levels or with level subcycling.
std::array<double, 2> vortex_through_band(bool subcycled) {
  fluid::reference::isentropic_vortex v{};
  v.cx = 3.5;
  v.cy = 5.0;
  v.u_inf = 1.0;
  v.v_inf = 0.0;
  v.period = 10.0;
  const double t_end = 3.0;
  std::array<double, 2> err{};
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
    if (subcycled)
      while (s.time() < t_end - 1e-14) s.step_subcycled(std::min(s.stable_dt_subcycled(0.5), t_end - s.time()));
    else pft::run_to(s, t_end, 0.5);
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
    err[std::size_t(g)] = e / vol;
    const index_t across = 4 * nb;
    MESSAGE(across, " coarse cells across (", s.block_count(), " blocks", std::string(subcycled ? ", subcycled" : ""),
            "): L1(rho) = ", err[std::size_t(g)]);
  }
  return err;
}
}  // namespace

TEST_CASE(
    "the isentropic vortex keeps second-order convergence through coarse-fine interfaces, with one step for both "
    "levels and with level subcycling") {
  const auto one = vortex_through_band(false);
  const double order = std::log2(one[0] / one[1]);
  MESSAGE("one step for both levels: observed order ", order);
  CHECK(order > 1.8);
  // Subcycled, the coarse level steps twice as long as the fine one: its time error is
  // larger, and the fine level's ghosts come from the coarse state interpolated in time.
  const auto sub = vortex_through_band(true);
  const double order_sub = std::log2(sub[0] / sub[1]);
  MESSAGE("subcycled: observed order ", order_sub, "; error against one step for both levels: ", sub[0] / one[0], ", ",
          sub[1] / one[1]);
  CHECK(order_sub > 1.8);
  CHECK(sub[1] < 1.5 * one[1]);
}
