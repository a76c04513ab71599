/// \file update.hpp
/// Stage update on interior cells (Shu–Osher form):  U ← a U⁰ + b (U + Δt dU).
/// With Check (the last stage), rows holding a non-finite or non-positive density or
/// pressure are flagged, then the first such cell stops the run with its index,
/// position, time and values.
#pragma once
#include <cmath>

#include "../../core/error.hpp"
#include "../../core/simd.hpp"
#include "../frame/pose.hpp"
#include "../gas.hpp"
#include "../grid.hpp"
#include "stage.hpp"

namespace parafsi::fluid::detail {

/// `bad`: one flag per interior row (n_y n_z), written when Check.
template <bool Check>
void update(const rectilinear_grid& grid, const gas::ideal& gas, const fields5<double>& U,
            const fields5<const double>& U0, const fields5<const double>& dU, double a, double b, double dt, char* bad,
            bool threaded) {
  const index_t nx = grid.n(0), ny = grid.n(1), nz = grid.n(2);
  const gas::ideal g = gas;
  par_for(threaded, 0, ny * nz, [&](index_t r) {
    const index_t base = grid.index(0, r % ny, r / ny);
    bool row_bad = false;
    simd::for_each_pack(0, nx, [&](auto tag, index_t i) {
      using V = typename decltype(tag)::type;
      const index_t c = base + i;
      V q[5];
      for (int f = 0; f < 5; ++f) {
        q[f] = V(a) * simd::load<V>(U0[f] + c) + V(b) * (simd::load<V>(U[f] + c) + V(dt) * simd::load<V>(dU[f] + c));
        simd::store(U[f] + c, q[f]);
      }
      if constexpr (Check) {
        const V p = g.pressure(q[0], q[1], q[2], q[3], q[4]);
        const auto ok = (q[0] > V(0.0)) && (p > V(0.0));
        row_bad = row_bad || !simd::all(ok) || !simd::all_finite(p);
      }
    });
    if constexpr (Check) bad[std::size_t(r)] = row_bad;
  });
}

/// Throw numerical_failure at the first non-physical cell of the flagged rows.
inline void check_rows(const rectilinear_grid& grid, const gas::ideal& g, const frame::pose& pose,
                       const fields5<const double>& U, const char* bad, double t_new) {
  const index_t nx = grid.n(0), ny = grid.n(1), nz = grid.n(2);
  for (index_t r = 0; r < ny * nz; ++r) {
    if (!bad[std::size_t(r)]) continue;
    const index_t j = r % ny, k = r / ny;
    for (index_t i = 0; i < nx; ++i) {
      const auto q = load_cons(U, grid.index(i, j, k));
      const double p = g.pressure(q.rho, q.m.x, q.m.y, q.m.z, q.E);
      if (!(q.rho > 0.0) || !(p > 0.0) || !std::isfinite(p)) {
        const Eigen::Vector3d x = pose.to_inertial({grid.centre(0, i), grid.centre(1, j), grid.centre(2, k)});
        throw numerical_failure(parafsi::detail::concat("fluid::solver: non-physical state in cell (", i, ", ", j, ", ",
                                                        k, ") at x = (", x[0], ", ", x[1], ", ", x[2],
                                                        ") m, t = ", t_new, " s: rho = ", q.rho, " kg/m^3, p = ", p,
                                                        " Pa, momentum = (", q.m.x, ", ", q.m.y, ", ", q.m.z,
                                                        "); reduce the time step (CFL) or check the set-up"),
                                grid.index(i, j, k), t_new);
      }
    }
  }
}

}  // namespace parafsi::fluid::detail
