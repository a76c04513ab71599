// Porosity laws: Ergun reproduces the paper's Table 2 permeabilities at 50 Pa; the
// inverse is exact; Darcy and impermeable; bad parameters are rejected.
#include <doctest/doctest.h>

#include "approx.hpp"

#include <parafsi/coupling/coupling.hpp>
#include <parafsi/model/fabric_catalogue.hpp>

#include <cmath>
#include <cstdio>

namespace pf = parafsi;

TEST_CASE("ergun: Table 2 air permeabilities at 50 Pa within 1 %") {
  for (const auto& f : pf::model::fabric_catalogue) {
    const pf::porosity::ergun law{f.alpha, f.beta, f.thickness};
    law.validate();
    const double v = law.through_velocity(f.test_pressure);
    const double rel = v / f.air_permeability - 1.0;
    std::printf("%-9s V(50 Pa) = %.6g m/s (table %.4g), rel. error %.2e\n", std::string(f.name).c_str(), v,
                f.air_permeability, rel);
    CHECK(std::fabs(rel) < 0.01);
    // And the forward law at the table's permeability gives 50 Pa.
    CHECK(law.pressure_jump(f.air_permeability) == doctest::Approx(50.0).epsilon(0.01));
  }
}

TEST_CASE("ergun: inverse is exact, odd, and the SIMD instantiation agrees") {
  const auto& f = pf::model::fabric("mat59225");
  const pf::porosity::ergun law{f.alpha, f.beta, f.thickness};
  for (double dp : {-800.0, -50.0, -1e-6, 0.0, 1e-9, 0.3, 20.0, 500.0, 1e5}) {
    const double v = law.through_velocity(dp);
    CHECK(law.pressure_jump(v) == doctest::Approx(dp).epsilon(1e-13).scale(1e-12));
    CHECK(law.through_velocity(-dp) == -v);
    const auto vp = law.through_velocity(pf::simd::pack<double>(dp));
    CHECK(vp.get(0) == pft::rel(v, 1e-14));
    // compliance = 1/resistance
    CHECK(law.compliance(dp) * law.resistance(v) == doctest::Approx(1.0).epsilon(1e-14));
  }
  // Tiny pressure jumps: no cancellation (V ≈ Δp/(αt)).
  CHECK(law.through_velocity(1e-12) == pft::rel(1e-12 / (f.alpha * f.thickness), 1e-9));
}

TEST_CASE("darcy and impermeable") {
  const auto d = pf::porosity::darcy::from_reference(0.508, 124.5, 1e-4);
  CHECK(d.alpha * d.thickness == doctest::Approx(245.08).epsilon(1e-3));  // methods §4.7 nylon fit
  CHECK(d.through_velocity(d.pressure_jump(0.3)) == doctest::Approx(0.3).epsilon(1e-14));
  const pf::porosity::impermeable imp;
  CHECK(imp.through_velocity(1e4) == 0.0);
  CHECK(imp.compliance(1e4) == 0.0);
}

TEST_CASE("porosity: bad parameters are rejected with the value") {
  CHECK_THROWS_WITH_AS((pf::porosity::ergun{-1.0, 1.0, 1e-4}.validate()), doctest::Contains("alpha must be >= 0"),
                       pf::invalid_input);
  CHECK_THROWS_WITH_AS((pf::porosity::ergun{1.0, 1.0, 0.0}.validate()), doctest::Contains("thickness"),
                       pf::invalid_input);
  CHECK_THROWS_AS((pf::porosity::ergun{0.0, 0.0, 1e-4}.validate()), pf::invalid_input);
  // Penalty stiffening below 0.01 cell outgrows the substep bound within a step: refused.
  pf::coupling::penalty_options po;
  po.stiffening = 0.005;
  CHECK_THROWS_WITH_AS(po.validate(), doctest::Contains("stiffening must be 0 (off) or >= 0.01"), pf::invalid_input);
  po.stiffening = 0.01;
  CHECK_NOTHROW(po.validate());
  po.max_cells_per_step = std::nan("");
  CHECK_THROWS_AS(po.validate(), pf::invalid_input);
  CHECK_THROWS_AS((pf::porosity::darcy{0.0, 1e-4}.validate()), pf::invalid_input);
  CHECK_THROWS_WITH_AS(pf::model::fabric("mat000"), doctest::Contains("unknown fabric 'mat000'"), pf::invalid_input);
}
