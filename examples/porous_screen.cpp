// porous_screen: a flat fabric sheet (edges pinned) spanning a slip-wall duct, air
// driven through it from an inflow at V against a fixed-pressure outlet, run to a
// steady state. Prints `pressure_drop=<Pa> through_velocity=<m/s>` (the pressure
// difference between windows 0.1–0.2 m up- and downstream of the sheet, and the air's
// velocity normal to the cloth: the mean duct velocity upstream times cos θ, by mass
// conservation; the inflow face is not rigid, so it is measured, not V) and the fabric's
// Ergun law at that velocity with the relative error. `--incline DEG` turns the sheet by
// DEG about the transverse z axis in a duct `--width-cells` cells wide (default 2
// upright, 8 inclined), so the cloth crosses the grid's faces as a staircase;
// `--through-flow face` puts the embedded coupling's law on each face's velocity.
// CSV `t,pressure_drop,through_velocity`.
#include "example_common.hpp"

#include <parafsi/coupling/coupling.hpp>
#include <parafsi/explicit_stepper.hpp>
#include <parafsi/model/duct_screen.hpp>
#include <parafsi/model/fabric_catalogue.hpp>

#include <filesystem>

namespace pf = parafsi;
namespace st = pf::structure;

int main(int argc, char** argv) {
  CLI::App app{"Flat porous fabric in a slip-wall duct: steady pressure drop against the Ergun law"};
  examples::common_options co;
  std::string fabric = "mat544", coupling = "penalty", through_flow = "cloth", out;
  double V = 0.5, pfac = 1.0, t_end = 0.1, incline = 0.0;
  int cells = 40, width_cells = 0;
  examples::add_flux_option(app, co);
  examples::add_limiter_option(app, co);
  examples::add_run_options(app, co);
  app.add_option("--fabric", fabric, "fabric of the paper's Table 2")
      ->check(CLI::IsMember({"mat544", "mat59225", "mat509"}))
      ->capture_default_str();
  app.add_option("--velocity", V, "inflow velocity (m/s)")->check(CLI::Range(1e-4, 50.0))->capture_default_str();
  app.add_option("--coupling", coupling,
                 "coupling method: penalty (the paper's) or embedded (membrane-aware face fluxes)")
      ->check(CLI::IsMember({"penalty", "embedded"}))
      ->capture_default_str();
  app.add_option("--through-flow", through_flow,
                 "embedded: the velocity the Ergun law acts on, cloth (the cloth's normal) or face (each face's own)")
      ->check(CLI::IsMember({"cloth", "face"}))
      ->capture_default_str();
  examples::add_cells_option(app, cells, "cells along the 1 m duct", 10);
  app.add_option("--pfac", pfac, "penalty factor PFAC")->check(CLI::Range(1e-4, 1e3))->capture_default_str();
  app.add_option("--incline", incline, "sheet turned by this angle about the transverse axis (degrees)")
      ->check(examples::finite)
      ->check(CLI::Range(-60.0, 60.0))
      ->capture_default_str();
  app.add_option("--width-cells", width_cells,
                 "cells across the duct along the incline's plane (even; 0 = 2 upright, 8 inclined)")
      ->check(CLI::Range(0, 64))
      ->capture_default_str();
  app.add_option("--time", t_end, "simulated time (s)")->check(CLI::Range(1e-4, 10.0))->capture_default_str();
  examples::add_out_option(app, out);
  int rc = 0;
  if (!examples::parse(app, argc, argv, rc)) return rc;
  examples::apply_threads(co);
  return examples::guarded("porous_screen", [&]() -> int {
    return examples::dispatch(co.flux, co.limiter, [&](auto flux, auto recon) -> int {
      const auto& fab = pf::model::fabric(fabric);
      const pf::porosity::ergun law{fab.alpha, fab.beta, fab.thickness};
      const int m = width_cells > 0 ? width_cells : (incline == 0.0 ? 2 : 8);
      const auto d = pf::model::duct_screen(1.0, cells, 0.5, 2, incline, m);  // 1 m duct, sheet at 0.5 m
      const double rho = 1.18, p0 = 101325.0;
      // Probe windows 0.1–0.2 m beyond the sheet's x extent on each side.
      const double reach = 0.5 * d.width_y * std::fabs(std::tan(d.incline));
      const double up_lo = d.x_sheet - reach - 0.2, up_hi = d.x_sheet - reach - 0.1;
      const double dn_lo = d.x_sheet + reach + 0.1, dn_hi = d.x_sheet + reach + 0.2;
      const double cos_incline = std::cos(d.incline);
      auto grid = pf::fluid::rectilinear_grid::uniform(d.cells, d.lo, d.hi);
      pf::boundary::set bc = pf::boundary::set::all(pf::boundary::slip_wall{});
      bc.side(0, 0, pf::boundary::inflow{rho, {V, 0, 0}, p0});
      bc.side(0, 1, pf::boundary::outflow{true, p0});
      pf::fluid::solver fl{grid, bc, flux, recon};
      fl.fill_uniform({rho, {V, 0, 0}, p0});
      // Sheet: 2 x 2 quads, edges pinned, the centre node free.
      st::nodes nd;
      for (const auto& x : d.sheet.positions) nd.add(x);
      for (auto i : d.sheet.edge) nd.pin(i);
      st::triangle_mesh tm;
      tm.triangles = d.sheet.triangles;
      const double E = fab.break_strength / 0.05 / fab.elongation / fab.thickness;  // secant modulus
      st::membrane_tri mem{tm, st::material::fabric<>::isotropic(E, 0.3, fab.areal_density, fab.thickness),
                           st::membrane_options{0.1}};
      st::assembly as{std::move(nd), std::move(mem)};
      as.integrator().gravity = {0, 0, 0};
      pf::coupling::penalty_options po;
      po.pfac = pfac;
      auto run = [&](auto cpl) -> int {
        pf::explicit_stepper s{std::move(fl), std::move(as), std::move(cpl)};
        const auto& g = s.fluid().grid();
        auto measure = [&](double& dp, double& u) {
          double pu = 0, pd = 0, uu = 0;
          int nu = 0, nd2 = 0;
          for (pf::index_t k = 0; k < g.n(2); ++k)
            for (pf::index_t j = 0; j < g.n(1); ++j)
              for (pf::index_t i = 0; i < g.n(0); ++i) {
                const double x = g.centre(0, i);
                const auto w = s.fluid().primitive(i, j, k);
                if (x > up_lo && x < up_hi) {
                  pu += w.p;
                  uu += w.u.x;
                  ++nu;
                }
                if (x > dn_lo && x < dn_hi) {
                  pd += w.p;
                  ++nd2;
                }
              }
          if (nu == 0 || nd2 == 0)
            throw pf::invalid_input("porous_screen: no cells in the probe windows; raise --cells");
          dp = pu / nu - pd / nd2;
          u = uu / nu * cos_incline;  // normal to the cloth: Q / A_cloth = U A / (A / cos θ)
        };
        examples::csv_writer csv(out, "t,pressure_drop,through_velocity");
        examples::progress prog("porous_screen", t_end, co.quiet);
        double dp = 0, u = 0;
        long next_row = 0;
        double max_pen = 0;
        examples::step_guard guard("porous_screen", t_end);
        while (s.time() < t_end - 1e-15) {
          s.step(std::min(guard(s.stable_dt(co.cfl), s.time()), t_end - s.time()));
          max_pen = std::max(max_pen, s.coupling().diagnostics().max_penetration_over_h);
          if (s.steps() >= next_row) {
            measure(dp, u);
            csv.row({s.time(), dp, u});
            next_row += 20;
          }
          prog(s.time(), s.steps());
        }
        prog.finish(s.time(), s.steps());
        measure(dp, u);
        csv.row({s.time(), dp, u});
        csv.close();
        const double ergun_dp = law.pressure_jump(u);
        std::printf(
            "pressure_drop=%.6g through_velocity=%.6g ergun_pressure_drop=%.6g relative_error=%.4e "
            "law_through_flow_velocity=%.6g max_penetration_over_h=%.4g\n",
            dp, u, ergun_dp, dp / ergun_dp - 1.0, s.coupling().total_through_flow() / s.coupling().coupled_area(),
            max_pen);
        return 0;
      };
      if (coupling == "embedded") {
        pf::coupling::embedded_options eo;
        eo.law_on = pf::coupling::through_flow_law_named(through_flow);
        return run(pf::coupling::embedded{law, eo});
      }
      return run(pf::coupling::penalty{law, po});
    });
  });
}
