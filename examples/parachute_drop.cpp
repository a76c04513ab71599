// parachute_drop: the paper's parachute–payload drop (section 4) end to end.
//
//   parachute_drop [--canopy paper|c9] [--fabric mat544|mat59225|mat509]
//                  [--resolution coarse|medium|fine] [--t-end SECONDS]
//                  [--coupling penalty|embedded] [--out DIR] [--vtk-every SECONDS]
//                  [--checkpoint-every SECONDS] [--restart FILE] [--threads N]
//
// Scene (model::drop_scene_parameters::paper() / ::c9()): released at rest from 35 m,
// flight path 90°, air ρ = 1.18 kg/m³, p = 101325 Pa, μ = 1.79e-5 Pa s (air without
// gravity), g = 9.81 m/s² on the structure and the payload (1.8 kg). The fluid box
// (cross-section 5 D0 × 5 D0, length 7 D0; --box-width/--box-length) follows the payload:
// frame::follow_payload translates it with the payload mass centre and turns its −z axis
// to the payload velocity, tracked every step. Far field + sponge on all six faces; cells
// refined around the canopy (fluid cell = 2 × canopy element size there), growing by
// --growth outwards. HLLC-LM + MUSCL (van Leer), SSP-RK2, constant viscosity; penalty
// coupling with the fabric's Ergun law (docs/coupling.md).
//
// Writes in DIR: history.csv (one row per --history-every ≤ 5 ms), summary.csv, and
// mid-plane slices slice_<t>.csv (+ slice_<t>_nodes.csv) at --slice-times. Definitions:
// include/parafsi/io/drop_summary.hpp and docs/validation.md. Progress on stderr; the
// summary row on stdout at the end.
#include "example_common.hpp"

#include <parafsi/coupling/coupling.hpp>
#include <parafsi/explicit_stepper.hpp>
#include <parafsi/io/drop_summary.hpp>
#include <parafsi/model/drop_scene.hpp>

#include <filesystem>
#include <sstream>

namespace pf = parafsi;
namespace st = pf::structure;
namespace md = pf::model;
namespace io = pf::io;
using pf::index_t;

