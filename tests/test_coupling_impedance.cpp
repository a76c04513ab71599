// Impedance (added-mass) stabilisation of the embedded coupling
// (embedded_options::impedance, docs/coupling.md §7).
//
// A free flat plate of areal mass m spans a slip-wall duct with still air on both sides
// and starts at v0 = 0.1 m/s. Each face radiates a plane acoustic wave, so the plate
// decelerates as v(t) = v0 exp(−2 ρ c t / m) (linear acoustics; far-field duct ends,
// no reflection within the run).
// - heavy plate (m = 10 kg/m², ρ h / m = 0.01): with and without the impedance term the
//   velocity follows the exponential within 2 % after 3 ms (the term does not spoil a
//   resolved case);
// - fabric-weight plate (m = 0.05 kg/m², h = 0.2 m, CFL 0.9: 2ρc Δt/m = 2.8, the
//   added-mass regime of the drop's canopy on the tiny grid): without the term the
//   explicit exchange over-reacts, the velocity flips sign every step and grows by
//   ~2.4x per step; with it the plate is brought to the air's speed in one step
//   (physical decay time m/(2ρc) = 62 µs, less than a step) and stays bounded (|v| ≤ v0,
//   < 0.1 v0 after 20 steps: what is left moves with the first-order smeared wave);
// - the momentum in flight: with the term, ΔP_air + ΔP_plate equals the summed impedance
//   impulse to round-off (first 3 steps, before the waves leave the duct). The term
//   acts through the substeps it forces (limit m_i/‖C_i‖): with one substep it is zero,
//   which is why the heavy plate's results are identical with and without it.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>

#include "approx.hpp"
#include "coupling_test_util.hpp"

namespace pf = parafsi;
namespace st = pf::structure;

namespace {
constexpr double rho0 = 1.18, p0 = 101325.0, v0 = 0.1, x0 = 1.0;

auto make_plate(double areal_mass, int cells, double impedance) {
  const auto d = pf::model::duct_screen(2.0, cells, x0);
  pf::boundary::set bc = pf::boundary::set::all(pf::boundary::slip_wall{});
  bc.axis(0, pf::boundary::far_field{});
  pf::fluid::solver fl{ctu::duct_grid(d), bc};
  fl.fill_uniform({rho0, {0, 0, 0}, p0});
  st::nodes nd;
  for (const auto& x : d.sheet.positions) nd.add(x, {v0, 0, 0});
  // Stiff in-plane (a rigid plate moving as a whole), areal mass as given.
  st::membrane_tri mem{ctu::sheet_mesh(d), st::material::fabric<>::isotropic(1e9, 0.3, areal_mass, 1e-3)};
  st::assembly as{std::move(nd), std::move(mem)};
  as.integrator().gravity.setZero();
  pf::coupling::embedded_options eo;
  eo.impedance = impedance;
  return pf::explicit_stepper{std::move(fl), std::move(as), pf::coupling::embedded{pf::porosity::impermeable{}, eo}};
}

template <class S>
double plate_velocity(const S& s) {
  const auto& nd = s.structure().node_set();
  double v = 0, m = 0;
  for (pf::index_t i = 0; i < nd.size(); ++i) {
    v += nd.mass(i) * nd.velocity(i).x();
    m += nd.mass(i);
  }
  return v / m;
}

template <class S>
double air_momentum_x(const S& s) {
  return s.fluid().totals().momentum[0];
}
}  // namespace

TEST_CASE("embedded impedance: a heavy plate radiating into the duct decays as exp(-2 rho c t / m), with or without") {
  pf::parallel::set_threads(1);
  const double m = 10.0, c = std::sqrt(1.4 * p0 / rho0), t_end = 3e-3;
  for (double zeta : {0.0, 1.0}) {
    auto s = make_plate(m, 40, zeta);
    while (s.time() < t_end - 1e-15) s.step(std::min(s.stable_dt(0.5), t_end - s.time()));
    const double exact = v0 * std::exp(-2.0 * rho0 * c * s.time() / m);
    const double v = plate_velocity(s);
    std::printf("heavy plate, impedance %.0f: v(%.1e s) = %.6f m/s, exact %.6f (%+.3f %%), %ld steps\n", zeta, s.time(),
                v, exact, 100 * (v / exact - 1), s.steps());
    CHECK(v == pft::rel(exact, 0.02));
  }
}

TEST_CASE("embedded impedance: a fabric-weight plate is added-mass unstable without it and stops with it") {
  pf::parallel::set_threads(1);
  const double m = 0.05;
  // Without: the velocity over-shoots through zero and grows.
  {
    auto s = make_plate(m, 10, 0.0);
    double vmax = 0;
    bool flipped = false;
    try {
      for (int k = 0; k < 20; ++k) {
        s.step(s.stable_dt(0.9));
        const double v = plate_velocity(s);
        if (v < 0) flipped = true;
        if (std::isfinite(v)) vmax = std::max(vmax, std::fabs(v));
      }
    } catch (const pf::numerical_failure& e) {
      MESSAGE("without impedance: stopped: " << e.what());
      vmax = 1e300;
    }
    std::printf("fabric-weight plate, no impedance: sign flip %d, max |v| over 20 steps %.3e m/s (v0 %.1f)\n",
                int(flipped), vmax, v0);
    CHECK(flipped);
    CHECK(vmax > 10 * v0);
  }
  // With: monotone stop, no growth, momentum in flight accounted for.
  {
    auto s = make_plate(m, 10, 1.0);
    const double P0 = air_momentum_x(s);
    const auto& nd = s.structure().node_set();
    double Ms = 0;
    for (pf::index_t i = 0; i < nd.size(); ++i) Ms += nd.mass(i);
    const double Ps0 = Ms * plate_velocity(s);
    double vmax = 0, in_flight = 0, dP = 0;
    for (int k = 0; k < 20; ++k) {
      s.step(s.stable_dt(0.9));
      const double v = plate_velocity(s);
      REQUIRE(std::isfinite(v));
      vmax = std::max(vmax, std::fabs(v));
      in_flight += s.coupling().diagnostics().impulse_impedance.x();
      // Momentum over the first 3 steps, before the waves reach the far-field ends.
      if (k == 2) dP = (air_momentum_x(s) - P0) + (Ms * v - Ps0) - in_flight;
    }
    const double v = plate_velocity(s);
    std::printf(
        "fabric-weight plate, impedance 1: v = %.3e m/s after 20 steps (max |v| %.3e); over 3 steps "
        "dP_air + dP_plate - impedance impulse = %.2e N s (m v0 = %.2e N s)\n",
        v, vmax, dP, Ms * v0);
    CHECK(std::fabs(v) < 0.1 * v0);
    CHECK(vmax <= v0 * (1 + 1e-12));
    CHECK(std::fabs(dP) < 1e-8 * Ms * v0);  // round-off of the summed cell momenta
  }
}
