/// \file drop_driver.hpp
/// The parachute drop as a function: `run_drop(config)` builds the scene of
/// model::drop_scene_parameters (paper() or c9()), the structure assembly, the following
/// fluid box and the coupled explicit_stepper, runs it to `t_end` and returns the
/// history (io::drop_history_row per output instant) and the summary; with `out` set it
/// writes history.csv, summary.csv and the mid-plane slices there. Shared by
/// examples/parachute_drop.cpp (the command line) and tests/test_drop_regression.cpp.
///
/// Scene: the model's values (released at rest from 35 m, flight path 90°, ρ = 1.18,
/// p = 101325, μ = 1.79e-5, g = 9.81 on the structure and payload only, payload 1.8 kg).
/// Fluid box: cross-section box_width × box_width D0, length box_length D0 with
/// box_ahead D0 ahead of the payload mass centre (ξ = 0); frame::follow_payload
/// translates it with the payload mass centre and turns its −z axis to the payload
/// velocity (track(x_next, v_next) every step). Cells of `cell`·D0 on the refined block
/// |ξx|, |ξy| ≤ 0.6 D0, ξz from 0.55 Ls above the confluence to 0.55 D0 above Ls (the
/// canopy), growing by `growth` per cell outwards; far field + 3-cell sponge on all six
/// faces. HLLC-LM + MUSCL (van Leer), SSP-RK2; constant μ or inviscid (`viscosity`).
/// Pressure-gradient scaling α (`pgs_alpha`; 0 = auto: 8 with the embedded coupling, 1 with
/// penalty, whose spring stiffness γp/α² it would soften): the air held at p/α².
/// Coupling: embedded (default) or penalty (PFAC, stiffening λ), both with the fabric's
/// Ergun law.
#pragma once
#include "example_common.hpp"

#include <parafsi/coupling/coupling.hpp>
#include <parafsi/explicit_stepper.hpp>
#include <parafsi/io/checkpoint.hpp>
#include <parafsi/io/drop_summary.hpp>
#include <parafsi/io/vtk.hpp>
#include <parafsi/model/drop_scene.hpp>
#include <parafsi/structure/from_drop_scene.hpp>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <optional>
#include <fstream>
#include <sstream>

