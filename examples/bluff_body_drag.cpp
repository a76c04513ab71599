// bluff_body_drag: a rigid impermeable disk normal to a uniform stream, or a
// hemispherical cup open towards it, held fixed (every node pinned) in air at U
// (default 40 m/s, Mach 0.12: low Mach, and half the acoustic steps of 20 m/s), run for
// --flow-times D/U (default 16). Prints `drag_coefficient=<Cd>`, the time-weighted mean
// over the second half of the run (t > t_end/2), and writes the CSV
// `t,drag_coefficient,side_force_y,side_force_z,probe_v,probe_w` (one row per fluid step). Default run (--cells 8):
// about a minute on one core.
//
// Drag = the force the coupling exerts on the body along the stream: the coupling's
// structure impulse of each step, Σ_nodes F·x̂ Δt̄ (pinned nodes included), divided by
// the step Δt_f, over ½ρU²A with A = πR² the frontal area (disk and cup alike).
//
// Set-up: body of diameter D = 0.2 m at the origin (disk in the plane x = 0; cup with
// its rim in x = 0 and its pole at x = +R, the concave side facing the oncoming air).
// Rectilinear grid with cells of D/N (N = --cells) in the box [−0.5D, 1.5D] × [−0.75D,
// 0.75D]², stretched by 15 % per cell out to [−2.5D, 5D] × [−2.5D, 2.5D]² (blockage πD²/4
// over 25D² = 3.1 %) by default: `--core-length`, `--core-width` (core) and `--domain-upstream`,
// `--domain-length`, `--domain-width` (box), in diameters ahead of and behind the body and from
// the axis, and `--stretch` (the growth) change it (coupling.md §8.1, §8.3); characteristic far
// field on all six faces with a 4-cell sponge towards the free stream (`--no-sponge`: none);
// impulsive start from the uniform stream. `--membrane-reconstruction one_sided` reconstructs
// the cells beside the body from their own side (the drop's default; first order by default
// here). HLLC-LM flux, MUSCL van Leer, SSP-RK2 (for inviscid air `--flux hllc` drops the
// low-Mach fix and `--limiter minmod` takes the more diffusive limiter: the scheme's
// dissipation in the wake, §8.2). Inviscid by default (separation fixed by the sharp edge);
// --reynolds RE switches on constant viscosity μ = ρUD/RE (laminar; no wall law, the boundary
// layer on the body is not resolved by either coupling). The penalty coupling uses PFAC = 1
// (as the other examples).
//
// Porous bodies: `--fabric mat544|mat59225|mat509` gives the body that fabric's Ergun law
// (the paper's Table 2), `--porous-resistance K` the quadratic loss law of a screen,
// Δp = K ½ρ u_n|u_n| (Ergun with α = 0, β t = K ρ / 2), u_n the through-velocity normal to
// the cloth. Then `through_fraction=` is also printed: the mean through-velocity over the
// body (the coupling's through-flow / its area) over U, averaged like the drag.
// With the embedded coupling `windward_cp=` and `leeward_cp=` are also printed: the body's
// wall pressures on its upstream and downstream sides along the stream (coupling::
// cloth_sides, gauge over ½ρU², averaged like the drag); their difference times the blocked
// area over πR² is the drag coefficient.
//
// `upstream_total_cp=` is the stream's total pressure one diameter ahead of the body on the
// axis (in the cell holding (−D, 0, 0): its centre within half a cell of that point, on the
// block mesh a leaf of whatever level is there), (p − p∞)/½ρU² + |u|²/U², averaged like the
// drag: 1 (to M²/4) in an unbounded stream; nan when that cell lies in the sponge.
// Above 1 the box feeds the body a stream with more than the free stream's total pressure: at
// low Mach number the characteristic far field holds the inflow's velocity (its ρc impedance
// lets a steady pressure rise move the velocity by only δp/ρc) and the sponge pulls the state
// back to the free stream, so the body's blockage pressure near an inflow face that is close
// becomes an excess of total pressure on the body's front (coupling.md §8.3: 1.19 with the
// default box at 8 cells per diameter and 40 m/s, 1.01 from 6 D upstream and ±5 D). The
// default box is the fast one, kept for the tables measured in it: past 4 D/U its runs warn
// (from 6 cells per diameter: at 4 and 5 the probe lies in the sponge and reads nan).
//
// The embedded coupling blocks whole grid faces: a face is a wall when the segment between
// its two cell centres crosses the body, so the body's frontal area is the count of
// stream-normal blocked faces times h², a staircase whose area differs from πR² by a
// few per cent, with the sign set by how the rim falls on the grid (on the tensor grid −8 % at
// 6 cells per diameter, where the axis runs through cell centres, +3.5 % at 8 and 16, −1 % at
// 12 and 24). The program prints
// `blocked_area_ratio=` (that area over πR²) and `drag_coefficient_on_blocked_area=` (the
// drag over ½ρU² times that area: the coefficient of the body the air sees).
//
// Wake: `--closure mixing_length|smagorinsky` adds that eddy viscosity to the air's
// (μ = 1.79e-5 Pa s unless --reynolds sets it; mixing length l_m = min(κ d_w, 0.07 D, Δ),
// d_w from the body's nodes; Smagorinsky C_s = 0.1; μ_t ≤ 1000 μ, as the drop scene).
// `--kick F` starts the air with a transverse velocity F·U along y (the far field then
// washes it out), breaking the set-up's symmetry so that a wake that can shed does. The CSV
// also has the side-force coefficients (y, z, over ½ρU²A; zero on the flat disk, whose
// inviscid load is normal to it) and the transverse velocity (v, w)/U of a wake probe on
// the axis 2D behind the rim plane (a hot wire's place). The program prints `strouhal=`
// f D/U of the probe's dominant frequency over the second half (io/spectrum.hpp: the
// summed spectrum of v and w, St in [0.02, 2]), `probe_amplitude=` its amplitude (/U) and
// `shedding_periods=` the periods of that frequency the second half holds; `strouhal=none`
// when the probe's amplitude is below 0.01 U (a steady wake) or the record holds fewer than
// three periods (a drift, not a measurement).
//
// Mesh: `--mesh tensor` (default) is the stretched rectilinear grid above. `--mesh blocks`
// puts the same box on the block-structured mesh (fluid/block_solver.hpp; blocks of
// --block-size³ cells): the finest level, cells of D/N, on every block that meets the core
// [−0.5D, core-length] × [−core-width, core-width]², each coarser level a ring at least one
// block thick (the 2:1 balance), the root blocks at most half the box's narrowest side. The
// root grid has block faces on x = −0.5D and on the axis, so the finest cells lie where the
// tensor grid's core cells do when the axis is a face line there (even N); the box is grown to whole root blocks
// (upstream from −0.5D, laterally about the axis) and the sponge is the whole number of root cells closest to 1.2 D
// (the tensor grid's 4 outer cells span 0.95-1.34 D across the stream in the default box). The mesh is built once,
// before the first step (the body is fixed), so the cells are where the wake needs them at a fraction of the tensor
// grid's count (0.65 at 16 cells per diameter, 0.43 at 24) (coupling.md §8.2).
#include "example_common.hpp"

