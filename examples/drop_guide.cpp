// The paper's parachute–payload drop built step by step (the program of docs/guide_drop.md).
//
//   drop_guide [--t-end T] [--out DIR]
//
// Scene model::drop_scene_parameters::paper("mat544") (8 gores, D0 = 1 m, payload 1.8 kg,
// 35 m up) released at 8 m/s straight down, so that the canopy is loaded within 0.2 s, on
// a tiny grid: canopy elements of D0/10, fluid cells of D0/5 around the canopy growing by
// 1.3 per cell outwards. Structure from structure::make_drop_assembly; a 5 D0 × 5 D0 × 7 D0
// box of air (model::make_drop_box) following the payload (frame::follow_payload), far
// field + sponge on all six faces, HLLC-LM + MUSCL (van Leer), inviscid, SSP-RK2; penalty
// coupling with the fabric's Ergun law; explicit_stepper. Writes DIR/history.csv (one row
// per 5 ms and the start; io::drop_observer, io::drop_history_writer) and DIR/summary.csv
// (columns: include/parafsi/io/drop_summary.hpp, docs/guide_drop.md); prints the last
// history row and the summary. The full program, with checkpoints, VTK output and
// mid-plane slices, is parachute_drop (scene::run_drop, include/parafsi/scene/drop.hpp),
// built from the same pieces.
#include <CLI/CLI.hpp>

#include <parafsi/coupling/coupling.hpp>
#include <parafsi/explicit_stepper.hpp>
#include <parafsi/io/drop_history.hpp>
#include <parafsi/model/drop_box.hpp>
#include <parafsi/parafsi.hpp>
#include <parafsi/scene/drop_steps.hpp>
#include <parafsi/structure/from_drop_scene.hpp>
#include "cli_checks.hpp"
#include "step_guard.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace pf = parafsi;
namespace io = parafsi::io;