namespace examples::drop {

namespace pf = parafsi;
namespace st = pf::structure;
namespace md = pf::model;
namespace io = pf::io;
using pf::index_t;

struct resolution {
  double element = 0.05;  ///< canopy element size / D0
  double cell = 0.10;     ///< fluid cell size around the canopy / D0
  double growth = 1.3;    ///< cell growth factor outside the refined block
};

/// draft: element D0/20, cell D0/10, growth 1.3 (17 576 cells; the packed canopy's mouth
/// spans two cells, too few for the embedded coupling to fill it reliably); coarse (the
/// default): D0/30, D0/15, growth 1.2 (54 872 cells); medium: D0/40, D0/20, growth 1.12
/// (about the paper's finest validation mesh, ≈ 1.5e5 cells); fine: D0/60, D0/30, growth
/// 1.1 (≈ 4.4e5 cells); tiny (tests): D0/10, D0/5, growth 1.3. docs/validation.md §8.
inline resolution preset(const std::string& name) {
  if (name == "draft") return {0.05, 0.10, 1.3};
  if (name == "medium") return {0.025, 0.05, 1.12};
  if (name == "fine") return {0.0167, 0.0333, 1.1};
  if (name == "tiny") return {0.1, 0.2, 1.3};
  pf::require(name == "coarse", "parachute_drop: unknown resolution '", name,
              "' (draft, coarse, medium, fine or tiny)");
  return {0.0333, 0.0667, 1.2};
}

struct drop_config {
  std::string canopy = "paper", fabric = "mat544", resolution = "coarse", coupling = "embedded";
  std::string viscosity = "auto";  ///< constant | inviscid | auto (inviscid at draft/coarse/tiny)
  double t_end = 6.0, history_every = 0.005;
  double box_width = 5.0, box_length = 7.0, box_ahead = 1.5, growth = 0, cfl = 0.9;  // growth 0: preset
  double pfac = 1.0, stiffening = 0.25, coupling_damping = 0.0, membrane_damping = 0.05;
  double impedance = 1.0;  ///< embedded: impedance (added-mass) stabilisation factor ζ
  double pgs_alpha = 0.0;  ///< pressure-gradient scaling α ≥ 1 (fluid/pressure_scaling.hpp), 1 = off; 0 = auto
  double cell = 0, element = 0;   ///< overrides of the preset (/ D0), 0 = preset
  double initial_speed = -1;      ///< override of the scene's release speed (m/s), < 0 = scene
  double payload_mass = -1;       ///< override of the payload mass (kg), < 0 = scene
  double line_stiffness = 1;      ///< multiplies EA of lines, riser and tapes (sensitivity, extremes)
  double modulus_scale = 1;       ///< multiplies the fabric moduli E11, E22, G12
  std::string packed = "scene";   ///< scene | reduced_radius | star_fold | constructed
  double packed_parameter = -1;   ///< reduced_radius: s; star_fold: seam half-angle (deg); < 0 = default
  std::string box = "follow";     ///< follow: the paper's moving box; fixed: a fixed box holding the fall
  double fixed_fall = 0;          ///< fixed box: fall length (m) the refined column extends below the start
  std::vector<double> slice_times;
  std::string out;                ///< output directory; empty: no files
  double vtk_every = 0;           ///< VTK (.vtu structure, .vts fluid, drop.pvd) interval (s), 0 = none
  double checkpoint_every = 0;    ///< checkpoint interval (s), 0 = none; file <out>/checkpoint.ckpt
  std::string restart;            ///< checkpoint to continue from (same scene and flags)
  bool quiet = false;
};

struct drop_result {
  std::string fabric;
  std::vector<io::drop_history_row> history;
  io::drop_summary summary;
  long cells = 0, nodes = 0, triangles = 0, steps = 0;
  double substeps_per_step = 0, wall = 0;
  pf::stepper_phase_times times{};
};

inline drop_result run_drop(const drop_config& c) {
    // ------------------------------------------------------------ scene (plain data)
    md::drop_scene_parameters P = c.canopy == "c9" ? md::drop_scene_parameters::c9() : md::drop_scene_parameters::paper(c.fabric);
    const double D0 = P.canopy.nominal_diameter;
    resolution R = preset(c.resolution);
    if (c.cell > 0) R.cell = c.cell;
    if (c.growth > 0) R.growth = c.growth;
    if (c.element > 0) R.element = c.element;
    if (c.initial_speed >= 0) P.initial_speed = c.initial_speed;
    if (c.payload_mass > 0) P.payload.mass = c.payload_mass;
    pf::require(c.line_stiffness > 0 && std::isfinite(c.line_stiffness),
                "parachute_drop: line stiffness scale must be > 0, got ", c.line_stiffness);
    for (auto* l : {&P.line, &P.skirt_tape, &P.vent_tape, &P.band}) l->stiffness_scale *= c.line_stiffness;
    pf::require(c.modulus_scale > 0 && std::isfinite(c.modulus_scale),
                "parachute_drop: fabric modulus scale must be > 0, got ", c.modulus_scale);
    P.moduli.modulus_scale *= c.modulus_scale;
    if (c.packed == "reduced_radius") P.shape = md::packed_shape::reduced_radius(c.packed_parameter > 0 ? c.packed_parameter : 0.2);
    else if (c.packed == "star_fold")
      P.shape = md::packed_shape::star_fold((c.packed_parameter >= 0 ? c.packed_parameter : 5.0) * std::numbers::pi / 180.0);
    else if (c.packed == "constructed") P.shape = md::packed_shape::constructed();
    else pf::require(c.packed == "scene", "parachute_drop: unknown packed shape '", c.packed, "'");
    pf::require(c.box == "follow" || c.box == "fixed", "parachute_drop: box must be follow or fixed, got '", c.box, "'");
    const bool fixed_box = c.box == "fixed";
    pf::require(!fixed_box || (c.fixed_fall > 0 && std::isfinite(c.fixed_fall)),
                "parachute_drop: a fixed box needs the fall length it must hold (> 0 m), got ", c.fixed_fall);
    P.canopy.element_size = R.element * D0;
    const md::drop_scene S = md::build_drop_scene(P);
    const std::string fabric_name(S.fabric.name);

    // ------------------------------------------------------------ structure
    auto chute = st::make_drop_assembly(S, c.membrane_damping);

    // ------------------------------------------------------------ fluid box
    // Box coordinates: payload mass centre at ξ = 0, box +z against the flight direction
    // (towards the canopy), so box −z follows the payload velocity.
    const double zc = (S.positions[std::size_t(S.suspension.confluence)] - S.payload.position).dot(S.axis()) / D0;
    // A fixed box (box = fixed) is the following box at the start, lengthened downwards
    // by the fall it must hold, with the refined column lengthened by the same amount.
    const double fall = fixed_box ? c.fixed_fall : 0.0;
    const double zlo = -c.box_ahead * D0 - fall, zhi = (c.box_length - c.box_ahead) * D0, half = 0.5 * c.box_width * D0;
    // Refined region: the canopy (radius ≤ 0.6 D0) from just below the skirt (the lines
    // meet the skirt about 0.94 Ls above the confluence) to above the inflated crown.
    const double rz0 = (zc + 0.55 * P.line_length_ratio) * D0 - fall, rz1 = (zc + 1.0 * P.line_length_ratio + 0.55) * D0;
    const double h = R.cell * D0;
    const auto ax = pf::fluid::axis::refined(-half, half, -0.6 * D0, 0.6 * D0, h, R.growth);
    const auto az = pf::fluid::axis::refined(zlo, zhi, std::max(zlo, rz0), std::min(zhi, rz1), h, R.growth);
    pf::fluid::rectilinear_grid grid{ax, ax, az};
    // Pressure-gradient scaling: the air is held at p∞/α² (sound speed c/α); outputs show
    // physical pressures p∞ + (q − p∞/α²).
    // α = 0: auto, 8 for the embedded coupling (docs/validation.md §8), 1 for penalty (its
    // spring stiffness PFAC γp A/h would fall as 1/α²).
    const double alpha = c.pgs_alpha == 0.0 ? (c.coupling == "embedded" ? 8.0 : 1.0) : c.pgs_alpha;
    const pf::fluid::pressure_gradient_scaling pgs{alpha};
    pgs.validate();
    // Guard: the scaled flow's Mach number αv/c, from the payload speed at every output.
    const double c_air = pf::gas::ideal{}.sound_speed(P.air_density, P.air_pressure);  // the solver's gas
    bool warned_mach = false;
    const double p_offset = pgs.pressure_offset(P.air_pressure);
    const pf::fluid::prim<double> air{P.air_density, {0.0, 0.0, 0.0}, pgs.scaled_ambient(P.air_pressure)};
    auto bc = pf::boundary::set::all(pf::boundary::far_field{air.rho, air.u, air.p});
    bc.layer = {3, 0.5};
    pf::frame::follow_payload follow;
    follow.axis = {0.0, 0.0, -1.0};
    follow.max_rate = 10.0;
    pf::viscosity::constant visc;
    visc.mu_value = P.air_viscosity;
    auto make_fluid = [&](auto viscosity, auto frame) {
      return pf::fluid::solver{grid, bc, pf::flux::hllc_lm{}, pf::recon::muscl<pf::limiter::van_leer>{}, viscosity,
                               frame};
    };
    auto with_frame = [&](auto viscosity, auto&& go) -> drop_result {
      if (fixed_box) return go(make_fluid(viscosity, pf::frame::fixed{}));
      return go(make_fluid(viscosity, follow));
    };
    auto with_fluid = [&](auto&& go) -> drop_result {
      if (c.viscosity == "inviscid" || (c.viscosity == "auto" && (c.resolution == "draft" || c.resolution == "coarse" || c.resolution == "tiny")))
        return with_frame(pf::viscosity::inviscid{}, go);
      return with_frame(visc, go);
    };
    return with_fluid([&](auto fl) -> drop_result {
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
    if (!fixed_box) fl.pose().V = chute.part<6>().body().mass_centre_velocity();
    if (pf::parallel::max_threads() > 1) fl.set_threading(true);
    const long ncells = long(grid.n(0)) * grid.n(1) * grid.n(2);

    const bool files = !c.out.empty();
    if (files) std::filesystem::create_directories(c.out);
    const std::vector<double>& slices = c.slice_times;

    // ------------------------------------------------------------ observables
    std::vector<Eigen::Vector3d> skirt_x(S.canopy.skirt.size());
    const double W_T = S.total_mass() * P.gravity, S0 = P.nominal_area();
    const index_t riser_last = index_t(S.cable(md::cable_kind::riser).segments.size()) - 1;

    auto run = [&](auto cpl) -> drop_result {
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
        std::ofstream os(c.out + "/" + name + ".csv");
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
               << w.p + p_offset << ',' << u.norm() << ',' << (u - vp).norm() << ',' << (dudz - dwdx) << '\n';
          }
        std::ofstream on(c.out + "/" + name + "_nodes.csv");
        on.precision(8);
        on << "xi,eta,zeta,canopy\n";
        for (index_t i = 0; i < nd.size(); ++i) {
          const Eigen::Vector3d xb = Rt * (X(i) - pose.X);
          on << xb.x() << ',' << xb.y() << ',' << xb.z() << ',' << (i < S.canopy_nodes ? 1 : 0) << '\n';
        }
      };

      drop_result res;
      // Restart: the stepper's full state from the checkpoint; the history rows up to the
      // restored time from <out>/history.csv.
      std::vector<io::drop_history_row> previous;
      if (!c.restart.empty()) {
        io::load_checkpoint(c.restart, s);
        {
          // The checkpoint holds the fluid, not the far field: a run restarted with another
          // α (or scene pressure) would put the restored air against a different ambient.
          const double q = s.fluid().primitive(0, 0, 0).p, q_inf = pgs.scaled_ambient(P.air_pressure);
          pf::require(q > 0.5 * q_inf && q < 2.0 * q_inf, "parachute_drop: checkpoint '", c.restart,
                      "' holds air at ", q, " Pa in a corner cell, but this run's ambient is ", q_inf,
                      " Pa (PGS alpha ", alpha, "): restart with the --pgs and scene of the run that wrote it");
        }
        std::ifstream in(c.out + "/history.csv");
        std::string line;
        std::getline(in, line);
        while (std::getline(in, line)) {
          std::array<double, io::drop_history_row::columns> v{};
          std::stringstream ls(line);
          std::string item;
          std::size_t k = 0;
          while (k < v.size() && std::getline(ls, item, ',')) v[k++] = item == "nan" ? NAN : std::stod(item);
          if (k == v.size() && v[0] <= s.time() + 1e-12) previous.push_back(io::drop_history_row::from(v));
        }
        if (!c.quiet) std::fprintf(stderr, "parachute_drop: restarted from %s at t = %.6g s (%zu history rows kept)\n",
                                   c.restart.c_str(), s.time(), previous.size());
      }
      std::ofstream hist;
      if (files) {
        hist.open(c.out + "/history.csv");
        if (!hist) throw pf::invalid_input("parachute_drop: cannot write '" + c.out + "/history.csv'");
        hist << io::drop_history_header << '\n';
        for (const auto& r : previous) io::write_history_row(hist, r);
      }
      res.history = previous;
      std::optional<io::pvd_writer> pvd;
      if (files && c.vtk_every > 0) {
        std::filesystem::create_directories(c.out + "/vtk");
        pvd.emplace(c.out + "/drop.pvd", c.restart.empty() ? NAN : s.time());
      }
      double next_vtk = s.time(), next_ckpt = s.time() + c.checkpoint_every;
      auto observers = [&] {
        if (pvd && s.time() >= next_vtk - 1e-9 * c.history_every) {
          char nm[64];
          std::snprintf(nm, sizeof nm, "%09.5f", s.time());
          const std::string fs = c.out + "/vtk/structure_" + nm + ".vtu", ff = c.out + "/vtk/fluid_" + nm + ".vts";
          io::write_vtu(fs, s.structure());
          io::vtk_options vo;
          vo.pressure_offset = p_offset;
          io::write_vts(ff, s.fluid(), vo);
          pvd->add(s.time(), ff, 0);
          pvd->add(s.time(), fs, 1);
          next_vtk += c.vtk_every;
        }
        if (files && c.checkpoint_every > 0 && s.time() >= next_ckpt - 1e-9 * c.history_every) {
          io::save_checkpoint(c.out + "/checkpoint.ckpt", s);
          next_ckpt += c.checkpoint_every;
        }
      };
      res.cells = ncells;
      res.nodes = long(nd.size());
      res.triangles = long(S.triangles.size());
      res.fabric = fabric_name;
      auto& history = res.history;
      auto record = [&] {
        history.push_back(observe());
        if (alpha > 1.0 && !warned_mach && !c.quiet && alpha * history.back().speed / c_air > 0.3) {
          warned_mach = true;
          std::fprintf(stderr,
                       "\nparachute_drop: warning: at t = %.3g s the payload moves at %.3g m/s, alpha M = %.2f > 0.3 with "
                       "PGS alpha %g: compressibility errors grow as (alpha M)^2; use --pgs %.0f or lower for this speed\n",
                       history.back().t, history.back().speed, alpha * history.back().speed / c_air, alpha,
                       std::max(1.0, std::floor(0.2 * c_air / history.back().speed)));
        }
        if (files) {
          io::write_history_row(hist, history.back());
          hist.flush();
        }
      };
      if (!c.quiet)
        std::fprintf(stderr,
                     "parachute_drop: %s canopy, %s, %s: %ld fluid cells (%ldx%ldx%ld, h = %.4g m near the canopy), "
                     "%ld structure nodes, %zu triangles, coupling %s, %s box, PGS alpha %g, t_end %.3g s\n",
                     P.name.c_str(), fabric_name.c_str(), c.resolution.c_str(), ncells, long(grid.n(0)),
                     long(grid.n(1)), long(grid.n(2)), h, long(nd.size()), S.triangles.size(), c.coupling.c_str(),
                     c.box.c_str(), alpha, c.t_end);
      if (c.restart.empty()) record();
      observers();
      examples::progress prog("parachute_drop", c.t_end, c.quiet);
      // Output times are n·history_every with an integer n (not a running sum), so a run
      // restarted from a checkpoint picks exactly the steps of the uninterrupted run.
      long n_out = long(std::floor(s.time() / c.history_every + 1e-6)) + 1;
      double next_out = c.history_every * double(n_out);
      std::size_t next_slice = 0;
      while (next_slice < slices.size() && slices[next_slice] <= s.time() + 1e-9 && !c.restart.empty()) ++next_slice;
      while (files && next_slice < slices.size() && slices[next_slice] <= 0) {
        write_slice(0.0);
        ++next_slice;
      }
      long substeps = 0;
      while (s.time() < c.t_end - 1e-12) {
        double dt = s.stable_dt(c.cfl);
        if (!(dt > 1e-9 * c.history_every) || !std::isfinite(dt))
          throw pf::numerical_failure(pf::detail::concat("parachute_drop: the stable step collapsed to ", dt,
                                                         " s at t = ", s.time(), " s (coupling ", c.coupling,
                                                         "); stopping"),
                                      -1, s.time());
        const double target = std::min(next_out, c.t_end);
        const double left = target - s.time();
        if (dt >= left * (1.0 - 1e-9)) dt = left;
        else if (dt > 0.5 * left) dt = 0.5 * left;
        const auto& body = as.template part<6>().body();
        const Eigen::Vector3d xp = body.mass_centre(), vp = body.mass_centre_velocity();
        const Eigen::Vector3d g{0, 0, -P.gravity};
        if constexpr (requires { s.fluid().frame().track(xp, vp); }) {
          s.fluid().frame().track(xp + vp * dt, vp + g * dt);
        } else {
          // Fixed box: stop with a message before the payload leaves the refined column.
          const Eigen::Vector3d xi = s.fluid().pose().R.transpose() * (xp - s.fluid().pose().X);
          if (xi.z() < -fall)
            throw pf::numerical_failure(pf::detail::concat("parachute_drop: the payload has fallen ", -xi.z(),
                                                           " m, beyond the fixed box's fall length ", fall,
                                                           " m, at t = ", s.time(), " s; raise --fixed-fall"),
                                        -1, s.time());
        }
        s.step(dt);
        substeps += s.last_substeps();
        if (s.time() >= next_out - 1e-9 * c.history_every || s.time() >= c.t_end - 1e-12) {
          record();
          observers();
          next_out = c.history_every * double(++n_out);
          while (files && next_slice < slices.size() && s.time() >= slices[next_slice] - 1e-9) {
            write_slice(slices[next_slice]);
            ++next_slice;
          }
        }
        prog(s.time(), s.steps());
      }
      prog.finish(s.time(), s.steps());
      if (files) hist.close();
      res.steps = s.steps();
      res.substeps_per_step = double(substeps) / double(std::max(1L, s.steps()));
      res.wall = prog.elapsed();
      res.times = s.timings();
      if (!c.quiet)
        std::fprintf(stderr,
                     "parachute_drop: %ld fluid steps, %.1f structure substeps per step; wall %.1f s (frame %.1f, "
                     "exchange %.1f, structure %.1f, fluid %.1f)\n",
                     res.steps, res.substeps_per_step, res.wall, res.times.move_frame, res.times.exchange,
                     res.times.structure, res.times.fluid);
      res.summary = io::summarize(history, fabric_name);
      if (files) {
        std::ofstream so(c.out + "/summary.csv");
        so << io::drop_summary_header << '\n' << res.summary.csv_row() << '\n';
      }
      return res;
    };
    const auto& fab = S.fabric;
    const pf::porosity::ergun law{fab.alpha, fab.beta, fab.thickness};
    if (c.coupling == "embedded") {
      pf::coupling::embedded_options eo;
      eo.impedance = c.impedance;
      return run(pf::coupling::embedded{law, eo});
    }
    pf::coupling::penalty_options po;
    po.pfac = c.pfac;
    po.stiffening = c.stiffening;
    po.damping_ratio = c.coupling_damping;
    return run(pf::coupling::penalty{law, po});
  });
}

}  // namespace examples::drop
