// piston: a rigid plate (a membrane whose nodes are driven at a constant speed v)
// pushed into still air in a slip-wall duct through the penalty coupling (the
// default) or the embedded coupling (--coupling embedded: the plate is a moving wall
// in the face fluxes, no leak). Ahead of
// the plate the air is compressed by the acoustic impedance, Δp = ρ c v (exact
// piston shock: ρ c v [(γ+1)M/4 + √(1 + ((γ+1)M/4)²)], M = v/c, 0.35 % above at
// v = 2 m/s). Prints `pressure_rise=<Pa> rho_c_v=<Pa> relative_error=<e>`, the mean
// air velocity ahead of the plate and the leak v − u_air (the numerical leak of a
// zero-thickness penalty wall in a collocated scheme, docs/coupling.md); with --out,
// a CSV `x,p,u` of the duct's centre line at the end.
#include "example_common.hpp"

#include <parafsi/coupling/coupling.hpp>
#include <parafsi/explicit_stepper.hpp>
#include <parafsi/model/duct_screen.hpp>

namespace pf = parafsi;
namespace st = pf::structure;

int main(int argc, char** argv) {
  CLI::App app{
      "Rigid plate driven into still air in a slip-wall duct (penalty or embedded coupling); "
      "the pressure rise ahead of it against rho*c*v"};
  examples::common_options co;
  double v = 2.0, pfac = 1.0, t_end = 3e-3;
  int cells = 100;
  std::string out, coupling = "penalty";
  examples::add_flux_option(app, co);
  examples::add_limiter_option(app, co);
  examples::add_run_options(app, co);
  app.add_option("--velocity", v, "plate speed (m/s)")->check(CLI::Range(1e-3, 100.0))->capture_default_str();
  examples::add_cells_option(app, cells, "cells along the 2 m duct", 20);
  app.add_option("--coupling", coupling, "fluid-structure coupling")
      ->check(CLI::IsMember({"penalty", "embedded"}))
      ->capture_default_str();
  app.add_option("--pfac", pfac, "penalty factor PFAC")->check(CLI::Range(1e-4, 1e3))->capture_default_str();
  app.add_option("--time", t_end, "simulated time (s); the wave must not reach the duct end")
      ->check(CLI::Range(1e-5, 5e-3))
      ->capture_default_str();
  app.add_option("--out", out, "optional CSV x,p,u of the centre line at the end");
  int rc = 0;
  if (!examples::parse(app, argc, argv, rc)) return rc;
  examples::apply_threads(co);
  return examples::guarded("piston", [&]() -> int {
    return examples::dispatch(co.flux, co.limiter, [&](auto flux, auto recon) -> int {
      const auto d = pf::model::duct_screen(2.0, cells, 0.5);  // 2 m duct, plate at 0.5 m
      const double x0 = d.x_sheet;
      auto grid = pf::fluid::rectilinear_grid::uniform(d.cells, d.lo, d.hi);
      pf::boundary::set bc = pf::boundary::set::all(pf::boundary::slip_wall{});
      bc.axis(0, pf::boundary::far_field{});
      pf::fluid::solver fl{grid, bc, flux, recon};
      const double rho = 1.18, p0 = 101325.0;
      fl.fill_uniform({rho, {0, 0, 0}, p0});
      st::nodes nd;
      for (const auto& x : d.sheet.positions) nd.add(x);
      for (pf::index_t i = 0; i < nd.size(); ++i) nd.prescribe_velocity(i, {v, 0, 0});
      st::triangle_mesh tm;
      tm.triangles = d.sheet.triangles;
      st::membrane_tri mem{tm, st::material::fabric<>::isotropic(1e6, 0.3, 1.0, 1e-3)};
      st::assembly as{std::move(nd), std::move(mem)};
      as.integrator().gravity = {0, 0, 0};
      pf::coupling::penalty_options po;
      po.pfac = pfac;
      auto run = [&](auto cpl) -> int {
        pf::explicit_stepper s{std::move(fl), std::move(as), std::move(cpl)};
        examples::progress prog("piston", t_end, co.quiet);
        double max_pen = 0;
        examples::step_guard guard("piston", t_end);
        while (s.time() < t_end - 1e-15) {
          s.step(std::min(guard(s.stable_dt(co.cfl), s.time()), t_end - s.time()));
          max_pen = std::max(max_pen, s.coupling().diagnostics().max_penetration_over_h);
          prog(s.time(), s.steps());
        }
        prog.finish(s.time(), s.steps());
        // Mean pressure over the compressed column between the plate and the front.
        const double c = std::sqrt(1.4 * p0 / rho);
        const double xp = x0 + v * t_end, xf = x0 + c * t_end;
        const double a = xp + 0.2 * (xf - xp), b = xp + 0.8 * (xf - xp);
        double sum = 0, usum = 0;
        int n = 0;
        const auto& g = s.fluid().grid();
        for (pf::index_t i = 0; i < g.n(0); ++i)
          if (g.centre(0, i) > a && g.centre(0, i) < b) {
            sum += s.fluid().primitive(i, 0, 0).p;
            usum += s.fluid().primitive(i, 0, 0).u.x;
            ++n;
          }
        if (n == 0)
          throw pf::invalid_input("piston: no cells between the plate and the front; raise --cells or --time");
        const double rise = sum / n - p0, ref = rho * c * v;
        if (!out.empty()) {
          examples::csv_writer csv(out, "x,p,u");
          for (pf::index_t i = 0; i < g.n(0); ++i) {
            const auto w = s.fluid().primitive(i, 0, 0);
            csv.row({g.centre(0, i), w.p, w.u.x});
          }
          csv.close();
        }
        const double ua = usum / n;
        std::printf(
            "pressure_rise=%.6g rho_c_v=%.6g relative_error=%.4e air_velocity=%.6g leak_velocity=%.6g "
            "rho_c_u_air=%.6g max_penetration_over_h=%.4g\n",
            rise, ref, rise / ref - 1.0, ua, v - ua, rho * c * ua, max_pen);
        return 0;
      };
      if (coupling == "embedded") return run(pf::coupling::embedded{pf::porosity::impermeable{}});
      return run(pf::coupling::penalty{pf::porosity::impermeable{}, po});
    });
  });
}
