// parachute_drop: the paper's parachute–payload drop (section 4) end to end.
//
//   parachute_drop [--canopy paper|c9] [--fabric mat544|mat59225|mat509]
//                  [--resolution draft|coarse|medium|fine] [--t-end SECONDS]
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
// --growth outwards. HLLC-LM + MUSCL (van Leer), SSP-RK2, the air's viscosity with Prandtl's
// mixing-length closure in the wake (--closure), pressure-gradient scaling α = 8 with embedded, 1 with penalty (--pgs);
// embedded coupling with the fabric's Ergun law on the cloth's normal through-velocity (--through-flow) and its
// impedance stabilisation, or the paper's penalty coupling
// (docs/coupling.md). Defaults chosen from the work-precision table, docs/validation.md §8.
// Studies: --box fixed --fixed-fall L (a fixed box holding a fall of L m, for the
// following-box comparison); --packed, --modulus-scale, --line-stiffness (sensitivity);
// --permeability (another fabric's Ergun law on this cloth: the permeability isolated);
// --payload-mass, --initial-speed (extreme scenes). A deployment's start: --packed bundle
// (the canopy gathered at line stretch, --packed-parameter its mouth / D0) with
// --initial-speed the speed at line stretch. A fixed canopy in a stream: --restart FILE
// --captive SPEED holds the checkpoint's shape and moves it at SPEED along its axis
// (with --permeability F, the same shape with fabric F's law).
//
// Writes in DIR: history.csv (one row per --history-every ≤ 5 ms; its last column the
// riser force low-pass filtered at --force-cutoff, 10 Hz), summary.csv, and
// mid-plane slices slice_<t>.csv (+ slice_<t>_nodes.csv) at --slice-times. Definitions:
// include/parafsi/io/drop_summary.hpp and docs/validation.md. Progress on stderr; the
// summary row on stdout at the end.
//
// Under MPI (built with parafsi::mpi when MPI is found): `mpirun -np N parachute_drop
// --mesh blocks ...` with the same flags splits every level of the block mesh over the N
// processes (with --coupling penalty the canopy's finest level is computed by every
// process; docs/guide_mpi.md); process 0 prints and writes the files, which are those of
// one process bit for bit, and each process writes its piece of the fluid VTK (.pvtu index).
//
// The run is scene::run_drop (include/parafsi/scene/drop.hpp); the flags bind directly to
// the fields of scene::drop_config, whose defaults are the program's. Every floating
// flag refuses NaN and ±inf (examples::finite); a write that fails (a full disk, a
// missing directory) stops the program with a message naming the file and exit code 1.
#include "example_common.hpp"

#include <parafsi/scene/drop.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <sstream>
#include <string>
#include <vector>

namespace {

std::vector<double> parse_list(const std::string& s) {
  std::vector<double> v;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty()) continue;
    std::size_t used = 0;
    double t = NAN;
    try {
      t = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != item.size() || !std::isfinite(t) || t < 0)
      throw CLI::ValidationError("--slice-times",
                                 "'" + item + "' is not a time in seconds (expected a comma list such as 0.5,1,2)");
    v.push_back(t);
  }
  std::sort(v.begin(), v.end());  // slices are written in time order
  return v;
}

std::string join_list(const std::vector<double>& v) {
  std::ostringstream os;
  for (std::size_t i = 0; i < v.size(); ++i) os << (i ? "," : "") << v[i];
  return os.str();
}

}  // namespace

#ifdef PARAFSI_WITH_MPI
#include <parafsi/mpi/block_halo.hpp>
#endif

