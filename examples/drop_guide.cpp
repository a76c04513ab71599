// The paper's parachute–payload drop built step by step (the program of docs/guide_drop.md).
//
//   drop_guide [--t-end T] [--out DIR]
//
// Scene model::drop_scene_parameters::paper("mat544") (8 gores, D0 = 1 m, payload 1.8 kg,
// 35 m up) released at 8 m/s straight down, so that the canopy is loaded within 0.2 s, on
// a tiny grid: canopy elements of D0/10, fluid cells of D0/5 around the canopy growing by
// 1.3 per cell outwards. Structure from structure::make_drop_assembly; a 5 D0 × 5 D0 × 7 D0
// box of air following the payload (frame::follow_payload), far field + sponge on all six
// faces, HLLC-LM + MUSCL (van Leer), inviscid, SSP-RK2; penalty coupling with the fabric's
// Ergun law; explicit_stepper. Writes DIR/history.csv (one row per 5 ms and the start) and
// DIR/summary.csv (columns: include/parafsi/io/drop_summary.hpp, docs/guide_drop.md);
// prints the last history row and the summary. The full program, with checkpoints, VTK
// output and mid-plane slices, is parachute_drop (examples/drop_driver.hpp).
#include <CLI/CLI.hpp>
#include <parafsi/coupling/coupling.hpp>
#include <parafsi/explicit_stepper.hpp>
#include <parafsi/io/drop_summary.hpp>
#include <parafsi/parafsi.hpp>
#include <parafsi/structure/from_drop_scene.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
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
  CLI11_PARSE(app, argc, argv);
  pf::parallel::set_threads(1);

  try {
    // 1. Scene as plain data (SI): the paper's drop with the mat544 fabric, canopy elements
    //    of D0/10, released at 8 m/s (the paper releases at rest).
    auto P = pf::model::drop_scene_parameters::paper("mat544");
    const double D0 = P.canopy.nominal_diameter;  // 1 m
    P.canopy.element_size = D0 / 10.0;
    P.initial_speed = 8.0;
    const pf::model::drop_scene S = pf::model::build_drop_scene(P);

    // 2. Structure: nodes, canopy membrane (damping ratio 0.05 of its highest mode), lines,
    //    riser, tapes, bands and the payload; gravity set. Part 2 = riser, part 6 = payload.
    auto chute = pf::structure::make_drop_assembly(S, 0.05);

    // 3. Fluid box in box coordinates ξ (m): payload mass centre at ξ = 0, +z along the
    //    canopy axis. 5 D0 × 5 D0 cross-section, 7 D0 long, 1.5 D0 of it ahead of the
    //    payload; cells of D0/5 on the block around the canopy (|ξx|, |ξy| ≤ 0.6 D0, along
    //    the axis from zc + 0.55 Ls to zc + Ls + 0.55 D0, zc the confluence), growing by 1.3
    //    per cell outwards.
    const double h = D0 / 5.0, Ls = P.line_length();
    const double zc = (S.positions[std::size_t(S.suspension.confluence)] - S.payload.position).dot(S.axis());
    const auto ax = pf::fluid::axis::refined(-2.5 * D0, 2.5 * D0, -0.6 * D0, 0.6 * D0, h, 1.3);
    const auto az = pf::fluid::axis::refined(-1.5 * D0, 5.5 * D0, zc + 0.55 * Ls, zc + Ls + 0.55 * D0, h, 1.3);
    pf::fluid::rectilinear_grid grid{ax, ax, az};
    const pf::fluid::prim<double> air{P.air_density, {0.0, 0.0, 0.0}, P.air_pressure};
    auto bc = pf::boundary::set::all(pf::boundary::far_field{air.rho, air.u, air.p});
    bc.layer = {3, 0.5};  // 3-cell sponge inside every face
    pf::frame::follow_payload follow;
    follow.axis = {0.0, 0.0, -1.0};  // box −z turns to the payload velocity
    follow.max_rate = 10.0;          // rad/s
    pf::fluid::solver fluid{grid, bc, pf::flux::hllc_lm{}, pf::recon::muscl<pf::limiter::van_leer>{},
                            pf::viscosity::inviscid{}, follow};
    fluid.initialize([&](const Eigen::Vector3d&) { return air; });
    // Pose: box +z along the canopy axis, origin and velocity those of the payload.
    const Eigen::Vector3d zb = S.axis();
    Eigen::Vector3d xb = Eigen::Vector3d::UnitY().cross(zb);
    if (xb.norm() < 1e-9) xb = Eigen::Vector3d::UnitX();
    xb.normalize();
    fluid.pose().R.col(0) = xb;
    fluid.pose().R.col(1) = zb.cross(xb);
    fluid.pose().R.col(2) = zb;
    fluid.pose().X = chute.part<6>().body().mass_centre();
    fluid.pose().V = chute.part<6>().body().mass_centre_velocity();

    // 4. Coupling: penalty (PFAC 1, stiffening λ = 0.25), the leak through the fabric by its
    //    Ergun law (α, β, thickness of the paper's Table 2).
    pf::coupling::penalty_options po;
    po.pfac = 1.0;
    po.stiffening = 0.25;
    pf::coupling::penalty coupling{pf::porosity::ergun{S.fabric.alpha, S.fabric.beta, S.fabric.thickness}, po};

    // 5. The coupled stepper owns the three parts from here on.
    pf::explicit_stepper s{std::move(fluid), std::move(chute), std::move(coupling)};
    const long cells = long(grid.n(0)) * grid.n(1) * grid.n(2);
    std::printf("drop_guide: %s, %ldx%ldx%ld = %ld cells, %ld nodes, %zu triangles, t_end %g s\n",
                std::string(S.fabric.name).c_str(), long(grid.n(0)), long(grid.n(1)), long(grid.n(2)), cells,
                long(s.structure().node_set().size()), S.triangles.size(), t_end);

    // 6. The time loop, up to an instant `target`. Each pass: the stable step (shortened to
    //    land on the target), the box's target at the end of the step (the payload's
    //    position and velocity extrapolated under gravity), the coupled step.
    const double cfl = 0.9;
    const Eigen::Vector3d g{0.0, 0.0, -P.gravity};
    const auto& body = s.structure().part<6>().body();
    auto advance_to = [&](double target) {
      while (s.time() < target - 1e-12) {
        const double left = target - s.time();
        double dt = s.stable_dt(cfl);
        if (dt >= left * (1.0 - 1e-9)) dt = left;  // land on the target
        else if (dt > 0.5 * left) dt = 0.5 * left;  // no sliver of a step before it
        const Eigen::Vector3d x = body.mass_centre(), v = body.mass_centre_velocity();
        s.fluid().frame().track(x + v * dt, v + g * dt);
        s.step(dt);
      }
    };

    // 7. Observables of one instant (definitions: io/drop_summary.hpp), one history row
    //    every 5 ms and at the start, then the summary.
    const auto& nd = s.structure().node_set();
    const auto& riser = s.structure().part<2>();
    const pf::index_t riser_last = pf::index_t(S.cable(pf::model::cable_kind::riser).segments.size()) - 1;
    const double W_T = S.total_mass() * P.gravity, S0 = P.nominal_area();
    pf::require(S.canopy.vent_centre >= 0, "drop_guide: the canopy has no vent-centre node");
    std::vector<Eigen::Vector3d> skirt(S.canopy.skirt.size());
    auto observe = [&] {
      io::drop_history_row r;
      const Eigen::Vector3d x = body.mass_centre(), v = body.mass_centre_velocity();
      r.t = s.time();
      r.x = x.x(); r.y = x.y(); r.z = x.z();
      r.vx = v.x(); r.vy = v.y(); r.vz = v.z();
      r.speed = v.norm();
      for (std::size_t k = 0; k < skirt.size(); ++k) skirt[k] = nd.position(S.canopy.skirt[k]);
      const Eigen::Vector3d conf = nd.position(S.suspension.confluence), vent = nd.position(S.canopy.vent_centre);
      r.canopy_diameter = io::canopy_diameter(skirt, conf, vent);
      r.open_force = std::max(0.0, riser.tension(nd, riser_last));
      const auto pa = io::axis_angles(body.rotation() * Eigen::Vector3d::UnitZ());
      const auto ca = io::axis_angles((vent - conf).normalized());
      r.payload_phi_x = pa[0]; r.payload_phi_y = pa[1];
      r.canopy_phi_x = ca[0]; r.canopy_phi_y = ca[1];
      r.flight_path_angle = io::flight_path_angle(v, P.flight_path_angle);
      r.drag_coefficient = io::drag_coefficient(W_T, P.air_density, r.speed, S0);
      return r;
    };
    std::filesystem::create_directories(out);
    std::ofstream hist(out + "/history.csv");
    if (!hist) throw pf::invalid_input("drop_guide: cannot write '" + out + "/history.csv'");
    hist << io::drop_history_header << '\n';
    std::vector<io::drop_history_row> history;
    auto record = [&] {
      history.push_back(observe());
      io::write_history_row(hist, history.back());
    };
    const double every = 0.005;  // s
    record();
    for (long n = 1; s.time() < t_end - 1e-12; ++n) {
      advance_to(std::min(every * double(n), t_end));
      record();
    }
    hist.close();

    // Summary of the history (summary.csv) and the last row on stdout.
    const io::drop_summary sum = io::summarize(history, std::string(S.fabric.name));
    std::ofstream so(out + "/summary.csv");
    so << io::drop_summary_header << '\n' << sum.csv_row() << '\n';
    if (!so) throw pf::invalid_input("drop_guide: cannot write '" + out + "/summary.csv'");
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