int main(int argc, char** argv) {
  CLI::App app{"The paper's parachute-payload drop, built step by step on a tiny grid."};
  double t_end = 0.2;
  std::string out = "drop_guide";
  app.add_option("--t-end", t_end, "simulated time (s)")->check(CLI::Range(1e-3, 10.0))->capture_default_str();
  app.add_option("--out", out, "output directory (history.csv, summary.csv)")->capture_default_str();
  if (int rc = 0; !examples::parse(app, argc, argv, rc)) return rc;
  pf::parallel::set_threads(1);

  try {
    pf::require(std::isfinite(t_end), "--t-end must be a finite number, got ", t_end);  // Range lets NaN through
    // 1. Scene as plain data (SI): the paper's drop with the mat544 fabric, canopy elements
    //    of D0/10, released at 8 m/s (the paper releases at rest).
    auto P = pf::model::drop_scene_parameters::paper("mat544");
    const double D0 = P.canopy.nominal_diameter;  // 1 m
    P.canopy.element_size = D0 / 10.0;
    P.initial_speed = 8.0;
    const pf::model::drop_scene S = pf::model::build_drop_scene(P);

    // 2. Structure: nodes, canopy membrane (damping ratio 0.05 of its highest mode), lines,
    //    riser, tapes, bands and the payload; gravity set. Parts by name: riser(chute),
    //    payload(chute).body(), ...
    pf::structure::drop_assembly chute = pf::structure::make_drop_assembly(S, 0.05);

    // 3. Fluid box in box coordinates ξ (m): payload mass centre at ξ = 0, +z along the
    //    canopy axis. 5 D0 × 5 D0 cross-section, 7 D0 long, 1.5 D0 of it ahead of the
    //    payload (the defaults of drop_box_parameters); cells of D0/5 on the block around
    //    the canopy (|ξx|, |ξy| ≤ 0.6 D0, along the axis from zc + 0.55 Ls to
    //    zc + Ls + 0.55 D0, zc the confluence), growing by 1.3 per cell outwards.
    pf::model::drop_box_parameters bp;
    bp.cell = 0.2;  // D0/5 (drop_box_parameters are in units of D0)
    bp.growth = 1.3;
    const pf::model::drop_box box = pf::model::make_drop_box(S, bp);
    const pf::fluid::rectilinear_grid grid = pf::scene::make_drop_grid(box);  // axis::refined per axis
    const pf::fluid::prim<double> air{P.air_density, {0.0, 0.0, 0.0}, P.air_pressure};
    auto bc = pf::boundary::set::all(pf::boundary::far_field{air.rho, air.u, air.p});
    bc.layer = {3, 0.5};  // 3-cell sponge inside every face
    pf::frame::follow_payload follow;
    follow.axis = {0.0, 0.0, -1.0};  // box −z turns to the payload velocity
    follow.max_rate = 10.0;          // rad/s
    pf::fluid::solver fluid{
        grid, bc, pf::flux::hllc_lm{}, pf::recon::muscl<pf::limiter::van_leer>{}, pf::viscosity::inviscid{}, follow};
    fluid.initialize([&](const Eigen::Vector3d&) { return air; });
    // Pose: the box axes (box +z along the canopy axis), origin and velocity those of the payload.
    pf::scene::place_drop_box(fluid, box, chute);

    // 4. Coupling: penalty (PFAC 1, stiffening λ = 0.25), the leak through the fabric by its
    //    Ergun law (α, β, thickness of the paper's Table 2).
    pf::coupling::penalty_options po;
    po.pfac = 1.0;
    po.stiffening = 0.25;
    pf::coupling::penalty coupling{pf::porosity::ergun{S.fabric.alpha, S.fabric.beta, S.fabric.thickness}, po};

    // 5. The coupled stepper owns the three parts from here on. Its frame target moves the
    //    box after the payload: before every step, the payload's mass centre extrapolated to
    //    the end of the step under gravity, track(x + v dt, v + g dt).
    pf::explicit_stepper s{std::move(fluid), std::move(chute), std::move(coupling),
                           pf::follow_body{pf::scene::drop_payload_body{}, S.params.gravity}};
    const long cells = long(grid.n(0)) * grid.n(1) * grid.n(2);
    std::printf("drop_guide: %s, %ldx%ldx%ld = %ld cells, %ld nodes, %zu triangles, t_end %g s\n",
                std::string(S.fabric.name).c_str(), long(grid.n(0)), long(grid.n(1)), long(grid.n(2)), cells,
                long(s.structure().node_set().size()), S.triangles.size(), t_end);

    // 6. The time loop, up to an instant `target`. Each pass: the stable step (shortened to
    //    land on the target), the coupled step.
    const double cfl = 0.9;
    examples::step_guard guard("drop_guide", t_end);
    auto advance_to = [&](double target) {
      while (s.time() < target - 1e-12) {
        const double dt = pf::scene::landing_step(guard(s.stable_dt(cfl), s.time()), target - s.time());
        s.step(dt);
      }
    };

    // 7. Observables of one instant (definitions: io/drop_summary.hpp), one history row
    //    every 5 ms and at the start, then the summary.
    io::drop_observer observe(S);
    std::filesystem::create_directories(out);
    //    The riser force low-pass filtered (io/gaussian_filter.hpp, 10 Hz) is the last
    //    column: a row is written once the H rows after it exist, the last H at the end.
    io::drop_history_writer hist(std::filesystem::path(out) / "history.csv");
    std::vector<io::drop_history_row> history;
    const double every = 0.005;  // s
    io::summary_options so;      // the summary's filter is the history column's
    so.sample_interval = every;
    io::drop_history_filter filt(io::gaussian_lowpass(so.force_cutoff, every));
    auto record = [&] {
      history.push_back(observe(s.time(), s.structure()));
      for (const auto& r : filt.complete(history)) hist.write(r);
    };
    record();
    for (long n = 1; s.time() < t_end - 1e-12; ++n) {
      advance_to(std::min(every * double(n), t_end));
      record();
    }
    for (const auto& r : filt.finish(history)) hist.write(r);
    hist.close();

    // Summary of the history (summary.csv) and the last row on stdout.
    const io::drop_summary sum = io::summarize(history, std::string(S.fabric.name), so);
    io::write_drop_summary(std::filesystem::path(out) / "summary.csv", sum);
    const auto& e = history.back();
    std::printf("steps=%ld rows=%zu t=%.4f s z=%.4f m speed=%.4f m/s canopy_diameter=%.4f m open_force=%.3f N\n",
                s.steps(), history.size(), e.t, e.z, e.speed, e.canopy_diameter, e.open_force);
    std::printf("%s\n%s\n", io::drop_summary_header, sum.csv_row().c_str());
  } catch (const pf::numerical_failure& e) {
    std::fprintf(stderr, "drop_guide: %s (index %ld, t = %g s)\n", e.what(), e.index, e.t);
    return 1;
  } catch (const pf::error& e) {
    std::fprintf(stderr, "drop_guide: %s\n", e.what());
    return 1;
  } catch (const std::filesystem::filesystem_error& e) {
    std::fprintf(stderr, "drop_guide: %s\n", e.what());
    return 1;
  }
  return 0;
}
