// Face patches (the hook of the embedded coupling): a wall patched into every face
// of one plane splits a closed box into two halves that exchange nothing; the
// identity patch changes nothing; the pressure jump on the wall is the difference
// of the one-sided momentum fluxes.
#include <doctest/doctest.h>

#include "fluid_test_util.hpp"

using namespace parafsi;
using pft::prim;

TEST_CASE("a patched wall plane seals one half of the box from the other") {
  const int n = 16;
  fluid::solver s{fluid::rectilinear_grid::uniform({n, 4, 4}, {0, 0, 0}, {1, 0.25, 0.25}),
                  boundary::set::all(boundary::slip_wall{}), flux::hllc_lm{}};
  s.initialize([](const Eigen::Vector3d& x) {
    return x[0] < 0.5 ? prim{1.2, {0, 0, 0}, 101375.0} : prim{1.2, {0, 0, 0}, 101325.0};
  });
  std::vector<fluid::patch_face> faces;
  for (index_t k = 0; k < 4; ++k)
    for (index_t j = 0; j < 4; ++j) faces.push_back({s.index(n / 2, j, k), 0});
  double impulse_on_wall = 0;
  int calls = 0, bad_context = 0;
  fluid::face_patches wall{faces, [&](const fluid::face_context& fc, fluid::cons<double>& lo, fluid::cons<double>& hi) {
                             // Reflecting wall on each side: only the pressure acts, no mass or energy crosses.
                             const double nx = fc.n.x;
                             lo = {0.0, {fc.L.p * nx, 0.0, 0.0}, 0.0};
                             hi = {0.0, {fc.R.p * nx, 0.0, 0.0}, 0.0};
                             impulse_on_wall += (fc.L.p - fc.R.p) * fc.area;
                             // The context names the stage and the list position: stage-major, list order.
                             const int expect = calls++;
                             if (fc.patch != std::size_t(expect % 16) ||
                                 fc.stage != (expect / 16) % decltype(s)::stages || fc.high != faces[fc.patch].high)
                               ++bad_context;
                           }};
  auto half_mass = [&](int side) {
    double m = 0;
    for (index_t k = 0; k < 4; ++k)
      for (index_t j = 0; j < 4; ++j)
        for (index_t i = side ? n / 2 : 0; i < (side ? n : n / 2); ++i)
          m += s.conserved(i, j, k).rho * s.grid().cell_volume(i, j, k);
    return m;
  };
  const double m0 = half_mass(0), m1 = half_mass(1);
  while (s.time() < 2e-3 - 1e-14) s.step(std::min(s.stable_dt(0.5), 2e-3 - s.time()), wall);
  CHECK(bad_context == 0);
  CHECK(calls > 0);
  MESSAGE("mass change left ", half_mass(0) - m0, " kg, right ", half_mass(1) - m1, " kg");
  CHECK(std::fabs(half_mass(0) - m0) < 1e-14 * m0);
  CHECK(std::fabs(half_mass(1) - m1) < 1e-14 * m1);
  CHECK(impulse_on_wall > 0.0);  // the high-pressure side pushes the wall towards +x
}

TEST_CASE("the identity patch reproduces the unpatched solution exactly") {
  auto make = [] {
    return fluid::solver{fluid::rectilinear_grid::uniform({12, 6, 4}, {0, 0, 0}, {1, 0.5, 0.3}),
                         boundary::set::all(boundary::periodic{}), flux::hllc{}};
  };
  auto a = make(), b = make();
  auto init = [](const Eigen::Vector3d& x) {
    return prim{1.0 + 0.1 * std::sin(6.28 * x[0]), {0.2, 0.1 * std::cos(6.28 * x[1]), 0.0}, 1.0 + 0.05 * x[2]};
  };
  a.initialize(init);
  b.initialize(init);
  fluid::face_patches identity{std::vector<fluid::patch_face>{{b.index(3, 2, 1), 0},
                                                              {b.index(5, 3, 2), 1},
                                                              {b.index(7, 1, 2), 2}},
                               [](const fluid::face_context&, fluid::cons<double>&, fluid::cons<double>&) {}};
  for (int k = 0; k < 10; ++k) {
    const double dt = a.stable_dt(0.5);
    a.step(dt);
    b.step(dt, identity);
  }
  double d = 0;
  for (index_t k = 0; k < 4; ++k)
    for (index_t j = 0; j < 6; ++j)
      for (index_t i = 0; i < 12; ++i) d = std::max(d, std::fabs(a.conserved(i, j, k).E - b.conserved(i, j, k).E));
  CHECK(d < 1e-12);
}
