// Bluff-body drag: a fixed impermeable disk normal to a 40 m/s stream, the set-up of
// examples/bluff_body_drag.cpp at 6 cells per diameter (inviscid, HLLC-LM + van Leer,
// far field + sponge), run for 16 D/U; the drag coefficient from the coupling's nodal
// impulses, averaged over the second half, must lie within 15 % of the range 1.12–1.17 (measured 1.317;
// values per coupling and resolution: docs/coupling.md §8). A porous disk with the quadratic
// loss law Δp = K ½ρu_n² at 8 cells per diameter: drag and through-flow against the
// momentum model of Steiros & Hultmark (2018), which includes the wake's base pressure. The
// stream's total pressure one diameter ahead against the free stream's (Bernoulli), with the
// inflow far from the disk.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include <parafsi/coupling/coupling.hpp>
#include <parafsi/explicit_stepper.hpp>
#include <parafsi/model/disk_mesh.hpp>
#include <parafsi/parafsi.hpp>

namespace pf = parafsi;
namespace st = pf::structure;

namespace {

struct drag_result {
  double cd = 0, through = 0;  ///< means over the second half: C_d, through-velocity / U
  /// The cloth's two sides (coupling::embedded::cloth_sides along the stream): mean gauge C_p
  /// windward and leeward over the second half, and the largest difference over all steps
  /// between their load (p_w − p_l) S and the coupling's impulse along the stream / Δt, and
  /// between their load vector (cloth_side_means::pressure_load) and the impulse vector / Δt,
  /// relative to the larger of that force and ½ρU²πR².
  double windward_cp = 0, leeward_cp = 0, load_identity = 0;
  /// The stream's total pressure one diameter ahead on the axis, (p − p∞)/q + |u|²/U², over the
  /// second half (1 to M²/4 in an unbounded stream).
  double upstream_total_cp = 0;
};

/// The box: from `upstream` diameters ahead of the disk to 5 behind, ±`width` from the axis.
struct box_extent {
  double upstream = 2.5, width = 2.5;
};

template <class Coupling>
drag_result disk_drag(int cells, double flow_times, Coupling cpl, box_extent box = {}) {
  const double D = 0.2, R = 0.5 * D, rho = 1.18, p0 = 101325.0, U = 40.0, h = D / cells;
  using pf::fluid::axis;
  const double W = box.width * D;
  pf::fluid::rectilinear_grid grid{axis::refined(-box.upstream * D, 5 * D, -0.5 * D, 1.5 * D, h, 1.15),
                                   axis::refined(-W, W, -0.75 * D, 0.75 * D, h, 1.15),
                                   axis::refined(-W, W, -0.75 * D, 0.75 * D, h, 1.15)};
  std::array<pf::index_t, 3> ahead{};  // the cell holding (−D, 0, 0)
  for (int d = 0; d < 3; ++d) {
    const auto& f = grid.axis_of(d).faces;
    ahead[std::size_t(d)] = pf::index_t(std::upper_bound(f.begin(), f.end(), d == 0 ? -D : 0.0) - f.begin()) - 1;
  }
  pf::boundary::set bc = pf::boundary::set::all(pf::boundary::far_field{rho, {U, 0, 0}, p0});
  bc.layer.cells = 4;
  pf::fluid::solver fl{grid, bc, pf::flux::hllc_lm{}, pf::recon::muscl<pf::limiter::van_leer>{}};
  fl.fill_uniform({rho, {U, 0, 0}, p0});
  const auto dm = pf::model::disk_mesh(R, std::max(2, cells / 2));
  st::nodes nd;
  for (const auto& p : dm.positions) nd.add(Eigen::Vector3d(0.0, p.x(), p.y()));
  for (pf::index_t i = 0; i < nd.size(); ++i) nd.pin(i);
  st::triangle_mesh tm;
  tm.triangles = dm.triangles;
  st::membrane_tri mem{tm, st::material::fabric<>::isotropic(3e8, 0.3, 0.054, 1.1e-4)};
  st::assembly as{std::move(nd), std::move(mem)};
  as.integrator().gravity = {0, 0, 0};
  pf::explicit_stepper s{std::move(fl), std::move(as), std::move(cpl)};
  const double t_end = flow_times * D / U, t_avg = 0.5 * t_end;
  const double qA = 0.5 * rho * U * U * std::numbers::pi * R * R;
  double sum = 0, sum_t = 0, sum_q = 0, sum_w = 0, sum_l = 0, sum_p0 = 0, identity = 0;
  while (s.time() < t_end * (1.0 - 1e-12)) {
    const double dt = std::min(s.stable_dt(0.5), t_end - s.time());
    const double t0 = s.time();
    s.step(dt);
    const double fx = s.coupling().diagnostics().impulse_structure.x() / dt, cd = fx / qA;
    REQUIRE(std::isfinite(cd));
    // A fixed body has no swept terms and the porous momentum leaves one side as it enters
    // the other: its load along the stream is the wall pressures' jump on the x-faces.
    const auto cs = s.coupling().cloth_sides(Eigen::Vector3d::UnitX());
    const double load = (cs.windward_pressure - cs.leeward_pressure) * cs.projected_area;
    REQUIRE(std::isfinite(load));
    identity = std::max(identity, std::fabs(load - fx) / std::max(std::fabs(fx), qA));
    // The load as a vector (side force included): the coupling's whole impulse / Δt.
    const Eigen::Vector3d F = s.coupling().diagnostics().impulse_structure / dt;
    identity = std::max(identity, (cs.pressure_load - F).norm() / std::max(F.norm(), qA));
    const double w = s.time() - std::max(t0, t_avg);
    if (w > 0) {
      sum += cd * w;
      sum_t += w;
      if constexpr (Coupling::porosity_type::permeable)
        sum_q += s.coupling().total_through_flow() / s.coupling().coupled_area() / U * w;
      sum_w += (cs.windward_pressure - p0) / (0.5 * rho * U * U) * w;
      sum_l += (cs.leeward_pressure - p0) / (0.5 * rho * U * U) * w;
      const auto wa = s.fluid().primitive(ahead[0], ahead[1], ahead[2]);
      sum_p0 += ((wa.p - p0) / (0.5 * rho * U * U) + pf::dot(wa.u, wa.u) / (U * U)) * w;
    }
  }
  return {sum / sum_t, sum_q / sum_t, sum_w / sum_t, sum_l / sum_t, identity, sum_p0 / sum_t};
}

/// Steiros & Hultmark (2018): a porous plate of loss coefficient K (on the velocity through
/// it, U(1 − a)) has C_D = 4a(3 − a) / (3(1 + a)) with K = C_D / (1 − a)²; returns
/// {C_D, 1 − a}, a found by bisection (C_D / (1 − a)² rises monotonically from 0 to ∞).
drag_result steiros_hultmark(double K) {
  auto cd = [](double a) { return 4.0 * a * (3.0 - a) / (3.0 * (1.0 + a)); };
  double lo = 0.0, hi = 1.0 - 1e-12;
  for (int i = 0; i < 200; ++i) {
    const double m = 0.5 * (lo + hi);
    (cd(m) / ((1.0 - m) * (1.0 - m)) < K ? lo : hi) = m;
  }
  const double a = 0.5 * (lo + hi);
  return {cd(a), 1.0 - a};
}

}  // namespace