int main(int argc, char** argv) {
#ifdef PARAFSI_WITH_MPI
  parafsi::mpi::environment mpi_env(argc, argv, /*only_if_launched=*/true);  // run alone: no MPI start-up
  int ranks = 1, rank = 0;
  if (mpi_env.active()) {
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  }
#else
  const int ranks = 1, rank = 0;
#endif
  CLI::App app{"Parachute-payload drop (the paper's section 4 scene): coupled fluid, canopy, lines and payload"};
  parafsi::scene::drop_config c;  // the defaults
  int threads = 0;
  const CLI::Validator& finite = examples::finite;
  app.add_option("--canopy", c.canopy, "scene: paper (section 4) or c9 (28-gore, 28 ft, deployed at 13.4 m/s)")
      ->check(CLI::IsMember({"paper", "c9"}))
      ->capture_default_str();
  app.add_option("--fabric", c.fabric, "canopy fabric of the paper's Table 2 (paper canopy)")
      ->check(CLI::IsMember({"mat544", "mat59225", "mat509"}))
      ->capture_default_str();
  app.add_option("--permeability", c.permeability,
                 "the fabric whose Ergun law (alpha, beta, thickness) the cloth's through-flow follows, keeping the "
                 "canopy fabric's weight and moduli (default: the canopy fabric's own); summary.csv's fabric "
                 "column then reads FABRIC+F_permeability")
      ->check(CLI::IsMember({"mat544", "mat59225", "mat509", "c9_mil_c_7020"}));
  app.add_option("--resolution", c.resolution,
                 "draft (element D0/20, cell D0/10), coarse (D0/30, D0/15), medium (D0/40, D0/20), fine (D0/60, "
                 "D0/30); tiny for tests")
      ->check(CLI::IsMember({"draft", "coarse", "medium", "fine", "tiny"}))
      ->capture_default_str();
  app.add_option("--t-end", c.t_end, "simulated time (s)")
      ->check(finite)
      ->check(CLI::Range(1e-4, 100.0))
      ->capture_default_str();
  app.add_option("--coupling", c.coupling,
                 "fluid-structure coupling: penalty (the paper's) or embedded (leak-free; impedance-stabilised)")
      ->check(CLI::IsMember({"penalty", "embedded"}))
      ->capture_default_str();
  app.add_option("--out", c.out, "output directory")->capture_default_str();
  app.add_option("--vtk-every", c.vtk_every, "VTK output interval (s)")->check(finite)->check(CLI::Range(0.0, 100.0));
  app.add_option("--checkpoint-every", c.checkpoint_every, "checkpoint interval (s)")
      ->check(finite)
      ->check(CLI::Range(0.0, 100.0));
  app.add_option("--restart", c.restart, "restart from this checkpoint file");
  app.add_option("--captive", c.captive_speed,
                 "a captive canopy: from the --restart checkpoint on, hold the structure in its shape and move it as "
                 "one body at this speed (m/s) along the canopy's axis through still air (drag in cloth_pressure.csv; "
                 "with --permeability another fabric's law on the same shape); 0: off")
      ->check(finite)
      ->check(CLI::Range(0.0, 200.0));
  app.add_option("--captive-hold", c.captive_hold,
                 "--captive: hold the whole structure (structure: a fixed shape) or the payload only (payload: the "
                 "canopy and lines free to breathe and turn about it, as on a wind tunnel's sting)")
      ->check(CLI::IsMember({"structure", "payload"}))
      ->capture_default_str();
  app.add_option("--threads", threads, "OpenMP threads (0: OMP_NUM_THREADS)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  app.add_option("--history-every", c.history_every, "history.csv row interval (s), at most 5 ms")
      ->check(finite)
      ->check(CLI::Range(1e-5, 0.005))
      ->capture_default_str();
  app.add_option("--force-cutoff", c.force_cutoff,
                 "cut-off (-3 dB, Hz) of the zero-phase low-pass filter of the riser force: history.csv "
                 "open_force_filtered and the summary's F_p, t_p")
      ->check(finite)
      ->check(CLI::Range(0.5, 1000.0))
      ->capture_default_str();
  app.add_option_function<std::string>(
         "--slice-times", [&c](const std::string& s) { c.slice_times = parse_list(s); },
         "times of the mid-plane slices (comma list, s; empty: none)")
      ->default_str(join_list(c.slice_times));
  app.add_option("--box-width", c.box_width, "box cross-section side / D0")
      ->check(finite)
      ->check(CLI::Range(2.0, 50.0))
      ->capture_default_str();
  app.add_option("--box-length", c.box_length, "box length / D0")
      ->check(finite)
      ->check(CLI::Range(3.0, 100.0))
      ->capture_default_str();
  app.add_option("--box-ahead", c.box_ahead, "box length ahead of the payload / D0")
      ->check(finite)
      ->check(CLI::Range(0.3, 50.0))
      ->capture_default_str();
  app.add_option("--grid-offset", c.grid_offset,
                 "shift of the fluid grid along the box axis, in finest cells (an ensemble over the grid's placement)")
      ->check(finite)
      ->check(CLI::Range(0.0, 0.999999))
      ->capture_default_str();
  app.add_option("--growth", c.growth, "cell growth factor outside the refined region (default: the resolution's)")
      ->check(finite)
      ->check(CLI::Range(1.0, 2.0));
  app.add_option("--cell", c.cell, "override: fluid cell size around the canopy / D0")
      ->check(finite)
      ->check(CLI::Range(0.0, 1.0));
  app.add_option_function<double>(
         "--finest-cell", [&c](double n) { c.cell = 1.0 / n; },
         "override: fluid cell size around the canopy as a fraction of D0, e.g. 30 for D0/30 (same as --cell 1/N)")
      ->check(finite)
      ->check(CLI::Range(1.0, 1000.0));
  app.add_option("--mesh", c.mesh,
                 "fluid mesh: tensor (the refined rectilinear box) or blocks (block-structured, refined to the "
                 "canopy)")
      ->check(CLI::IsMember({"tensor", "blocks"}))
      ->capture_default_str();
  app.add_option("--block-size", c.block_size, "blocks: cells per block edge (even, 4-64)")
      ->check(CLI::Range(4, 64))
      ->capture_default_str();
  app.add_option("--refine-every", c.refine_every, "blocks: regrid to the canopy every this many steps")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  app.add_option("--root-blocks", c.root_blocks,
                 "blocks: the least number of root blocks across the box's narrowest side (sets the levels: "
                 "1 gives blocks of 16 the levels of blocks of 8)")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  app.add_flag("--refine-column", c.refine_column,
               "blocks: also hold the finest level on the tensor box's refined column about the axis (from below "
               "the line confluence to above the crown)");
  app.add_flag("--static-mesh", c.static_mesh,
               "blocks: refine once at the start, to the canopy and the refined column as --refine-column, and "
               "never regrid (the canopy must stay on that column)");
  app.add_flag("--subcycle", c.subcycle,
               "blocks: level subcycling, each level at its own CFL step (the finest level, the embedded "
               "coupling and the structure together; one process)");
  app.add_option("--refine-vorticity", c.refine_vorticity,
                 "blocks: also refine the wake where |vorticity| h exceeds this fraction of the payload speed "
                 "(0: off)")
      ->check(finite)
      ->check(CLI::Range(0.0, 10.0))
      ->capture_default_str();
  app.add_option("--element", c.element, "override: canopy element size / D0")
      ->check(finite)
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--cfl", c.cfl, "CFL number of the fluid step")
      ->check(finite)
      ->check(CLI::Range(0.01, 1.0))
      ->capture_default_str();
  app.add_option("--pfac", c.pfac, "penalty factor PFAC")
      ->check(finite)
      ->check(CLI::Range(1e-3, 1e3))
      ->capture_default_str();
  app.add_option("--stiffening", c.stiffening, "penalty stiffening lambda (0 = off)")
      ->check(finite)
      ->check(CLI::Range(0.0, 10.0))
      ->capture_default_str();
  app.add_option("--coupling-damping", c.coupling_damping, "penalty damping ratio")
      ->check(finite)
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--membrane-damping", c.membrane_damping, "membrane damping ratio (highest mode)")
      ->check(finite)
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_flag("--quiet", c.quiet, "no progress on stderr");
  app.add_option("--initial-speed", c.initial_speed,
                 "override: release speed (m/s), every node and the payload along the flight path in still air "
                 "(with --packed bundle: the speed at line stretch); default: the scene's")
      ->check(finite)
      ->check(CLI::Range(0.0, 200.0));
  app.add_option("--viscosity", c.viscosity,
                 "air viscosity: constant (mu of the scene), inviscid, or auto (constant with a closure; without one "
                 "inviscid at draft/coarse, else constant)")
      ->check(CLI::IsMember({"auto", "constant", "inviscid"}))
      ->capture_default_str();
  app.add_option(
         "--closure,--turbulence", c.turbulence,
         "eddy-viscosity closure of the wake, added to the air's viscosity: mixing_length (Prandtl's, the method's; "
         "distance to the canopy and lines), smagorinsky, none (the scheme's implicit LES) or auto (mixing_length; "
         "none with --viscosity inviscid); --turbulence: the same")
      ->check(CLI::IsMember({"auto", "none", "mixing_length", "smagorinsky"}))
      ->capture_default_str();
  app.add_option("--impedance", c.impedance,
                 "embedded: impedance (added-mass) stabilisation factor, 0 = off (light fabric is unstable without)")
      ->check(finite)
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--through-flow", c.through_flow,
                 "embedded: the velocity the fabric's Ergun law acts on: cloth (the cloth's normal through-velocity) "
                 "or face (each grid face's, too permeable where the cloth is inclined to the grid)")
      ->check(CLI::IsMember({"cloth", "face"}))
      ->capture_default_str();
  app.add_option("--membrane-reconstruction", c.membrane_reconstruction,
                 "embedded: the cells beside the cloth reconstructed from their own side (one_sided, second order up "
                 "to the membrane) or first order; auto: one_sided")
      ->check(CLI::IsMember({"auto", "one_sided", "first_order"}))
      ->capture_default_str();
  app.add_option("--payload-mass", c.payload_mass, "override: payload mass (kg); default: the scene's")
      ->check(finite)
      ->check(CLI::Range(1e-3, 1e5));
  app.add_option("--line-stiffness", c.line_stiffness, "multiplies EA of the lines, riser and tapes")
      ->check(finite)
      ->check(CLI::Range(1e-3, 1e4))
      ->capture_default_str();
  app.add_option("--modulus-scale", c.modulus_scale, "multiplies the fabric moduli E11, E22, G12")
      ->check(finite)
      ->check(CLI::Range(1e-3, 1e3))
      ->capture_default_str();
  app.add_option("--packed", c.packed, "initial packed canopy shape (scene: the scene's, reduced radius 0.2 for paper)")
      ->check(CLI::IsMember({"scene", "reduced_radius", "star_fold", "bundle", "constructed"}))
      ->capture_default_str();
  app.add_option("--packed-parameter", c.packed_parameter,
                 "reduced_radius: radial scale s (default 0.2); star_fold: seam half-angle in degrees (default 5); "
                 "bundle: mouth diameter / D0, in [0.01, 0.5] (default 0.1)")
      ->check(finite)
      ->check(CLI::Range(0.0, 89.0));
  app.add_option("--box", c.box, "fluid box: follow (the paper's, moves and turns with the payload) or fixed")
      ->check(CLI::IsMember({"follow", "fixed"}))
      ->capture_default_str();
  app.add_option("--fixed-fall", c.fixed_fall, "fixed box: fall length (m) it must hold below the release point")
      ->check(finite)
      ->check(CLI::Range(0.0, 1000.0));
  app.add_option("--pgs", c.pgs_alpha,
                 "pressure-gradient scaling alpha >= 1: sound speed c/alpha, steps alpha times longer (1 = off; "
                 "default 0 = auto: 8 with embedded, 1 with penalty)")
      ->check(finite)
      ->check(CLI::Range(0.0, 64.0))
      ->capture_default_str();
  int rc = 0;
  if (!examples::parse(app, argc, argv, rc)) return rc;
  if (threads > 0) parafsi::parallel::set_threads(threads);
  if (ranks > 1) {
    if (c.mesh != "blocks") {
      if (rank == 0)
        std::fprintf(stderr, "parachute_drop: %d processes need --mesh blocks (the tensor box runs on one)\n", ranks);
      return 2;
    }
#ifdef PARAFSI_WITH_MPI
    parafsi::mpi::halo_options ho;
    // Every level is split over the processes; the embedded coupling brings the cells its
    // faces read to every process each stage. The penalty coupling's points read the air
    // anywhere in their cells' stencils during the structure's substeps: the canopy's level
    // is then computed by every process.
    ho.replicate_finest = c.coupling == "penalty";
    c.halo = std::make_shared<parafsi::mpi::block_halo>(MPI_COMM_WORLD, ho);
#endif
    if (rank != 0) c.quiet = true;
  }

  const int status = examples::guarded("parachute_drop", [&]() -> int {
    examples::progress prog("parachute_drop", c.t_end, c.quiet);
    const auto r = parafsi::scene::run_drop(c, [&](double t, long steps, bool done) {
      if (done) prog.finish(t, steps);
      else prog(t, steps);
    });
    if (rank == 0) std::printf("%s\n%s\n", parafsi::io::drop_summary_header, r.summary.csv_row().c_str());
    return 0;
  });
#ifdef PARAFSI_WITH_MPI
  // An error on one process (its message printed above) stops them all: the others may
  // wait in a collective call that this one will never make.
  if (status != 0 && ranks > 1) MPI_Abort(MPI_COMM_WORLD, status);
#endif
  return status;
}
