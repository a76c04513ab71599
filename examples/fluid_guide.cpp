// Fluid-only stepper on a payload-following box (the program of docs/guide_fluid.md).
//
//   fluid_guide [--t-end T] [--speed V] [--drift D] [--h-fine H] [--cfl C] [--threads N] [--out FILE.csv]
//
// Air at rest; a prescribed payload falls at --speed m/s with a horizontal drift of
// --drift m/s. The box follows it (frame::follow_payload, its −z axis turned towards the
// payload's velocity); a momentum source of a bluff-body drag, spread over the cells
// within 0.3 m of the payload, pushes the air. Grid refined around the payload,
// far-field faces with a sponge, HLLC-LM + MUSCL (van Leer), Sutherland viscosity and
// Smagorinsky eddy viscosity, SSP-RK2. Prints the pose, the totals and the extreme
// pressures; with --out writes the line through the payload along the box z axis as
// CSV `xi_z,x,y,z,rho,ux,uy,uz,p` (box coordinate, inertial position, state).
#include <CLI/CLI.hpp>

#include <parafsi/io/checked_file.hpp>
#include <parafsi/parafsi.hpp>
#include "cli_checks.hpp"
#include "step_guard.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

namespace pf = parafsi;

int main(int argc, char** argv) {
  CLI::App app{"Fluid-only stepper on a box that follows a prescribed falling payload."};
  double t_end = 0.04, speed = 20.0, drift = 4.0, h_fine = 0.15, cfl = 0.5;
  int threads = 1;
  std::string out;
  app.add_option("--t-end", t_end, "simulated time (s)")->check(CLI::Range(0.0, 10.0))->capture_default_str();
  app.add_option("--speed", speed, "payload fall speed (m/s)")->check(CLI::Range(0.0, 100.0))->capture_default_str();
  app.add_option("--drift", drift, "payload horizontal speed (m/s)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  app.add_option("--h-fine", h_fine, "cell size around the payload (m)")
      ->check(CLI::Range(0.02, 0.5))
      ->capture_default_str();
  app.add_option("--cfl", cfl, "CFL number of the stable step")->check(CLI::Range(0.01, 1.0))->capture_default_str();
  app.add_option("--threads", threads, "OpenMP threads")->check(CLI::Range(1, 1024))->capture_default_str();
  app.add_option("--out", out, "CSV of the line through the payload along the box z axis");
  if (int rc = 0; !examples::parse(app, argc, argv, rc)) return rc;
  pf::parallel::set_threads(threads);

  try {
    // 1. Grid in box coordinates ξ (m): fine cells around the payload at ξ = 0, growing by
    //    20 % per cell outwards; the wake side (+z, behind the payload) is longer.
    const auto ax = pf::fluid::axis::refined(-2.0, 2.0, -0.5, 0.5, h_fine, 1.2);
    const auto az = pf::fluid::axis::refined(-2.0, 4.0, -0.5, 0.5, h_fine, 1.2);
    pf::fluid::rectilinear_grid grid{ax, ax, az};

    // 2. Boundaries: quiescent far field on all six faces, 3-cell sponge inside them.
    const pf::fluid::prim<double> air{1.18, {0.0, 0.0, 0.0}, 101325.0};
    auto bc = pf::boundary::set::all(pf::boundary::far_field{air.rho, air.u, air.p});
    bc.layer = {3, 0.5};

    // 3. Policies: values carry parameters, types carry choices; any order, defaults for
    //    the rest (here the time scheme: time::ssp_rk2).
    pf::frame::follow_payload follow;
    follow.axis = {0.0, 0.0, -1.0};  // box −z points along the payload's velocity
    follow.max_rate = 10.0;          // rad/s (cap on the turning rate)
    pf::fluid::solver s{grid,
                        bc,
                        pf::flux::hllc_lm{},
                        pf::recon::muscl<pf::limiter::van_leer>{},
                        pf::viscosity::sutherland{},
                        pf::turbulence::smagorinsky{},
                        follow};

    // 4. Initial state (ξ: cell centre in box coordinates) and pose.
    s.initialize([&](const Eigen::Vector3d&) { return air; });
    const Eigen::Vector3d x0{0.0, 0.0, 100.0}, v{drift, 0.0, -speed};
    auto payload = [&](double t) -> Eigen::Vector3d { return x0 + v * t; };
    s.pose().X = x0;
    s.pose().V = v;  // stable_dt() sees the box speed from the first step on
    s.enable_sources();

    // 5. The payload's drag on the air, F = ½ ρ C_d A |v| v (N), spread uniformly over the
    //    cells within 0.3 m of ξ = 0: a momentum source (N/m³) and its power f·u (W/m³).
    const double cd_area = 1.0 * 0.1, radius = 0.3;
    const Eigen::Vector3d force = 0.5 * air.rho * cd_area * v.norm() * v;
    double blob_volume = 0.0;
    auto for_blob = [&](auto&& f) {
      for (pf::index_t k = 0; k < grid.n(2); ++k)
        for (pf::index_t j = 0; j < grid.n(1); ++j)
          for (pf::index_t i = 0; i < grid.n(0); ++i) {
            const Eigen::Vector3d xi{grid.centre(0, i), grid.centre(1, j), grid.centre(2, k)};
            if (xi.norm() < radius) f(i, j, k);
          }
    };
    for_blob([&](pf::index_t i, pf::index_t j, pf::index_t k) { blob_volume += grid.cell_volume(i, j, k); });
    const Eigen::Vector3d f = force / blob_volume;
    auto set_sources = [&] {
      for_blob([&](pf::index_t i, pf::index_t j, pf::index_t k) {
        const pf::index_t c = s.index(i, j, k);
        const auto w = s.primitive(i, j, k);
        s.source(0)[c] = f.x();
        s.source(1)[c] = f.y();
        s.source(2)[c] = f.z();
        s.source(3)[c] = f.x() * w.u.x + f.y() * w.u.y + f.z() * w.u.z;
      });
    };

    // 6. The user's loop: stable step, target of the coming step, sources, step.
    const auto before = s.totals();
    examples::step_guard guard("fluid_guide", t_end);
    while (s.time() < t_end) {
      const double dt = std::min(guard(s.stable_dt(cfl), s.time()), t_end - s.time());
      s.frame().track(payload(s.time() + dt), v);
      set_sources();
      s.step(dt);
    }

    // 7. Results: pose, totals, extreme pressures.
    const auto after = s.totals();
    const Eigen::Vector3d axis = s.pose().R * follow.axis;
    const double angle = std::acos(std::clamp(axis.dot(v.normalized()), -1.0, 1.0));
    double p_min = 1e300, p_max = -1e300;
    for (pf::index_t k = 0; k < grid.n(2); ++k)
      for (pf::index_t j = 0; j < grid.n(1); ++j)
        for (pf::index_t i = 0; i < grid.n(0); ++i) {
          p_min = std::min(p_min, s.primitive(i, j, k).p);
          p_max = std::max(p_max, s.primitive(i, j, k).p);
        }
    std::printf("%s\n", s.name().c_str());
    std::printf("cells=%ldx%ldx%ld steps=%ld t=%.4f s\n", grid.n(0), grid.n(1), grid.n(2), s.steps(), s.time());
    std::printf("box_origin=(%.4f, %.4f, %.4f) m payload=(%.4f, %.4f, %.4f) m axis_to_velocity=%.2e rad\n",
                s.pose().X.x(), s.pose().X.y(), s.pose().X.z(), payload(s.time()).x(), payload(s.time()).y(),
                payload(s.time()).z(), angle);
    std::printf("momentum_change=(%.4e, %.4e, %.4e) N s mass_change=%.3e kg\n", after.momentum[0] - before.momentum[0],
                after.momentum[1] - before.momentum[1], after.momentum[2] - before.momentum[2],
                after.mass - before.mass);
    std::printf("p_min=%.2f Pa p_max=%.2f Pa\n", p_min, p_max);

    // 8. Optional CSV: the cells of the box z axis through the payload, placed in space.
    if (!out.empty()) {
      auto nearest = [&](int d) {
        pf::index_t best = 0;
        for (pf::index_t i = 1; i < grid.n(d); ++i)
          if (std::fabs(grid.centre(d, i)) < std::fabs(grid.centre(d, best))) best = i;
        return best;
      };
      const pf::index_t i = nearest(0), j = nearest(1);
      std::ostringstream csv;  // written through io::checked_file below
      csv.precision(12);
      csv << "xi_z,x,y,z,rho,ux,uy,uz,p\n";
      for (pf::index_t k = 0; k < grid.n(2); ++k) {
        const Eigen::Vector3d x = s.pose().to_inertial({grid.centre(0, i), grid.centre(1, j), grid.centre(2, k)});
        const auto w = s.primitive(i, j, k);
        csv << grid.centre(2, k) << ',' << x.x() << ',' << x.y() << ',' << x.z() << ',' << w.rho << ',' << w.u.x << ','
            << w.u.y << ',' << w.u.z << ',' << w.p << '\n';
      }
      pf::io::write_text_file(out, csv.str());
    }
  } catch (const pf::numerical_failure& e) {
    std::fprintf(stderr, "fluid_guide: %s (storage index %ld, t = %g s)\n", e.what(), e.index, e.t);
    return 1;
  } catch (const pf::error& e) {
    std::fprintf(stderr, "fluid_guide: %s\n", e.what());
    return 1;
  }
  return 0;
}