TEST_CASE(
    "bluff body: fixed disk drag coefficient within 15 % of the 1.12-1.17 range (embedded, 6 cells per diameter)") {
  const auto r = disk_drag(6, 16.0, pf::coupling::embedded{pf::porosity::impermeable{}});
  const double cd = r.cd;
  MESSAGE("disk C_d (embedded, D/h = 6, mean over 8-16 D/U) = " << r.cd << ", windward C_p " << r.windward_cp
                                                                << ", leeward C_p " << r.leeward_cp
                                                                << ", load identity " << r.load_identity);
  // Within 15 % of the published range 1.12–1.17 (the criterion); the coarse
  // wake's drag is still falling at the end of the run, so the mean is an upper estimate.
  CHECK(cd > 0.85 * 1.12);
  CHECK(cd < 1.15 * 1.17);
  // The wall pressures carry the whole load, every step, to round-off; the front is loaded
  // and the back in suction. The front reads C_p 1.16 on p∞, above the free stream's
  // stagnation value 1 + M²/4 = 1.003: this box feeds the disk a stream of more total
  // pressure (the next test case; coupling.md §8.3).
  CHECK(r.load_identity < 1e-9);
  CHECK(r.windward_cp > 0.5);
  CHECK(r.leeward_cp < 0);
}

TEST_CASE("bluff body: the stream ahead of the disk keeps the free stream's total pressure once the inflow is far") {
  // Bernoulli on the stagnation streamline: one diameter ahead of the disk the total pressure
  // is the free stream's, C_p + |u|²/U² = 1 + O(M²/4 = 0.0033), whatever the disk does to the
  // velocity there. At low Mach number the characteristic far field holds the inflow's velocity
  // (a steady pressure rise δp moves it by δp/ρc only) and the sponge pulls the state back to
  // the free stream, so an inflow face close to the body turns the body's blockage pressure
  // into an excess of total pressure. Measured (8 cells per diameter, 16 D/U): 1.19 from 2.5 D
  // upstream and ±2.5 D, 1.013 from 6 D and ±5 D (coupling.md §8.3; the near box's excess
  // measures the box and is not pinned here). 6 cells per diameter, 4 D/U: with the far inflow
  // the value holds from 2 D/U on (1.005 over 8–16 D/U).
  const auto far = disk_drag(6, 4.0, pf::coupling::embedded{pf::porosity::impermeable{}}, {6.0, 5.0});
  MESSAGE("total pressure one diameter ahead, (p - p_inf)/q + |u|^2/U^2 over 2-4 D/U, inflow at 6 D, +-5 D: "
          << far.upstream_total_cp << " (C_d " << far.cd << ", windward C_p " << far.windward_cp << ")");
  CHECK(std::fabs(far.upstream_total_cp - 1.0) < 0.025);
}

TEST_CASE(
    "bluff body: porous disk (K = 4) on the Steiros-Hultmark relation within 10 % (embedded, 8 cells per diameter)") {
  // The model at K = 4: C_D = 1.088, through-fraction 0.522; the actuator-disk momentum
  // relation (no base pressure) would give 1.000 and 0.500 (a = ½, its limit).
  const double K = 4.0, rho = 1.18, t = 1e-4;
  const auto r = disk_drag(8, 16.0, pf::coupling::embedded{pf::porosity::ergun{0.0, K * rho / (2.0 * t), t}});
  const auto sh = steiros_hultmark(K);
  MESSAGE("porous disk K = 4, D/h = 8, mean over 8-16 D/U: C_d = " << r.cd << " (Steiros-Hultmark " << sh.cd
                                                                   << "), through-fraction " << r.through << " ("
                                                                   << sh.through << ")");
  CHECK(std::fabs(sh.cd - 1.0884) < 1e-3);  // the model itself, solved here
  CHECK(std::fabs(r.cd / sh.cd - 1.0) < 0.10);
  CHECK(std::fabs(r.through / sh.through - 1.0) < 0.10);
  MESSAGE("  windward C_p " << r.windward_cp << ", leeward C_p " << r.leeward_cp << ", load identity "
                            << r.load_identity);
  CHECK(r.load_identity < 1e-9);
}