namespace {

struct resolution {
  double element = 0.05;  ///< canopy element size / D0
  double cell = 0.10;     ///< fluid cell size around the canopy / D0
};

resolution preset(const std::string& name) {
  if (name == "medium") return {0.025, 0.05};
  if (name == "fine") return {0.0167, 0.0333};
  if (name == "tiny") return {0.1, 0.2};
  return {0.05, 0.10};
}

std::vector<double> parse_list(const std::string& s) {
  std::vector<double> v;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) v.push_back(std::stod(item));
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Parachute-payload drop (the paper's section 4 scene): coupled fluid, canopy, lines and payload"};
  std::string canopy = "paper", fabric = "mat544", res_name = "coarse", coupling = "penalty", out = "out/drop";
  std::string restart, slice_times = "0.1,0.2,0.3,0.5,1,2,4,6";
  double t_end = 6.0, vtk_every = 0, checkpoint_every = 0, history_every = 0.005;
  double box_width = 5.0, box_length = 7.0, box_ahead = 1.5, growth = 1.3, cfl = 0.9;
  double pfac = 1.0, stiffening = 0.25, coupling_damping = 0.0, membrane_damping = 0.05;
  double h_cell = 0, h_element = 0;
  int threads = 0;
  bool quiet = false;
  std::string viscosity = "auto";
  app.add_option("--canopy", canopy, "scene: paper (section 4) or c9 (28-gore, 28 ft, deployed at 13.4 m/s)")
      ->check(CLI::IsMember({"paper", "c9"}))
      ->capture_default_str();
  app.add_option("--fabric", fabric, "canopy fabric of the paper's Table 2 (paper canopy)")
      ->check(CLI::IsMember({"mat544", "mat59225", "mat509"}))
      ->capture_default_str();
  app.add_option("--resolution", res_name,
                 "coarse (element D0/20, cell D0/10), medium (D0/40, D0/20), fine (D0/60, D0/30); tiny for tests")
      ->check(CLI::IsMember({"coarse", "medium", "fine", "tiny"}))
      ->capture_default_str();
  app.add_option("--t-end", t_end, "simulated time (s)")->check(CLI::Range(1e-4, 100.0))->capture_default_str();
  app.add_option("--coupling", coupling, "fluid-structure coupling: penalty (the paper's) or embedded")
      ->check(CLI::IsMember({"penalty", "embedded"}))
      ->capture_default_str();
  app.add_option("--out", out, "output directory")->capture_default_str();
  app.add_option("--vtk-every", vtk_every, "VTK output interval (s)")->check(CLI::Range(0.0, 100.0));
  app.add_option("--checkpoint-every", checkpoint_every, "checkpoint interval (s)")->check(CLI::Range(0.0, 100.0));
  app.add_option("--restart", restart, "restart from this checkpoint file");
  app.add_option("--threads", threads, "OpenMP threads (0: OMP_NUM_THREADS)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  app.add_option("--history-every", history_every, "history.csv row interval (s), at most 5 ms")
      ->check(CLI::Range(1e-5, 0.005))
      ->capture_default_str();
  app.add_option("--slice-times", slice_times, "times of the mid-plane slices (comma list, s; empty: none)")
      ->capture_default_str();
  app.add_option("--box-width", box_width, "box cross-section side / D0")->check(CLI::Range(2.0, 50.0))->capture_default_str();
  app.add_option("--box-length", box_length, "box length / D0")->check(CLI::Range(3.0, 100.0))->capture_default_str();
  app.add_option("--box-ahead", box_ahead, "box length ahead of the payload / D0")
      ->check(CLI::Range(0.3, 50.0))
      ->capture_default_str();
  app.add_option("--growth", growth, "cell growth factor outside the refined region")
      ->check(CLI::Range(1.0, 2.0))
      ->capture_default_str();
  app.add_option("--cell", h_cell, "override: fluid cell size around the canopy / D0")->check(CLI::Range(0.0, 1.0));
  app.add_option("--element", h_element, "override: canopy element size / D0")->check(CLI::Range(0.0, 1.0));
  app.add_option("--cfl", cfl, "CFL number of the fluid step")->check(CLI::Range(0.01, 1.0))->capture_default_str();
  app.add_option("--pfac", pfac, "penalty factor PFAC")->check(CLI::Range(1e-3, 1e3))->capture_default_str();
  app.add_option("--stiffening", stiffening, "penalty stiffening lambda (0 = off)")
      ->check(CLI::Range(0.0, 10.0))
      ->capture_default_str();
  app.add_option("--coupling-damping", coupling_damping, "penalty damping ratio")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--membrane-damping", membrane_damping, "membrane damping ratio (highest mode)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_flag("--quiet", quiet, "no progress on stderr");
  app.add_option("--viscosity", viscosity,
                 "air viscosity: constant (mu of the scene), inviscid, or auto (inviscid at coarse, else constant)")
      ->check(CLI::IsMember({"auto", "constant", "inviscid"}))
      ->capture_default_str();
  int rc = 0;
  if (!examples::parse(app, argc, argv, rc)) return rc;
  if (vtk_every > 0 || checkpoint_every > 0 || !restart.empty()) {
    std::fprintf(stderr,
                 "parachute_drop: error: --vtk-every, --checkpoint-every and --restart are not available yet "
                 "(the io/vtk, io/checkpoint headers are not in this version)\n");
    return 2;
  }
  if (threads > 0) pf::parallel::set_threads(threads);

  return examples::guarded("parachute_drop", [&]() -> int {
    // ------------------------------------------------------------ scene (plain data)
    md::drop_scene_parameters P = canopy == "c9" ? md::drop_scene_parameters::c9() : md::drop_scene_parameters::paper(fabric);
    const double D0 = P.canopy.nominal_diameter;
    resolution R = preset(res_name);
    if (h_cell > 0) R.cell = h_cell;
    if (h_element > 0) R.element = h_element;
    P.canopy.element_size = R.element * D0;
    const md::drop_scene S = md::build_drop_scene(P);
    const std::string fabric_name(S.fabric.name);

    // ------------------------------------------------------------ structure
    st::nodes nodes;
    for (std::size_t i = 0; i < S.positions.size(); ++i) nodes.add(S.positions[i], S.velocities[i], S.point_mass[i]);
    st::triangle_mesh tm;
    tm.triangles = S.triangles;
    tm.reference = S.reference;
    tm.warp_per_element = S.warp;
    const auto& m = S.moduli;
    st::membrane_tri membrane{tm, st::material::fabric<>{m.E11, m.E22, m.nu12, m.G12, m.areal_density, m.thickness},
                              st::membrane_options{membrane_damping}};
    auto part = [&](md::cable_kind k) {
      const auto& c = S.cable(k);
      return st::cable{st::line_mesh{c.segments, c.rest_length},
                       st::material::cable{c.material.EA(), c.material.mass_per_length, c.material.damping_ratio, 0.0}};
    };
    st::attachment payload{st::rigid_body{st::rigid_body::cuboid(S.payload.mass, S.payload.size), S.payload.position,
                                          S.payload.attitude, S.payload.velocity}};
    for (const auto& a : S.attachments) payload.attach(a.node, a.r_body);
    st::assembly chute{std::move(nodes),
                       std::move(membrane),
                       part(md::cable_kind::suspension_line),
                       part(md::cable_kind::riser),
                       part(md::cable_kind::skirt_tape),
                       part(md::cable_kind::vent_tape),
                       part(md::cable_kind::radial_band),
                       std::move(payload)};
    chute.integrator().gravity = {0, 0, -P.gravity};
    chute.finalize();

    // ------------------------------------------------------------ fluid box
    // Box coordinates: payload mass centre at ξ = 0, box +z against the flight direction
    // (towards the canopy), so box −z follows the payload velocity.
    const double zc = (S.positions[std::size_t(S.suspension.confluence)] - S.payload.position).dot(S.axis()) / D0;
    const double zlo = -box_ahead * D0, zhi = (box_length - box_ahead) * D0, half = 0.5 * box_width * D0;
    // Refined region: the canopy (radius ≤ 0.6 D0) from just below the skirt (the lines
    // meet the skirt about 0.94 Ls above the confluence) to above the inflated crown.
    const double rz0 = (zc + 0.55 * P.line_length_ratio) * D0, rz1 = (zc + 1.0 * P.line_length_ratio + 0.55) * D0;
    const double h = R.cell * D0;
    const auto ax = pf::fluid::axis::refined(-half, half, -0.6 * D0, 0.6 * D0, h, growth);
    const auto az = pf::fluid::axis::refined(zlo, zhi, std::max(zlo, rz0), std::min(zhi, rz1), h, growth);
    pf::fluid::rectilinear_grid grid{ax, ax, az};
    const pf::fluid::prim<double> air{P.air_density, {0.0, 0.0, 0.0}, P.air_pressure};
    auto bc = pf::boundary::set::all(pf::boundary::far_field{air.rho, air.u, air.p});
    bc.layer = {3, 0.5};
    pf::frame::follow_payload follow;
    follow.axis = {0.0, 0.0, -1.0};
    follow.max_rate = 10.0;
    pf::viscosity::constant visc;
    visc.mu_value = P.air_viscosity;
    auto make_fluid = [&](auto viscosity) {
      return pf::fluid::solver{grid, bc, pf::flux::hllc_lm{}, pf::recon::muscl<pf::limiter::van_leer>{}, viscosity,
                               follow};
    };
    auto with_fluid = [&](auto&& go) -> int {
      if (viscosity == "inviscid" || (viscosity == "auto" && (res_name == "coarse" || res_name == "tiny")))
        return go(make_fluid(pf::viscosity::inviscid{}));
      return go(make_fluid(visc));
    };
    return with_fluid([&](auto fl) -> int {
    fl.initialize([&](const Eigen::Vector3d&) { return air; });
    {
      // Box axes: +z along the canopy axis (against the flight direction).
      const Eigen::Vector3d zb = S.axis();
      Eigen::Vector3d xb = Eigen::Vector3d::UnitY().cross(zb);
      if (xb.norm() < 1e-9) xb = Eigen::Vector3d::UnitX();
      xb.normalize();
      const Eigen::Vector3d yb = zb.cross(xb);
      fl.pose().R.col(0) = xb;
      fl.pose().R.col(1) = yb;
      fl.pose().R.col(2) = zb;
    }
    fl.pose().X = chute.part<6>().body().mass_centre();
    fl.pose().V = chute.part<6>().body().mass_centre_velocity();
    if (pf::parallel::max_threads() > 1) fl.set_threading(true);
    const long ncells = long(grid.n(0)) * grid.n(1) * grid.n(2);

    std::filesystem::create_directories(out);
    const std::vector<double> slices = parse_list(slice_times);

    // ------------------------------------------------------------ observables
    std::vector<Eigen::Vector3d> skirt_x(S.canopy.skirt.size());
    const double W_T = S.total_mass() * P.gravity, S0 = P.nominal_area();
    const index_t riser_last = index_t(S.cable(md::cable_kind::riser).segments.size()) - 1;

    auto run = [&](auto cpl) -> int {
      pf::explicit_stepper s{std::move(fl), std::move(chute), std::move(cpl)};
      auto& as = s.structure();
      const auto& nd = as.node_set();
      auto X = [&](index_t i) { return nd.position(i); };
      auto vent_point = [&]() -> Eigen::Vector3d {
        if (S.canopy.vent_centre >= 0) return X(S.canopy.vent_centre);
        Eigen::Vector3d c = Eigen::Vector3d::Zero();
        for (index_t i : S.canopy.vent) c += X(i);
        return c / double(S.canopy.vent.size());
      };
      auto observe = [&]() {
        const auto& body = as.template part<6>().body();
        io::drop_history_row r;
        r.t = s.time();
        const Eigen::Vector3d x = body.mass_centre(), v = body.mass_centre_velocity();
        r.x = x.x(); r.y = x.y(); r.z = x.z();
        r.vx = v.x(); r.vy = v.y(); r.vz = v.z();
        r.speed = v.norm();
        for (std::size_t k = 0; k < skirt_x.size(); ++k) skirt_x[k] = X(S.canopy.skirt[k]);
        const Eigen::Vector3d conf = X(S.suspension.confluence), vent = vent_point();
        r.canopy_diameter = io::canopy_diameter(skirt_x, conf, vent);
        r.open_force = std::max(0.0, as.template part<2>().tension(nd, riser_last));
        const auto pa = io::axis_angles(body.rotation() * Eigen::Vector3d::UnitZ());
        const auto ca = io::axis_angles((vent - conf).normalized());
        r.payload_phi_x = pa[0]; r.payload_phi_y = pa[1];
        r.canopy_phi_x = ca[0]; r.canopy_phi_y = ca[1];
        r.flight_path_angle = io::flight_path_angle(v, P.flight_path_angle);
        r.drag_coefficient = io::drag_coefficient(W_T, P.air_density, r.speed, S0);
        for (index_t i = 0; i < nd.size(); ++i)
          if (!X(i).allFinite())
            throw pf::numerical_failure(pf::detail::concat("parachute_drop: structure node ", i,
                                                           " has a non-finite position at t = ", s.time(), " s"),
                                        long(i), s.time());
        return r;
      };
      auto write_slice = [&](double t_label) {
        const auto& f = s.fluid();
        const auto& g = f.grid();
        const auto& pose = f.pose();
        const Eigen::Matrix3d Rt = pose.R.transpose();
        pf::index_t j0 = 0;
        for (pf::index_t j = 1; j < g.n(1); ++j)
          if (std::fabs(g.centre(1, j)) < std::fabs(g.centre(1, j0))) j0 = j;
        const Eigen::Vector3d vp = as.template part<6>().body().mass_centre_velocity();
        auto ub = [&](pf::index_t i, pf::index_t k) {
          const auto w = f.primitive(i, j0, k);
          return Eigen::Vector3d(Rt * Eigen::Vector3d(w.u.x, w.u.y, w.u.z));
        };
        char name[64];
        std::snprintf(name, sizeof name, "slice_%06.3f", t_label);
        std::ofstream os(out + "/" + name + ".csv");
        os.precision(8);
        os << "xi,zeta,x,y,z,rho,p,speed,speed_rel,omega_n\n";
        const pf::index_t nx = g.n(0), nz = g.n(2);
        for (pf::index_t k = 0; k < nz; ++k)
          for (pf::index_t i = 0; i < nx; ++i) {
            const pf::index_t il = std::max<pf::index_t>(0, i - 1), ir = std::min(nx - 1, i + 1);
            const pf::index_t kl = std::max<pf::index_t>(0, k - 1), kr = std::min(nz - 1, k + 1);
            // ω_y (box) = ∂u_x/∂ζ − ∂u_z/∂ξ (the component normal to the plane).
            const double dudz = (ub(i, kr).x() - ub(i, kl).x()) / (g.centre(2, kr) - g.centre(2, kl));
            const double dwdx = (ub(ir, k).z() - ub(il, k).z()) / (g.centre(0, ir) - g.centre(0, il));
            const auto w = f.primitive(i, j0, k);
            const Eigen::Vector3d u(w.u.x, w.u.y, w.u.z);
            const Eigen::Vector3d xi(g.centre(0, i), g.centre(1, j0), g.centre(2, k));
            const Eigen::Vector3d x = pose.X + pose.R * xi;
            os << xi.x() << ',' << xi.z() << ',' << x.x() << ',' << x.y() << ',' << x.z() << ',' << w.rho << ','
               << w.p << ',' << u.norm() << ',' << (u - vp).norm() << ',' << (dudz - dwdx) << '\n';
          }
        std::ofstream on(out + "/" + name + "_nodes.csv");
        on.precision(8);
        on << "xi,eta,zeta,canopy\n";
        for (index_t i = 0; i < nd.size(); ++i) {
          const Eigen::Vector3d xb = Rt * (X(i) - pose.X);
          on << xb.x() << ',' << xb.y() << ',' << xb.z() << ',' << (i < S.canopy_nodes ? 1 : 0) << '\n';
        }
      };

      std::ofstream hist(out + "/history.csv");
      if (!hist) throw pf::invalid_input("parachute_drop: cannot write '" + out + "/history.csv'");
      hist << io::drop_history_header << '\n';
      std::vector<io::drop_history_row> history;
      auto record = [&] {
        history.push_back(observe());
        io::write_history_row(hist, history.back());
      };
      std::fprintf(stderr,
                   "parachute_drop: %s canopy, %s, %s: %ld fluid cells (%ldx%ldx%ld, h = %.4g m near the canopy), "
                   "%ld structure nodes, %zu triangles, coupling %s, t_end %.3g s\n",
                   P.name.c_str(), fabric_name.c_str(), res_name.c_str(), ncells, long(grid.n(0)), long(grid.n(1)),
                   long(grid.n(2)), h, long(nd.size()), S.triangles.size(), coupling.c_str(), t_end);
      record();
      examples::progress prog("parachute_drop", t_end, quiet);
      double next_out = history_every;
      std::size_t next_slice = 0;
      while (next_slice < slices.size() && slices[next_slice] <= 0) {
        write_slice(0.0);
        ++next_slice;
      }
      long substeps = 0;
      while (s.time() < t_end - 1e-12) {
        double dt = s.stable_dt(cfl);
        const double target = std::min(next_out, t_end);
        const double left = target - s.time();
        if (dt >= left * (1.0 - 1e-9)) dt = left;
        else if (dt > 0.5 * left) dt = 0.5 * left;
        const auto& body = as.template part<6>().body();
        const Eigen::Vector3d xp = body.mass_centre(), vp = body.mass_centre_velocity();
        const Eigen::Vector3d g{0, 0, -P.gravity};
        s.fluid().frame().track(xp + vp * dt, vp + g * dt);
        s.step(dt);
        substeps += s.last_substeps();
        if (s.time() >= next_out - 1e-9 * history_every || s.time() >= t_end - 1e-12) {
          record();
          next_out += history_every;
          while (next_slice < slices.size() && s.time() >= slices[next_slice] - 1e-9) {
            write_slice(slices[next_slice]);
            ++next_slice;
          }
        }
        prog(s.time(), s.steps());
      }
      prog.finish(s.time(), s.steps());
      hist.close();
      const auto& tm_ = s.timings();
      std::fprintf(stderr,
                   "parachute_drop: %ld fluid steps, %.1f structure substeps per step; wall %.1f s (frame %.1f, "
                   "exchange %.1f, structure %.1f, fluid %.1f)\n",
                   s.steps(), double(substeps) / double(std::max(1L, s.steps())), prog.elapsed(), tm_.move_frame,
                   tm_.exchange, tm_.structure, tm_.fluid);
      const io::drop_summary sum = io::summarize(history, fabric_name);
      std::ofstream so(out + "/summary.csv");
      so << io::drop_summary_header << '\n' << sum.csv_row() << '\n';
      so.close();
      std::printf("%s\n%s\n", io::drop_summary_header, sum.csv_row().c_str());
      return 0;
    };
    const auto& fab = S.fabric;
    const pf::porosity::ergun law{fab.alpha, fab.beta, fab.thickness};
    if (coupling == "embedded") return run(pf::coupling::embedded{law});
    pf::coupling::penalty_options po;
    po.pfac = pfac;
    po.stiffening = stiffening;
    po.damping_ratio = coupling_damping;
    return run(pf::coupling::penalty{law, po});
    });
  });
}
