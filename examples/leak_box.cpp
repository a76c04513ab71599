// leak_box: a closed slip-wall box split by an impermeable membrane (all nodes
// pinned) with an initial pressure difference DP (left +DP/2, right −DP/2). Every
// kilogram that crosses is leak: the penalty wall's numerical leak (docs/coupling.md).
// Prints `leak_velocity=<m/s>` (mean through-flow per membrane area over the run,
// from the mass gained by the right half) and the late-time rate (second half).
// CSV `t,pressure_left,pressure_right,leak_velocity` (instantaneous).
#include "example_common.hpp"

#include <parafsi/coupling/coupling.hpp>
#include <parafsi/explicit_stepper.hpp>
#include <parafsi/model/duct_screen.hpp>

namespace pf = parafsi;
namespace st = pf::structure;

int main(int argc, char** argv) {
  CLI::App app{"Closed box split by an impermeable pinned membrane: the numerical leak of the coupling"};
  examples::common_options co;
  std::string coupling = "penalty", out;
  double DP = 50.0, pfac = 1.0, t_end = 0.05, stiffening = 0.0;
  int cells = 40;
  examples::add_flux_option(app, co);
  examples::add_limiter_option(app, co);
  examples::add_run_options(app, co);
  app.add_option("--coupling", coupling,
                 "coupling method: penalty (the paper's) or embedded (membrane-aware face fluxes)")
      ->check(CLI::IsMember({"penalty", "embedded"}))
      ->capture_default_str();
  app.add_option("--pressure-jump", DP, "initial pressure difference (Pa)")
      ->check(CLI::Range(1e-3, 1e5))
      ->capture_default_str();
  examples::add_cells_option(app, cells, "cells along the 1 m box", 10);
  app.add_option("--pfac", pfac, "penalty factor PFAC")->check(CLI::Range(1e-4, 1e3))->capture_default_str();
  // λ > 0 stiffens the springs by (d/(λh))², which the stable step does not see: a tiny λ
  // would diverge, so 0 (off) or [0.01, 10].
  app.add_option("--stiffening", stiffening, "nonlinear stiffening lambda (0 = off)")
      ->check(CLI::Validator(
          [](std::string& s) {
    double v = 0;
    if (CLI::detail::lexical_cast(s, v) && (v == 0 || (v >= 0.01 && v <= 10))) return std::string();
    return "stiffening " + s + " is neither 0 (off) nor in [0.01, 10]";
          },
          "0 or [0.01 - 10]"))
      ->capture_default_str();
  app.add_option("--time", t_end, "simulated time (s)")->check(CLI::Range(1e-4, 10.0))->capture_default_str();
  examples::add_out_option(app, out);
  int rc = 0;
  if (!examples::parse(app, argc, argv, rc)) return rc;
  examples::apply_threads(co);
  return examples::guarded("leak_box", [&]() -> int {
    return examples::dispatch(co.flux, co.limiter, [&](auto flux, auto recon) -> int {
      const auto d = pf::model::duct_screen(1.0, cells, 0.5);  // 1 m box, membrane at 0.5 m
      const double xs = d.x_sheet, rho = 1.18, p0 = 101325.0;
      auto grid = pf::fluid::rectilinear_grid::uniform(d.cells, d.lo, d.hi);
      pf::fluid::solver fl{grid, pf::boundary::set::all(pf::boundary::slip_wall{}), flux, recon};
      fl.initialize([&](const Eigen::Vector3d& xi) {
        return pf::fluid::prim<double>{rho, {0, 0, 0}, xi.x() < xs ? p0 + 0.5 * DP : p0 - 0.5 * DP};
      });
      st::nodes nd;
      for (const auto& x : d.sheet.positions) nd.add(x);
      for (pf::index_t i = 0; i < nd.size(); ++i) nd.pin(i);
      st::triangle_mesh tm;
      tm.triangles = d.sheet.triangles;
      st::membrane_tri mem{tm, st::material::fabric<>::isotropic(3e8, 0.3, 0.054, 1.1e-4)};
      st::assembly as{std::move(nd), std::move(mem)};
      as.integrator().gravity = {0, 0, 0};
      pf::coupling::penalty_options po;
      po.pfac = pfac;
      po.stiffening = stiffening;
      auto run = [&](auto cpl) -> int {
        pf::explicit_stepper s{std::move(fl), std::move(as), std::move(cpl)};
        const auto& g = s.fluid().grid();
        const double area = d.area();
        auto halves = [&](double& ml, double& mr, double& pl, double& pr) {
          ml = mr = pl = pr = 0;
          int nl = 0, nr = 0;
          for (pf::index_t k = 0; k < 2; ++k)
            for (pf::index_t j = 0; j < 2; ++j)
              for (pf::index_t i = 0; i < g.n(0); ++i) {
                const auto w = s.fluid().primitive(i, j, k);
                const double mass = w.rho * g.cell_volume(i, j, k);
                if (g.centre(0, i) < xs) {
                  ml += mass;
                  pl += w.p;
                  ++nl;
                } else {
                  mr += mass;
                  pr += w.p;
                  ++nr;
                }
              }
          pl /= nl;
          pr /= nr;
        };
        double ml, mr0, pl, pr, mr;
        halves(ml, mr0, pl, pr);
        examples::csv_writer csv(out, "t,pressure_left,pressure_right,leak_velocity");
        examples::progress prog("leak_box", t_end, co.quiet);
        double t_prev = 0, mr_prev = mr0, mr_half = mr0, t_half = -1, max_pen = 0;
        long next_row = 0;
        examples::step_guard guard("leak_box", t_end);
        while (s.time() < t_end - 1e-15) {
          s.step(std::min(guard(s.stable_dt(co.cfl), s.time()), t_end - s.time()));
          max_pen = std::max(max_pen, s.coupling().diagnostics().max_penetration_over_h);
          if (t_half < 0 && s.time() >= 0.5 * t_end) {
            halves(ml, mr_half, pl, pr);
            t_half = s.time();
          }
          if (s.steps() >= next_row) {
            halves(ml, mr, pl, pr);
            const double dt = s.time() - t_prev;
            csv.row({s.time(), pl, pr, (mr - mr_prev) / (rho * area * dt)});
            t_prev = s.time();
            mr_prev = mr;
            next_row += 20;
          }
          prog(s.time(), s.steps());
        }
        prog.finish(s.time(), s.steps());
        halves(ml, mr, pl, pr);
        csv.row({s.time(), pl, pr, (mr - mr_prev) / (rho * area * std::max(s.time() - t_prev, 1e-300))});
        csv.close();
        const double leak = (mr - mr0) / (rho * area * s.time());
        const double late = t_half > 0 ? (mr - mr_half) / (rho * area * (s.time() - t_half)) : leak;
        std::printf(
            "leak_velocity=%.6g leak_velocity_late=%.6g pressure_left=%.6g pressure_right=%.6g "
            "max_penetration_over_h=%.4g\n",
            leak, late, pl, pr, max_pen);
        return 0;
      };
      if (coupling == "embedded") return run(pf::coupling::embedded{pf::porosity::impermeable{}});
      return run(pf::coupling::penalty{pf::porosity::impermeable{}, po});
    });
  });
}
