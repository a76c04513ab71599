// Momentum and energy exchange of the penalty coupling: in a periodic box (no
// boundary forces) the air's momentum change equals minus the structure's, to
// round-off, every step, with and without structure substeps; the air's energy
// change equals the coupling work Σ W given to it.
#include <doctest/doctest.h>

#include <parafsi/coupling/coupling.hpp>
#include <parafsi/explicit_stepper.hpp>
#include <parafsi/fluid/fluid.hpp>
#include <parafsi/model/fabric_catalogue.hpp>
#include <parafsi/model/rect_mesh.hpp>
#include <parafsi/structure/structure.hpp>

#include <cmath>
#include <cstdio>

namespace pf = parafsi;
namespace st = pf::structure;

namespace {
template <class Porosity>
auto make_stepper(Porosity por, double areal_density, double E, double pfac) {
  auto grid = pf::fluid::rectilinear_grid::uniform({8, 8, 8}, {0, 0, 0}, {0.4, 0.4, 0.4});
  pf::fluid::solver fl{grid, pf::boundary::set::all(pf::boundary::periodic{})};
  // A tilted square patch moving obliquely through still air.
  const auto m = pf::model::rect_mesh({0.12, 0.1, 0.11}, {0.02, 0.18, 0.0}, {0.0, 0.03, 0.17}, 3, 3);
  st::nodes nd;
  for (const auto& x : m.positions) nd.add(x, {4.0, 1.0, -0.5});
  st::triangle_mesh tm;
  tm.triangles = m.triangles;
  st::membrane_tri mem{tm, st::material::fabric<>::isotropic(E, 0.3, areal_density, 1e-4)};
  st::assembly as{std::move(nd), std::move(mem)};
  as.integrator().gravity = {0, 0, 0};
  pf::coupling::penalty_options o;
  o.pfac = pfac;
  return pf::explicit_stepper{std::move(fl), std::move(as), pf::coupling::penalty{por, o}};
}

template <class S>
void check_balance(S& s, int steps, const char* label) {
  auto fm = [&] {
    const auto t = s.fluid().totals();
    return Eigen::Vector3d(t.momentum[0], t.momentum[1], t.momentum[2]);
  };
  double worst = 0, worst_e = 0, scale = 0;
  long max_m = 0;
  for (int n = 0; n < steps; ++n) {
    const Eigen::Vector3d pf0 = fm(), ps0 = s.structure().linear_momentum();
    const double e0 = s.fluid().totals().energy;
    s.step(s.stable_dt(0.5));
    const Eigen::Vector3d dpf = fm() - pf0, dps = s.structure().linear_momentum() - ps0;
    const auto& d = s.coupling().diagnostics();
    scale = std::max(scale, d.impulse_structure.norm());
    // Structure momentum change = coupling impulse (no other load).
    CHECK((dps - d.impulse_structure).norm() <= 1e-12 * (ps0.norm() + d.impulse_structure.norm()));
    worst = std::max(worst, (dpf + dps).norm() / std::max(d.impulse_structure.norm(), 1e-300));
    const double de = s.fluid().totals().energy - e0;
    worst_e = std::max(worst_e, std::fabs(de - d.work_fluid) / e0);  // round-off of the energy sum
    max_m = std::max(max_m, s.last_substeps());
  }
  std::printf("%s: %d steps, max substeps %ld, max step impulse %.3e N s, "
              "max |dP_fluid + dP_structure| / |J| = %.2e, max |dE_fluid - W| / E_fluid = %.2e\n",
              label, steps, max_m, scale, worst, worst_e);
  CHECK(scale > 0);
  CHECK(worst < 1e-9);
  CHECK(worst_e < 1e-13);
}
}  // namespace

TEST_CASE("penalty: impulse balance to round-off every step (impermeable, one substep)") {
  pf::parallel::set_threads(1);
  auto s = make_stepper(pf::porosity::impermeable{}, 0.5, 1e5, 0.1);
  check_balance(s, 40, "impermeable");
  CHECK(s.coupling().points().size() > 0);
  CHECK(s.coupling().diagnostics().max_penetration_over_h > 0);
}

TEST_CASE("penalty: impulse balance with structure substeps and a porous fabric") {
  const auto& f = pf::model::fabric_catalogue[2];
  auto s = make_stepper(pf::porosity::ergun{f.alpha, f.beta, f.thickness}, 0.05, 5e10, 1.0);
  check_balance(s, 40, "ergun mat509, stiff membrane");
  CHECK(s.last_substeps() > 1);
}
