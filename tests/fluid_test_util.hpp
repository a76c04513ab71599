// Shared set-ups for the fluid tests.
#pragma once
#include <parafsi/parafsi.hpp>

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
}  // namespace pft