#include <parafsi/coupling/coupling.hpp>
#include <parafsi/explicit_stepper.hpp>
#include <parafsi/io/spectrum.hpp>
#include <parafsi/model/disk_mesh.hpp>
#include <parafsi/model/fabric_catalogue.hpp>

#include <limits>
#include <numbers>

namespace pf = parafsi;
namespace st = pf::structure;

namespace {

/// The block mesh's layout (see the file comment): blocks of n³ cells, the finest cell h
/// on level L, L the largest that leaves at least two root blocks (n 2^L h) across the
/// box's narrowest side; root faces on x = −0.5 D and on the axis, the box grown to whole
/// root blocks: upstream to at least −`upstream` D, downstream to `length` D, laterally to
/// ±`width` D. Returns the layout and L.
std::pair<pf::fluid::block_layout, int> core_blocks(double D, double h, int n, double length, double width,
                                                    double upstream) {
  const double narrow = std::min(2.0 * width * D, (upstream + length) * D);
  const int L = std::max(0, int(std::floor(std::log2(narrow / (2.0 * n * h) + 1e-9))));
  if (L > pf::fluid::blocks::tree::max_depth)
    throw std::invalid_argument("bluff_body_drag: " + std::to_string(L) + " levels are too many (fewer --cells)");
  const double root = double(n) * h * std::ldexp(1.0, L);
  const auto whole = [&](double span) { return pf::index_t(std::ceil(span / root - 1e-9)); };
  pf::fluid::block_layout lay;
  lay.block_cells = n;
  const pf::index_t up = whole(std::max(upstream - 0.5, 0.5) * D), down = whole((length + 0.5) * D),
                    side = whole(width * D);
  lay.lo = {-0.5 * D - double(up) * root, -double(side) * root, -double(side) * root};
  lay.hi = {-0.5 * D + double(down) * root, double(side) * root, double(side) * root};
  lay.root_blocks = {up + down, 2 * side, 2 * side};
  for (pf::index_t nb : lay.root_blocks)
    if (nb > pf::fluid::blocks::tree::max_root)
      throw std::invalid_argument("bluff_body_drag: " + std::to_string(nb) +
                                  " root blocks on an axis, more than the tree holds (a smaller box)");
  return {lay, L};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Drag of a fixed disk or hemispherical cup in a uniform stream (penalty or embedded coupling)"};
  examples::common_options co;
  std::string shape = "disk", coupling = "embedded", out, fabric = "none", closure = "none", mesh = "tensor";
  std::string membrane_reconstruction = "first_order";
  int block_size = 8;
  double U = 40.0, Re = 0.0, pfac = 1.0, t_end = -1.0, flow_times = 16.0, resistance = 0.0, kick = 0.0;
  // The grid, in diameters: uniform cells of D/N in [-0.5, core_length] x [-core_width, core_width]^2,
  // stretched out to [-domain_upstream, domain_length] x [-domain_width, domain_width]^2.
  double core_length = 1.5, core_width = 0.75, domain_length = 5.0, domain_width = 2.5, stretch = 1.15,
         domain_upstream = 2.5;
  bool no_sponge = false;
  int cells = 8;
  examples::add_run_options(app, co);
  app.add_option("--shape", shape, "disk (flat, normal to the stream) or cup (hemisphere, open towards the stream)")
      ->check(CLI::IsMember({"disk", "cup"}))
      ->capture_default_str();
  app.add_option("--coupling", coupling,
                 "coupling method: penalty (the paper's) or embedded (membrane-aware face fluxes)")
      ->check(CLI::IsMember({"penalty", "embedded"}))
      ->capture_default_str();
  app.add_option("--membrane-reconstruction", membrane_reconstruction,
                 "embedded: the cells beside the body reconstructed from their own side (one_sided, second order up "
                 "to the wall) or first order")
      ->check(CLI::IsMember({"first_order", "one_sided"}))
      ->capture_default_str();
  examples::add_cells_option(app, cells, "fluid cells across the body diameter D = 0.2 m", 4);
  app.add_option("--velocity", U, "free-stream velocity U (m/s)")->check(CLI::Range(1.0, 100.0))->capture_default_str();
  app.add_option("--reynolds", Re, "Reynolds number U D / nu (sets a constant viscosity; 0 = inviscid)")
      ->check(CLI::Validator(
          [](std::string& s) {
    double v = 0;
    if (CLI::detail::lexical_cast(s, v) && (v == 0 || (v >= 1 && v <= 1e9))) return std::string();
    return "Reynolds number " + s + " is neither 0 (inviscid) nor in [1, 1e9]";
          },
          "0 or [1 - 1e9]"))
      ->capture_default_str();
  auto* fab_opt = app.add_option("--fabric", fabric, "porous body: the Ergun law of this fabric (none: impermeable)")
                      ->check(CLI::IsMember({"none", "mat544", "mat59225", "mat509"}))
                      ->capture_default_str();
  app.add_option("--porous-resistance", resistance,
                 "porous body with the loss law dp = K rho u_n|u_n| / 2 of this K (0: impermeable)")
      ->check(examples::finite)
      ->check(CLI::Range(0.0, 1e6))
      ->excludes(fab_opt)
      ->capture_default_str();
  app.add_option("--closure", closure,
                 "eddy-viscosity closure of the wake: none, mixing_length (Prandtl's, distance to the body) or "
                 "smagorinsky; with a closure the air has its viscosity (1.79e-5 Pa s unless --reynolds)")
      ->check(CLI::IsMember({"none", "mixing_length", "smagorinsky"}))
      ->capture_default_str();
  app.add_option("--kick", kick, "initial transverse velocity along y as a fraction of U (breaks the symmetry)")
      ->check(examples::finite)
      ->check(CLI::Range(0.0, 0.5))
      ->capture_default_str();
  app.add_option("--core-length", core_length, "downstream end of the uniform-cell core (diameters behind the body)")
      ->check(CLI::Range(0.5, 50.0))
      ->capture_default_str();
  app.add_option("--core-width", core_width, "half-width of the uniform-cell core (diameters from the axis)")
      ->check(CLI::Range(0.6, 20.0))
      ->capture_default_str();
  app.add_option("--domain-length", domain_length,
                 "downstream end of the box (diameters behind the body; the wake probe is at 2)")
      ->check(CLI::Range(2.5, 200.0))
      ->capture_default_str();
  app.add_option("--domain-width", domain_width, "half-width of the box (diameters from the axis)")
      ->check(CLI::Range(1.0, 100.0))
      ->capture_default_str();
  app.add_option("--domain-upstream", domain_upstream,
                 "upstream end of the box (diameters ahead of the body; the far field there holds the inflow)")
      ->check(CLI::Range(1.0, 200.0))
      ->capture_default_str();
  app.add_flag("--no-sponge", no_sponge,
               "no sponge layer inside the far-field faces (the characteristic far field alone)");
  app.add_option("--stretch", stretch, "growth of the cells outside the core, per cell")
      ->check(CLI::Range(1.0, 1.5))
      ->capture_default_str();
  app.add_option("--mesh", mesh,
                 "fluid mesh: tensor (the stretched rectilinear grid) or blocks (the block-structured mesh, the "
                 "finest level on the core)")
      ->check(CLI::IsMember({"tensor", "blocks"}))
      ->capture_default_str();
  app.add_option("--block-size", block_size, "cells per block edge (--mesh blocks)")
      ->check(CLI::IsMember({4, 8, 16, 32}))
      ->capture_default_str();
  app.add_option("--flux", co.flux,
                 "Riemann flux: hllc_lm (HLLC with the low-Mach fix) or hllc (without it); inviscid air only")
      ->check(CLI::IsMember({"hllc_lm", "hllc"}))
      ->capture_default_str();
  app.add_option("--limiter", co.limiter, "MUSCL limiter: van_leer or minmod (more diffusive); inviscid air only")
      ->check(CLI::IsMember({"van_leer", "minmod"}))
      ->capture_default_str();
  app.add_option("--pfac", pfac, "penalty factor PFAC (penalty coupling)")
      ->check(CLI::Range(1e-4, 1e3))
      ->capture_default_str();
  app.add_option("--flow-times", flow_times, "run length in flow-through times D/U (ignored with --time)")
      ->check(CLI::Range(0.5, 1000.0))
      ->capture_default_str();
  app.add_option("--time", t_end, "simulated time (s); default flow-times * D/U")->check(CLI::Range(1e-5, 10.0));
  examples::add_out_option(app, out);
  int rc = 0;
  if (!examples::parse(app, argc, argv, rc)) return rc;
  examples::apply_threads(co);
  return examples::guarded("bluff_body_drag", [&]() -> int {
    const double D = 0.2, R = 0.5 * D, rho = 1.18, p0 = 101325.0, h = D / cells;
    if (t_end <= 0) t_end = flow_times * D / U;
    const double t_avg = 0.5 * t_end;
    const double area = std::numbers::pi * R * R, qA = 0.5 * rho * U * U * area;
    // Grid refined around the body.
    // The stretched part is empty or at least one core cell wide (no sliver cell that would
    // cut the time step).
    const auto gap_ok = [&](double core, double box) { return core == box || (box - core) * cells >= 1.0 - 1e-9; };
    if (!gap_ok(core_length, domain_length) || !gap_ok(core_width, domain_width))
      throw std::invalid_argument("bluff_body_drag: the core (--core-length " + std::to_string(core_length) +
                                  ", --core-width " + std::to_string(core_width) +
                                  ") must end at the box (--domain-length, --domain-width) or at least one cell "
                                  "(1/" +
                                  std::to_string(cells) + " D) inside it");
    using pf::fluid::axis;
    const auto lateral = axis::refined(-domain_width * D, domain_width * D, -core_width * D, core_width * D, h,
                                       stretch);
    auto grid = pf::fluid::rectilinear_grid{axis::refined(-domain_upstream * D, domain_length * D, -0.5 * D,
                                                          core_length * D, h, stretch),
                                            lateral, lateral};
    pf::boundary::set bc = pf::boundary::set::all(pf::boundary::far_field{rho, {U, 0, 0}, p0});
    bc.layer.cells = no_sponge ? 0 : 4;
    if (grid.interior_cells() > 200'000'000)
      throw std::invalid_argument("bluff_body_drag: the grid has " + std::to_string(grid.interior_cells()) +
                                  " cells, more than 2e8 (fewer --cells, a smaller box or more --stretch)");
    // Body: disk triangulation (normal +z) turned to face the stream, or mapped onto the
    // hemisphere by equal meridian arc (polar angle θ = (r/R)·π/2, pole at x = +R).
    const int rings = std::max(2, (shape == "cup" ? 3 : 2) * cells / 4);
    const auto dm = pf::model::disk_mesh(R, rings);
    st::nodes nd;
    for (const auto& p : dm.positions) {
      if (shape == "disk") {
        nd.add(Eigen::Vector3d(0.0, p.x(), p.y()));
      } else {
        const double r = std::hypot(p.x(), p.y()), phi = std::atan2(p.y(), p.x());
        const double th = std::min(1.0, r / R) * 0.5 * std::numbers::pi;
        nd.add(Eigen::Vector3d(R * std::cos(th), R * std::sin(th) * std::cos(phi), R * std::sin(th) * std::sin(phi)));
      }
    }
    for (pf::index_t i = 0; i < nd.size(); ++i) nd.pin(i);
    st::triangle_mesh tm;
    tm.triangles = dm.triangles;
    st::membrane_tri mem{tm, st::material::fabric<>::isotropic(3e8, 0.3, 0.054, 1.1e-4)};
    st::assembly as{std::move(nd), std::move(mem)};
    as.integrator().gravity = {0, 0, 0};
    const double mu = Re > 0 ? rho * U * D / Re : (closure != "none" ? 1.79e-5 : 0.0);
    if (mu > 0 && (co.flux != "hllc_lm" || co.limiter != "van_leer"))
      throw std::invalid_argument(
          "bluff_body_drag: --flux and --limiter other than hllc_lm and van_leer need "
          "inviscid air (no --reynolds, --closure none)");
    if (!co.quiet)
      std::fprintf(
          stderr,
          "bluff_body_drag: %s, %s coupling, D = %g m, U = %g m/s, h = D/%d, %s grid %lld x %lld x %lld = "
          "%lld cells (core to %g D behind, +-%g D; box from %g D ahead to %g D behind, +-%g D, blockage %.2g %%%s), "
          "%zu triangles, "
          "t_end = %g s (%g D/U), %s\n",
          shape.c_str(), coupling.c_str(), D, U, cells, mesh == "tensor" ? "mesh: tensor" : "(the tensor mesh's)",
          (long long)grid.n(0), (long long)grid.n(1), (long long)grid.n(2), (long long)grid.interior_cells(),
          core_length, core_width, domain_upstream, domain_length, domain_width,
          100.0 * std::numbers::pi / 16.0 / (domain_width * domain_width), no_sponge ? ", no sponge" : "",
          dm.triangles.size(), t_end, t_end * U / D,
          mu > 0 ? ("Re = " + std::to_string(rho * U * D / mu) + ", closure " + closure).c_str() : "inviscid");

    // Wake probe: the cell holding (2D, 0, 0).
    const Eigen::Vector3d probe_point(2 * D, 0.0, 0.0);
    // Upstream probe: the cell holding (−D, 0, 0), the stream's total pressure one diameter ahead.
    const Eigen::Vector3d ahead_point(-D, 0.0, 0.0);
    std::array<pf::index_t, 3> probe{}, ahead{};
    for (int d = 0; d < 3; ++d) {
      const auto& f = grid.axis_of(d).faces;
      probe[std::size_t(d)] = pf::index_t(std::upper_bound(f.begin(), f.end(), probe_point[d]) - f.begin()) - 1;
      ahead[std::size_t(d)] = pf::index_t(std::upper_bound(f.begin(), f.end(), ahead_point[d]) - f.begin()) - 1;
    }
    if (mesh == "tensor" && probe[0] >= grid.n(0) - bc.layer.cells)
      throw std::invalid_argument("bluff_body_drag: the wake probe at 2 D lies in the far-field sponge (the last " +
                                  std::to_string(bc.layer.cells) + " cells); lengthen the box (--domain-length)");
    if (mesh == "tensor" && bc.layer.cells > 0 && grid.axis_of(0).faces[std::size_t(bc.layer.cells)] > -0.5 * D)
      throw std::invalid_argument("bluff_body_drag: the far-field sponge (the first " + std::to_string(bc.layer.cells) +
                                  " cells) reaches the air just upstream of the body; lengthen the box "
                                  "(--domain-upstream)");
    // The sponge across the stream reaching the rim (a narrow box), as the block mesh checks.
    for (int d = 1; mesh == "tensor" && bc.layer.cells > 0 && d < 3; ++d) {
      const auto& f = grid.axis_of(d).faces;
      if (f[std::size_t(bc.layer.cells)] > -0.5 * D || f[f.size() - 1 - std::size_t(bc.layer.cells)] < 0.5 * D)
        throw std::invalid_argument(
            "bluff_body_drag: the far-field sponge reaches the body's rim; widen the box (--domain-width)");
    }
    // The upstream probe inside the sponge (a short box at few cells per diameter) reads the
    // sponge's state, not the stream's: it is then reported as nan.
    bool ahead_in_sponge = false;
    for (int d = 0; mesh == "tensor" && d < 3; ++d)
      ahead_in_sponge = ahead_in_sponge || ahead[std::size_t(d)] < bc.layer.cells ||
                        ahead[std::size_t(d)] >= grid.n(d) - bc.layer.cells;
    if (coupling != "embedded" && membrane_reconstruction != "first_order")
      throw std::invalid_argument("bluff_body_drag: --membrane-reconstruction one_sided needs --coupling embedded");
    auto run_with = [&](auto fl) -> int {
      using Fluid = decltype(fl);
      constexpr bool blocks = requires { fl.tree(); };
      fl.fill_uniform({rho, {U, kick * U, 0}, p0});
      if constexpr (blocks) {
        // The sponge counts root cells, so on a narrow box it can reach the body itself.
        for (const Eigen::Vector3d& x :
             {Eigen::Vector3d(0, 0.5 * D, 0), Eigen::Vector3d(0, 0, 0.5 * D), Eigen::Vector3d(-0.5 * D, 0, 0)}) {
          const auto [bx, cx] = fl.locate(x);
          if (bx < 0 || fl.sponge_rate(bx, cx) > 0.0)
            throw std::invalid_argument(
                "bluff_body_drag: the far-field sponge reaches the body's rim or the air just upstream of it; widen "
                "the box (--domain-width)");
        }
        {
          const auto [ba, ca] = fl.locate(ahead_point);
          ahead_in_sponge = ba < 0 || fl.sponge_rate(ba, ca) > 0.0;
        }
        const auto [b, c] = fl.locate(probe_point);
        if (b < 0 || fl.sponge_rate(b, c) > 0.0)
          throw std::invalid_argument(
              "bluff_body_drag: the wake probe at 2 D lies in the far-field sponge; lengthen the box "
              "(--domain-length)");
        if (parafsi::parallel::max_threads() > 1) fl.set_threading(true);
      }
      if constexpr (Fluid::needs_wall_distance) {
        std::vector<Eigen::Vector3d> pts(std::size_t(as.node_set().size()));
        for (pf::index_t i = 0; i < as.node_set().size(); ++i) pts[std::size_t(i)] = as.node_set().position(i);
        // Each block within the closure's reach for its own cells (the same eddy viscosity).
        fl.wall_distance_from(pts);
      }
      auto run = [&](auto cpl) -> int {
        pf::explicit_stepper s{std::move(fl), std::move(as), std::move(cpl)};
        examples::csv_writer csv(out, "t,drag_coefficient,side_force_y,side_force_z,probe_v,probe_w");
        std::vector<double> ts, pv, pw;  // the second half, for the probe's spectrum
        examples::progress prog("bluff_body_drag", t_end, co.quiet);
        double sum = 0, sum_t = 0, sum_p0 = 0, max_pen = 0, sum_q = 0, blocked_area = 0, sum_w = 0, sum_l = 0;
        constexpr bool sides = requires { s.coupling().cloth_sides(Eigen::Vector3d::UnitX()); };
        examples::step_guard guard("bluff_body_drag", t_end);
        while (s.time() < t_end * (1.0 - 1e-12)) {
          double dt = guard(s.stable_dt(co.cfl), s.time());
          const double left = t_end - s.time();
          if (dt >= left * (1.0 - 1e-12)) dt = left;
          else if (dt > 0.5 * left) dt = 0.5 * left;
          const double t0 = s.time();
          s.step(dt);
          max_pen = std::max(max_pen, s.coupling().diagnostics().max_penetration_over_h);
          // The embedded body blocks whole faces (those whose cell-centre segment it
          // crosses): its frontal area is the stream-normal blocked faces' area, not πR².
          // Fixed body: the same faces every step.
          if constexpr (requires { s.coupling().patch_faces(); })
            if (blocked_area == 0.0)
              for (const auto& f : s.coupling().patch_faces())
                if (f.axis == 0) {  // the face's area: its high cell's widths across the stream
                  const auto& fl = s.fluid();
                  auto add = [&](const pf::fluid::rectilinear_grid& g, pf::index_t cell) {
                    const auto ijk = g.ijk(cell);
                    blocked_area += g.width(1, ijk[1]) * g.width(2, ijk[2]);
                  };
                  if constexpr (blocks) add(fl.block_at(f.high / fl.stride()).grid, f.high % fl.stride());
                  else add(fl.grid(), f.high);
                }
          const Eigen::Vector3d c = s.coupling().diagnostics().impulse_structure / dt / qA;
          const double cd = c.x();
          if (!c.allFinite()) throw pf::numerical_failure("bluff_body_drag: the body force is not finite", 0, s.time());
          pf::fluid::prim<double> wp, wa;
          if constexpr (blocks) wp = s.fluid().sample(probe_point), wa = s.fluid().sample(ahead_point);
          else
            wp = s.fluid().primitive(probe[0], probe[1], probe[2]),
            wa = s.fluid().primitive(ahead[0], ahead[1], ahead[2]);
          csv.row({s.time(), cd, c.y(), c.z(), wp.u.y / U, wp.u.z / U});
          if (s.time() > t_avg) {
            ts.push_back(s.time());
            pv.push_back(wp.u.y / U);
            pw.push_back(wp.u.z / U);
          }
          // Time-weighted mean over the part of the step inside [t_avg, t_end].
          const double w = s.time() - std::max(t0, t_avg);
          if (w > 0) {
            sum += cd * w;
            sum_t += w;
            sum_p0 += ((wa.p - p0) / (0.5 * rho * U * U) + pf::dot(wa.u, wa.u) / (U * U)) * w;
            if constexpr (decltype(cpl)::porosity_type::permeable)
              sum_q += s.coupling().total_through_flow() / s.coupling().coupled_area() / U * w;
            if constexpr (sides) {  // the body's two sides along the stream (+x), gauge over q
              const auto cs = s.coupling().cloth_sides(Eigen::Vector3d::UnitX());
              sum_w += (cs.windward_pressure - p0) / (0.5 * rho * U * U) * w;
              sum_l += (cs.leeward_pressure - p0) / (0.5 * rho * U * U) * w;
            }
          }
          prog(s.time(), s.steps());
        }
        prog.finish(s.time(), s.steps());
        csv.close();
        const double cd = sum_t > 0 ? sum / sum_t : 0.0;
        std::printf(
            "drag_coefficient=%.6g shape=%s coupling=%s cells_per_diameter=%d averaged_from_t=%.6g t_end=%.6g "
            "steps=%ld max_penetration_over_h=%.3g wall_seconds=%.1f",
            cd, shape.c_str(), coupling.c_str(), cells, t_avg, s.time(), s.steps(), max_pen, prog.elapsed());
        if constexpr (decltype(cpl)::porosity_type::permeable)
          std::printf(" through_fraction=%.6g", sum_t > 0 ? sum_q / sum_t : 0.0);
        if constexpr (sides)
          std::printf(" windward_cp=%.6g leeward_cp=%.6g", sum_t > 0 ? sum_w / sum_t : 0.0,
                      sum_t > 0 ? sum_l / sum_t : 0.0);
        const double cp0 = sum_t > 0 && !ahead_in_sponge ? sum_p0 / sum_t : std::numeric_limits<double>::quiet_NaN();
        std::printf(" upstream_total_cp=%.6g", cp0);
        if (cp0 > 1.03 && t_avg * U / D >= 2.0)  // past the impulsive start's acoustic transient
          std::fprintf(stderr,
                       "bluff_body_drag: warning: the stream one diameter ahead of the body carries %.3g q of total "
                       "pressure, %.0f %% of q more than the free stream: the box's inflow is too close or too narrow "
                       "for this body and the drag carries about that excess (coupling.md 8.3; try --domain-upstream 6 "
                       "--domain-width 5)\n",
                       cp0, 100.0 * (cp0 - 1.0));
        if (blocked_area > 0)
          std::printf(" blocked_area_ratio=%.6g drag_coefficient_on_blocked_area=%.6g", blocked_area / area,
                      cd * area / blocked_area);
        // The wake probe: its dominant frequency in St ∈ [0.02, 2] over the second half.
        if (ts.size() >= 8 && (ts.back() - ts.front()) * U / D > 1.0) {
          const auto pk = pf::io::dominant_frequency(ts, {pv, pw}, 0.02 * U / D, 2.0 * U / D);
          if (pk.amplitude >= 1e-2 && pk.periods >= 3) std::printf(" strouhal=%.4g", pk.frequency * D / U);
          else std::printf(" strouhal=none");
          std::printf(" probe_amplitude=%.3g shedding_periods=%.3g", pk.amplitude, pk.periods);
        }
        std::printf(" closure=%s reynolds=%.4g mesh=%s flux=%s limiter=%s membrane_reconstruction=%s\n",
                    closure.c_str(), mu > 0 ? rho * U * D / mu : 0.0, mesh.c_str(), Fluid::flux_type::name(),
                    Fluid::recon_type::name(), coupling == "embedded" ? membrane_reconstruction.c_str() : "none");
        return 0;
      };
      auto with = [&](auto por) -> int {
        if (coupling == "embedded") {
          if (membrane_reconstruction == "one_sided") return run(pf::coupling::embedded<decltype(por), true>{por});
          return run(pf::coupling::embedded{por});
        }
        pf::coupling::penalty_options po;
        po.pfac = pfac;
        return run(pf::coupling::penalty{por, po});
      };
      if (fabric != "none") {
        const auto& fab = pf::model::fabric(fabric);
        return with(pf::porosity::ergun{fab.alpha, fab.beta, fab.thickness});
      }
      if (resistance > 0) {
        const double t = 1e-4;  // any thickness: the law is K ρ u²/2 whatever it is
        return with(pf::porosity::ergun{0.0, resistance * rho / (2.0 * t), t});
      }
      return with(pf::porosity::impermeable{});
    };
    // The fluid on the chosen mesh with the given policies (flux and reconstruction first).
    auto with_fluid = [&](auto... policies) -> int {
      if (mesh == "tensor") return run_with(pf::fluid::solver{grid, bc, policies...});
      const auto [lay, levels] = core_blocks(D, h, block_size, domain_length, domain_width, domain_upstream);
      // The block mesh's sponge is counted in root cells (a width that varies with N and the
      // block size): as many as make it closest to 1.2 D (the tensor grid's 4 outer cells, default box: 0.95-1.34 D).
      auto bcb = bc;
      bcb.layer.cells = no_sponge ? 0 : std::max(1, int(std::lround(1.2 * D / lay.cell_width(0, 0))));
      pf::fluid::block_solver fl{pf::fluid::blocks::tree(lay.root_blocks), lay, bcb, policies...};
      fl.regrid(pf::fluid::blocks::in_box{lay,
                                          {-0.5 * D, -core_width * D, -core_width * D},
                                          {core_length * D, core_width * D, core_width * D},
                                          levels},
                levels);
      if (!co.quiet) {
        std::vector<long> per(std::size_t(levels + 1), 0);
        for (const auto& q : fl.tree().leaves()) ++per[std::size_t(q.level)];
        std::string counts;
        for (int l = 0; l <= levels; ++l) counts += (l ? " / " : "") + std::to_string(per[std::size_t(l)]);
        std::fprintf(stderr,
                     "bluff_body_drag: block mesh, box [%g, %g] x [%g, %g]^2 m, %lld blocks of %d^3 (levels 0-%d: "
                     "%s), %lld cells, sponge %d root cells (%.3g D), blockage %.2g %%\n",
                     lay.lo[0], lay.hi[0], lay.lo[1], lay.hi[1], (long long)fl.block_count(), block_size, levels,
                     counts.c_str(), (long long)fl.cell_count(), bcb.layer.cells,
                     bcb.layer.cells * lay.cell_width(0, 0) / D,
                     100.0 * area / ((lay.hi[1] - lay.lo[1]) * (lay.hi[2] - lay.lo[2])));
      }
      return run_with(std::move(fl));
    };
    using muscl = pf::recon::muscl<pf::limiter::van_leer>;
    if (closure == "mixing_length") {
      pf::turbulence::prandtl_mixing_length ml;
      ml.ref_length = D;
      ml.mu_cap = 1000.0 * mu;
      return with_fluid(pf::flux::hllc_lm{}, muscl{}, ml, pf::viscosity::constant{mu, 0.72});
    }
    if (closure == "smagorinsky") {
      pf::turbulence::smagorinsky sm;
      sm.mu_cap = 1000.0 * mu;
      return with_fluid(pf::flux::hllc_lm{}, muscl{}, sm, pf::viscosity::constant{mu, 0.72});
    }
    if (mu > 0) return with_fluid(pf::flux::hllc_lm{}, muscl{}, pf::viscosity::constant{mu, 0.72});
    // The scheme's own dissipation (inviscid air only): the low-Mach fix off, or the more
    // diffusive limiter.
    using minmod = pf::recon::muscl<pf::limiter::minmod>;
    if (co.flux == "hllc") {
      if (co.limiter == "minmod") return with_fluid(pf::flux::hllc{}, minmod{});
      return with_fluid(pf::flux::hllc{}, muscl{});
    }
    if (co.limiter == "minmod") return with_fluid(pf::flux::hllc_lm{}, minmod{});
    return with_fluid(pf::flux::hllc_lm{}, muscl{});
  });
}
