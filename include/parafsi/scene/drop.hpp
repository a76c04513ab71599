/// \file drop.hpp
/// The parachute drop as library code: `run_drop(config)` builds the scene of
/// model::drop_scene_parameters (paper() or c9()) with the config's overrides, the
/// structure assembly (structure/from_drop_scene.hpp), the fluid box (model/drop_box.hpp)
/// with its solver, the coupling and the explicit_stepper, runs it to `t_end` and returns
/// the history (io::drop_history_row per output instant) and the summary; with `out` set
/// it writes history.csv, summary.csv, the mid-plane slices, VTK files and checkpoints
/// there. examples/parachute_drop.cpp is its command line; examples/drop_guide.cpp builds
/// the same drop step by step from the pieces below.
///
/// Pieces (each usable on its own):
///   drop_config           every choice of a run, with its default (the program's)
///   make_drop_setup(c)    the plain data: scene parameters after the overrides, the
///                         resolution, the scene, the fluid box, α
///   scene/drop_steps.hpp  make_drop_grid(box), place_drop_box(fluid, box, assembly),
///                         drop_frame_target<Fluid>(g), landing_step(dt, left): the steps
///                         a program that builds the drop itself shares with run_drop
///
/// Scene: the model's values (paper: released at rest from 35 m, flight path 90°,
/// ρ = 1.18, p = 101325, μ = 1.79e-5, g = 9.81 on the structure and payload only, payload
/// 1.8 kg). Fluid box: model::make_drop_box (cross-section box_width × box_width D0,
/// length box_length D0 with box_ahead D0 ahead of the payload mass centre; cells of
/// `cell`·D0 on the block around the canopy growing by `growth` per cell outwards);
/// frame::follow_payload translates it with the payload mass centre and turns its −z axis
/// to the payload velocity (box = follow), or frame::fixed (box = fixed, lengthened by
/// fixed_fall). Far field + 3-cell sponge on all six faces. HLLC-LM + MUSCL (van Leer),
/// SSP-RK2; constant μ or inviscid (`viscosity`), with an eddy-viscosity closure of the wake
/// (`turbulence`, default Prandtl's mixing length). Pressure-gradient scaling α (`pgs_alpha`;
/// 0 = auto: 8 with the embedded coupling, 1 with penalty, whose spring stiffness γp/α²
/// it would soften): the air held at p/α². Coupling: embedded (default) or penalty (PFAC,
/// stiffening λ), both with the fabric's Ergun law. The embedded coupling reconstructs the
/// cells beside the cloth from their own side on either mesh (`membrane_reconstruction`
/// auto or one_sided: coupling::embedded<P, true>, second order up to the membrane), or
/// takes their own values (first_order).
///
/// Loop (each step): on the block mesh the regrid to the canopy (every `refine_every`
/// steps); the stable step at `cfl` (subcycled, no longer than the step the regrid's canopy
/// buffer was made for: drop_canopy_travel), shortened to land on the next output
/// instant n · history_every (an integer n, so a restarted run takes the steps of the
/// uninterrupted one); the coupled step (the stepper moves the box after the payload:
/// its frame target, `drop_frame_target`). At each output
/// instant: a history row (checked for non-finite nodes), the αM guard (a warning once
/// when α |v_payload| / c > 0.3), the rows whose open-force filter window is now complete
/// to history.csv (io::drop_history_filter: a row is written H = ⌈4σ/history_every⌉ rows
/// after its own, 11 rows at the defaults; the last H at the end of the run, or when the
/// run stops with an error), VTK and checkpoint at their intervals, the slices due.
/// Stops with numerical_failure when the stable step collapses below 1e-9 history_every
/// or when the payload leaves a fixed box's refined column. Restart: the stepper's state
/// from the checkpoint (refused if its air is not at this run's ambient, i.e. another α or
/// scene pressure, or if t_end is not after its time), the history rows up to the
/// restored time from the checkpoint (its section "history"), their filtered force
/// recomputed from the raw column as their windows complete, so the restarted history.csv
/// and summary.csv equal the uninterrupted run's bit for bit. A checkpoint holds the
/// run's drop_signature: a restart whose parameters differ is refused naming the
/// parameter and both values.
/// Messages (progress is the caller's, through `progress`) go to stderr unless `quiet`.
#pragma once
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../coupling/coupling.hpp"
#include "../explicit_stepper.hpp"
#include "../fluid/blocks/halo.hpp"
#include "../fluid/fluid.hpp"
#include "../io/block_vtk.hpp"
#include "../io/checkpoint.hpp"
#include "../io/csv.hpp"
#include "../io/drop_history.hpp"
#include "../io/drop_slice.hpp"
#include "../io/drop_summary.hpp"
#include "../io/vtk.hpp"
#include "../model/drop_box.hpp"
#include "../model/drop_scene.hpp"
#include "../structure/from_drop_scene.hpp"
#include "drop_steps.hpp"

namespace parafsi::scene {

/// Every choice of a drop run. The defaults are parachute_drop's (its flags bind to these
/// fields); `out` empty writes no files.
struct drop_config {
  std::string canopy = "paper";   ///< paper | c9
  std::string fabric = "mat544";  ///< paper canopy: mat544 | mat59225 | mat509
  /// The fabric whose Ergun law (α, β, thickness) the cloth's through-flow follows; empty:
  /// the canopy's own. Isolates permeability from the cloth's weight and moduli.
  std::string permeability;
  std::string resolution = "coarse";  ///< draft | coarse | medium | fine | tiny (model::drop_resolution)
  std::string coupling = "embedded";  ///< embedded | penalty
  std::string mesh = "tensor";        ///< tensor: the refined rectilinear box; blocks: the block mesh
  int block_size = 8;                 ///< blocks: cells per block edge
  int refine_every = 1;               ///< blocks: regrid to the canopy every this many steps
  int root_blocks = 2;                ///< blocks: the least number of root blocks across the box's narrowest side
  /// blocks: also refine the wake where |ω| h > this × the payload's speed (the velocity
  /// turning by that fraction across a cell; coarsened below a quarter of it); 0 = off
  double refine_vorticity = 0;
  /// blocks: also hold the finest level on the tensor box's refined column (drop_column_target)
  bool refine_column = false;
  /// blocks: refine once, at the start, to the canopy and the refined column (as
  /// --refine-column's first mesh), and never regrid: a mesh that stays (the membrane must
  /// stay on the column's finest level, or the coupling stops the run)
  bool static_mesh = false;
  /// blocks: level subcycling (fluid::block_solver::step_subcycled): each level steps at its
  /// own CFL limit, the finest level, the coupling and the structure together (embedded
  /// coupling, one process)
  bool subcycle = false;
  /// constant | inviscid | auto (constant with a closure; without one inviscid at draft/coarse/tiny)
  std::string viscosity = "auto";
  /// The wake's eddy-viscosity closure: none | mixing_length (Prandtl's, the method's,
  /// l_m = min(κ d_w, C_l D0, Δ), d_w from the canopy and line nodes) | smagorinsky
  /// (C_s = 0.1) | auto (mixing_length, or none with viscosity = inviscid; chosen from the
  /// 6 s drops, docs/validation.md §8.2); a closure brings the air's viscosity with it
  std::string turbulence = "auto";
  /// The closure this run uses (auto resolved).
  std::string closure() const {
    if (turbulence != "auto") return turbulence;
    return viscosity == "inviscid" ? "none" : "mixing_length";
  }
  double t_end = 6.0;            ///< simulated time (s)
  double history_every = 0.005;  ///< output interval (s)
  double force_cutoff = 10.0;    ///< riser-force filter cut-off (Hz): open_force_filtered, F_p, t_p
  double box_width = 5.0, box_length = 7.0, box_ahead = 1.5;  ///< fluid box / D0 (model::drop_box_parameters)
  double grid_offset = 0.0;  ///< shift of the fluid grid along the box axis, in finest cells, in [0, 1)
  double growth = 0;         ///< cell growth factor outside the refined block; 0 = the resolution's
  double cfl = 0.9;          ///< CFL number of the fluid step
  double pfac = 1.0, stiffening = 0.25, coupling_damping = 0.0;  ///< penalty: PFAC, λ, damping ratio
  double membrane_damping = 0.05;                                ///< membrane damping ratio of its highest mode
  double impedance = 1.0;  ///< embedded: impedance (added-mass) stabilisation factor ζ
  /// embedded: the velocity the fabric law acts on, cloth (the cloth's normal) or face
  /// (each grid face's own, the rule before 2026-12; coupling::through_flow_law)
  std::string through_flow = "cloth";
  /// embedded: the cells beside the cloth reconstructed from their own side (one_sided) or
  /// first order (first_order); auto = one_sided
  std::string membrane_reconstruction = "auto";
  /// Whether the run's embedded coupling reconstructs the cells beside the cloth one-sided.
  bool one_sided() const { return coupling == "embedded" && membrane_reconstruction != "first_order"; }
  double pgs_alpha = 0.0;        ///< pressure-gradient scaling α ≥ 1; 1 = off, 0 = auto (pressure_scaling.hpp)
  double cell = 0, element = 0;  ///< overrides of the resolution (/ D0), 0 = the resolution's
  double initial_speed = -1;     ///< override of the scene's release speed (m/s), < 0 = scene
  double payload_mass = -1;      ///< override of the payload mass (kg), <= 0 = scene
  double line_stiffness = 1;     ///< multiplies EA of lines, riser and tapes (sensitivity, extremes)
  double modulus_scale = 1;      ///< multiplies the fabric moduli E11, E22, G12
  std::string packed = "scene";  ///< scene | reduced_radius | star_fold | bundle | constructed
  double packed_parameter = -1;  ///< reduced_radius: s; star_fold: θ_s (deg); bundle: mouth d/D0; < 0 = default
  std::string box = "follow";    ///< follow: the paper's moving box; fixed: a fixed box holding the fall
  double fixed_fall = 0;         ///< fixed box: fall length (m) the refined column extends below the start
  std::vector<double> slice_times{0.1, 0.2, 0.3, 0.5, 1, 2, 4, 6};  ///< mid-plane slice times (s)
  std::string out = "out/drop";                                     ///< output directory; empty: no files
  double vtk_every = 0;  ///< VTK (.vtu structure, .vts/.vtu fluid or .pvtu pieces, drop.pvd) interval (s), 0 = none
  double checkpoint_every = 0;  ///< checkpoint interval (s), 0 = none; file <out>/checkpoint.ckpt
  std::string restart;          ///< checkpoint to continue from (same scene and flags)
  /// > 0: a captive canopy (m/s). From the restart on, the structure is held in the shape
  /// of the checkpoint (structure::assembly::hold) and moves as one rigid body at this
  /// speed along the canopy's axis, vent → confluence, through the still air: the same
  /// shape in a steady stream, with no swing and no breathing, its drag read from
  /// cloth_pressure.csv. Needs --restart (of a run with the canopy's own fabric law; the
  /// captive run may give another with `permeability`); writes no checkpoint.
  double captive_speed = 0;
  /// --captive: what is held, the whole structure (structure: a fixed shape) or the payload
  /// only (payload: the canopy and lines free to breathe and to turn about the payload,
  /// which moves at the captive speed without turning, as on a wind tunnel's sting)
  std::string captive_hold = "structure";
  bool quiet = false;  ///< no messages on stderr
  /// Block mesh over several processes (set by a distributed program, e.g. with
  /// mpi::block_halo: every level split with the embedded coupling; with the penalty
  /// coupling replicate_finest, the canopy's level computed by every process); every process
  /// runs the same drop, process 0 writes the files but for the fluid's VTK pieces (one per
  /// process, with a .pvtu index).
  std::shared_ptr<fluid::blocks::halo> halo;

  /// Throws invalid_input naming a bad field (non-finite numbers included).
  void validate() const {
    auto one_of = [](const std::string& v, std::initializer_list<const char*> names) {
      for (const char* n : names)
        if (v == n) return true;
      return false;
    };
    require(one_of(canopy, {"paper", "c9"}), "parachute_drop: canopy must be paper or c9, got '", canopy, "'");
    require(one_of(coupling, {"embedded", "penalty"}), "parachute_drop: coupling must be embedded or penalty, got '",
            coupling, "'");
    require(one_of(through_flow, {"cloth", "face"}), "parachute_drop: through-flow must be cloth or face, got '",
            through_flow, "'");
    require(one_of(membrane_reconstruction, {"auto", "one_sided", "first_order"}),
            "parachute_drop: membrane reconstruction must be auto, one_sided or first_order, got '",
            membrane_reconstruction, "'");
    require(one_of(viscosity, {"auto", "constant", "inviscid"}),
            "parachute_drop: viscosity must be auto, constant or inviscid, got '", viscosity, "'");
    require(one_of(turbulence, {"auto", "none", "mixing_length", "smagorinsky"}),
            "parachute_drop: closure must be auto, none, mixing_length or smagorinsky, got '", turbulence, "'");
    require(closure() == "none" || viscosity != "inviscid", "parachute_drop: --closure ", turbulence,
            " is an eddy viscosity added to the air's: it cannot run with --viscosity inviscid");
    require(one_of(packed, {"scene", "reduced_radius", "star_fold", "bundle", "constructed"}),
            "parachute_drop: unknown packed shape '", packed, "'");
    require(box == "follow" || box == "fixed", "parachute_drop: box must be follow or fixed, got '", box, "'");
    require(mesh == "tensor" || mesh == "blocks", "parachute_drop: mesh must be tensor or blocks, got '", mesh, "'");
    if (mesh == "blocks") {
      require(block_size >= 4 && block_size <= 64 && block_size % 2 == 0,
              "parachute_drop: --block-size must be even and in [4, 64], got ", block_size);
      require(refine_every >= 1, "parachute_drop: --refine-every must be >= 1 step, got ", refine_every);
      require(root_blocks >= 1 && root_blocks <= 16, "parachute_drop: --root-blocks must be in [1, 16], got ",
              root_blocks);
      require(std::isfinite(refine_vorticity) && refine_vorticity >= 0 && refine_vorticity <= 10,
              "parachute_drop: --refine-vorticity must be in [0, 10] (0: off), got ", refine_vorticity);
    } else {
      require(refine_vorticity == 0, "parachute_drop: --refine-vorticity needs --mesh blocks");
      require(!refine_column, "parachute_drop: --refine-column needs --mesh blocks");
      require(!static_mesh, "parachute_drop: --static-mesh needs --mesh blocks");
      require(!subcycle, "parachute_drop: --subcycle needs --mesh blocks");
    }
    require(!subcycle || !halo,
            "parachute_drop: --subcycle runs on one process, without mpirun (level subcycling is not distributed "
            "yet)");
    require(!subcycle || coupling == "embedded",
            "parachute_drop: --subcycle needs the embedded coupling (its faces and the structure advance with the "
            "finest level)");
    const std::pair<const char*, double> numbers[] = {{"t_end", t_end},
                                                      {"history_every", history_every},
                                                      {"force_cutoff", force_cutoff},
                                                      {"box_width", box_width},
                                                      {"box_length", box_length},
                                                      {"box_ahead", box_ahead},
                                                      {"growth", growth},
                                                      {"cfl", cfl},
                                                      {"pfac", pfac},
                                                      {"stiffening", stiffening},
                                                      {"coupling_damping", coupling_damping},
                                                      {"membrane_damping", membrane_damping},
                                                      {"impedance", impedance},
                                                      {"pgs_alpha", pgs_alpha},
                                                      {"cell", cell},
                                                      {"element", element},
                                                      {"initial_speed", initial_speed},
                                                      {"payload_mass", payload_mass},
                                                      {"line_stiffness", line_stiffness},
                                                      {"modulus_scale", modulus_scale},
                                                      {"packed_parameter", packed_parameter},
                                                      {"fixed_fall", fixed_fall},
                                                      {"vtk_every", vtk_every},
                                                      {"checkpoint_every", checkpoint_every},
                                                      {"captive_speed", captive_speed}};
    for (const auto& [name, v] : numbers)
      require(std::isfinite(v), "parachute_drop: ", name, " must be a finite number, got ", v);
    for (double t : slice_times)
      require(std::isfinite(t) && t >= 0, "parachute_drop: slice times must be finite and >= 0, got ", t);
    require(t_end > 0, "parachute_drop: t_end must be > 0 s, got ", t_end);
    require(history_every > 0, "parachute_drop: history_every must be > 0 s, got ", history_every);
    // Below 0.5 Hz the filter (σ > 0.26 s) would flatten the opening peak (0.1–0.3 s) itself.
    require(force_cutoff >= 0.5, "parachute_drop: --force-cutoff must be >= 0.5 Hz, got ", force_cutoff);
    require(4.0 * std::sqrt(std::numbers::ln2) / (2.0 * std::numbers::pi * force_cutoff) / history_every <= 1e6,
            "parachute_drop: --force-cutoff ", force_cutoff, " Hz at --history-every ", history_every,
            " s needs a filter half-window of more than 1e6 rows");
    require(t_end / history_every <= 1e9, "parachute_drop: t_end / history_every = ", t_end / history_every,
            " output instants, more than 1e9");
    require(cfl > 0 && cfl <= 1, "parachute_drop: cfl must be in (0, 1], got ", cfl);
    require(growth == 0 || (growth >= 1 && growth <= 2),
            "parachute_drop: growth must be in [1, 2] (0: the "
            "resolution's), got ",
            growth);
    require(cell >= 0 && element >= 0,
            "parachute_drop: cell and element sizes must be >= 0 (0: the resolution's), "
            "got ",
            cell, " and ", element);
    // Penalty stiffening multiplies the springs by 1 + (d/(λh))², which the stable step does
    // not see: a tiny λ diverges.
    require(stiffening == 0 || (stiffening >= 0.01 && stiffening <= 10),
            "parachute_drop: --stiffening must be 0 (off) or in [0.01, 10], got ", stiffening);
    require(line_stiffness > 0, "parachute_drop: line stiffness scale must be > 0, got ", line_stiffness);
    if (!permeability.empty()) {
      try {
        model::fabric(permeability);
      } catch (const invalid_input& e) {
        throw invalid_input(parafsi::detail::concat("parachute_drop: --permeability: ", e.what()));
      }
    }
    require(modulus_scale > 0, "parachute_drop: fabric modulus scale must be > 0, got ", modulus_scale);
    require(pgs_alpha == 0 || pgs_alpha >= 1, "parachute_drop: --pgs (PGS alpha) must be >= 1 (0: auto), got ",
            pgs_alpha);
    require(vtk_every >= 0 && checkpoint_every >= 0,
            "parachute_drop: VTK and checkpoint intervals must be >= 0 s, "
            "got ",
            vtk_every, " and ", checkpoint_every);
    require(!out.empty() || (vtk_every == 0 && checkpoint_every == 0), "parachute_drop: --vtk-every ", vtk_every,
            " and --checkpoint-every ", checkpoint_every, " need an output directory, but --out is empty (no files)");
    require(packed != "reduced_radius" || packed_parameter < 0 || (packed_parameter > 0 && packed_parameter <= 1),
            "parachute_drop: --packed-parameter ", packed_parameter,
            ": the reduced radius s of the packed canopy must be in (0, 1] (negative: the default 0.2)");
    require(packed != "bundle" || packed_parameter < 0 || (packed_parameter >= 0.01 && packed_parameter <= 0.5),
            "parachute_drop: --packed-parameter ", packed_parameter,
            ": the bundle's mouth diameter d/D0 must be in [0.01, 0.5] (negative: the default 0.1)");
    require(std::is_sorted(slice_times.begin(), slice_times.end()),
            "parachute_drop: --slice-times must be in increasing order");
    for (double t : slice_times)  // a slice is written at an output instant and labelled with its time
      require(std::fabs(std::round(t / history_every) * history_every - t) <= 1e-9 * std::max(t, history_every),
              "parachute_drop: --slice-times ", t, " s is not an output instant (a multiple of --history-every ",
              history_every, " s)");
    require(box != "fixed" || fixed_fall > 0,
            "parachute_drop: a fixed box needs the fall length it must hold (> 0 m), got ", fixed_fall);
    require(captive_speed >= 0 && captive_speed <= 200,
            "parachute_drop: --captive speed must be in [0, 200] m/s (0: off), got ", captive_speed);
    require(captive_speed > 0 || captive_hold == "structure", "parachute_drop: --captive-hold ", captive_hold,
            " needs --captive SPEED");
    if (captive_speed > 0) {
      require(!restart.empty(),
              "parachute_drop: --captive holds the canopy in the shape of a checkpoint: give --restart FILE");
      require(coupling == "embedded",
              "parachute_drop: --captive reads the canopy's drag from cloth_pressure.csv, which the embedded "
              "coupling writes: use --coupling embedded");
      // The free run's files would be cut at the checkpoint's time and replaced.
      std::error_code ec;
      const std::filesystem::path from = std::filesystem::path(restart).parent_path();
      require(out.empty() || !std::filesystem::equivalent(from.empty() ? std::filesystem::path(".") : from, out, ec),
              "parachute_drop: --captive writes into --out ", out,
              ", the directory of the checkpoint's own run: give another --out (its history would be replaced)");
      require(checkpoint_every == 0,
              "parachute_drop: --captive writes no checkpoint (the hold is not saved); drop "
              "--checkpoint-every");
      require(box == "follow", "parachute_drop: --captive needs the following box (--box follow)");
      require(captive_hold == "structure" || captive_hold == "payload",
              "parachute_drop: --captive-hold must be structure or payload, got '", captive_hold, "'");
    }
  }
};

struct drop_result {
  std::string fabric;
  std::vector<io::drop_history_row> history;
  io::drop_summary summary;
  long cells = 0, nodes = 0, triangles = 0, steps = 0;  ///< steps: of the coarsest level when subcycled
  double substeps_per_step = 0, wall = 0;               ///< structure substeps per such step
  /// Block mesh: leaf cells averaged over the steps, the most at any step, and the regrids
  /// that changed the mesh (the tensor box: its cell count, the same, 0).
  double mean_cells = 0;
  long max_cells = 0, regrids = 0;
  /// Block mesh: the canopy's largest displacement relative to the box between two regrids
  /// as a fraction of the travel the earlier regrid's buffer allowed (since the start or the
  /// restart; above 1 the canopy left its buffer; 0 on the tensor box and a static mesh).
  double canopy_travel_ratio = 0;
  stepper_phase_times times{};
};

/// Progress of a run: called with (t, steps, done) after every step (done = false) and
/// once at the end (done = true).
using drop_progress = std::function<void(double t, long steps, bool done)>;

/// The plain data of a run, resolved from a drop_config.
struct drop_setup {
  model::drop_scene_parameters params;  ///< the scene's parameters after the overrides
  model::drop_resolution resolution;    ///< the preset after the overrides
  model::drop_scene scene;
  model::drop_box box;
  double alpha = 1;        ///< pressure-gradient scaling α (auto resolved)
  bool fixed_box = false;  ///< frame::fixed instead of frame::follow_payload
  bool viscous = false;    ///< constant μ instead of inviscid
};

/// The scene, box and numbers of the config `c` (validated first).
inline drop_setup make_drop_setup(const drop_config& c) {
  c.validate();
  drop_setup su;
  model::drop_scene_parameters& P = su.params;
  P = c.canopy == "c9" ? model::drop_scene_parameters::c9() : model::drop_scene_parameters::paper(c.fabric);
  const double D0 = P.canopy.nominal_diameter;
  model::drop_resolution& R = su.resolution;
  R = model::drop_resolution::preset(c.resolution);
  if (c.cell > 0) R.cell = c.cell;
  if (c.growth > 0) R.growth = c.growth;
  if (c.element > 0) R.element = c.element;
  if (c.initial_speed >= 0) P.initial_speed = c.initial_speed;
  if (c.payload_mass > 0) P.payload.mass = c.payload_mass;
  for (auto* l : {&P.line, &P.skirt_tape, &P.vent_tape, &P.band}) l->stiffness_scale *= c.line_stiffness;
  P.moduli.modulus_scale *= c.modulus_scale;
  if (c.packed == "reduced_radius")
    P.shape = model::packed_shape::reduced_radius(c.packed_parameter > 0 ? c.packed_parameter : 0.2);
  else if (c.packed == "star_fold")
    P.shape = model::packed_shape::star_fold((c.packed_parameter >= 0 ? c.packed_parameter : 5.0) * std::numbers::pi /
                                             180.0);
  else if (c.packed == "bundle")
    P.shape = model::packed_shape::bundle(c.packed_parameter > 0 ? c.packed_parameter : 0.1);
  else if (c.packed == "constructed") P.shape = model::packed_shape::constructed();
  su.fixed_box = c.box == "fixed";
  P.canopy.element_size = R.element * D0;
  // The model's refusals name counts and sizes; the flags that set them are added here.
  try {
    su.scene = model::build_drop_scene(P);
  } catch (const invalid_input& e) {
    throw invalid_input(parafsi::detail::concat("parachute_drop: the scene (--element ", R.element, " D0, --packed ",
                                                c.packed, "): ", e.what()));
  }
  model::drop_box_parameters bp;
  bp.width = c.box_width;
  bp.length = c.box_length;
  bp.ahead = c.box_ahead;
  bp.cell = R.cell;
  bp.growth = R.growth;
  bp.fall = su.fixed_box ? c.fixed_fall : 0.0;
  bp.offset = c.grid_offset;
  try {
    su.box = model::make_drop_box(su.scene, bp);
  } catch (const invalid_input& e) {
    throw invalid_input(parafsi::detail::concat("parachute_drop: the fluid box (--cell ", R.cell, " D0, --growth ",
                                                R.growth, ", --box-width ", c.box_width, ", --box-length ",
                                                c.box_length, "): ", e.what()));
  }
  // α = 0: auto, 8 for the embedded coupling (docs/validation.md §8), 1 for penalty (its
  // spring stiffness PFAC γp A/h would fall as 1/α²).
  su.alpha = c.pgs_alpha == 0.0 ? (c.coupling == "embedded" ? 8.0 : 1.0) : c.pgs_alpha;
  const bool coarse = c.resolution == "draft" || c.resolution == "coarse" || c.resolution == "tiny";
  su.viscous = c.closure() != "none" || !(c.viscosity == "inviscid" || (c.viscosity == "auto" && coarse));
  return su;
}

/// True when `--permeability` names a fabric other than the canopy's: the cloth then follows
/// another fabric's Ergun law (naming its own fabric is the default run).
inline bool drop_permeability_swapped(const drop_config& c, const drop_setup& su) {
  return !c.permeability.empty() && c.permeability != su.scene.fabric.name;
}

/// Every parameter of `c` (resolved by `su`) that changes the run: saved with each
/// checkpoint and compared on restart (io::scene_signature), so a restart with another
/// scene, resolution, coupling, α, payload, moduli, packed shape, box, closure, CFL,
/// damping or output interval is refused naming the parameter and both values. Not in it:
/// t_end, out, slice_times, vtk_every, checkpoint_every, threads, force_cutoff (they do not
/// change the computed states; the filtered force is recomputed from the raw one).
inline io::scene_signature drop_signature(const drop_config& c, const drop_setup& su) {
  io::scene_signature g;
  g.add("canopy", c.canopy).add("fabric", std::string(su.scene.fabric.name)).add("resolution", c.resolution);
  g.add("cell", su.resolution.cell).add("element", su.resolution.element).add("growth", su.resolution.growth);
  g.add("coupling", c.coupling).add("pgs_alpha", su.alpha).add("impedance", c.impedance);
  g.add("pfac", c.pfac).add("stiffening", c.stiffening).add("coupling_damping", c.coupling_damping);
  g.add("viscosity", su.viscous ? "constant" : "inviscid").add("cfl", c.cfl);
  g.add("turbulence", c.closure());
  g.add("through_flow", c.through_flow);
  g.add("membrane_reconstruction", c.coupling != "embedded" ? "none" : (c.one_sided() ? "one_sided" : "first_order"));
  g.add("membrane_damping", c.membrane_damping).add("history_every", c.history_every);
  g.add("initial_speed", su.params.initial_speed).add("payload_mass", su.params.payload.mass);
  g.add("line_stiffness", c.line_stiffness).add("modulus_scale", c.modulus_scale);
  if (drop_permeability_swapped(c, su)) g.add("permeability", c.permeability);
  g.add("packed", c.packed).add("packed_parameter", c.packed_parameter);
  g.add("box", c.box).add("box_width", c.box_width).add("box_length", c.box_length).add("box_ahead", c.box_ahead);
  g.add("fixed_fall", su.fixed_box ? c.fixed_fall : 0.0);
  if (c.grid_offset != 0.0) g.add("grid_offset", c.grid_offset);
  if (c.mesh == "blocks")
    g.add("mesh", c.mesh)
        .add("block_size", std::int64_t(c.block_size))
        .add("refine_every", std::int64_t(c.refine_every))
        .add("refine_vorticity", c.refine_vorticity)
        .add("refine_column", std::int64_t(c.refine_column));
  if (c.mesh == "blocks" && c.static_mesh) g.add("static_mesh", std::int64_t(1));
  if (c.mesh == "blocks" && c.subcycle) g.add("subcycle", std::int64_t(1));
  if (c.mesh == "blocks" && c.root_blocks != 2) g.add("root_blocks", std::int64_t(c.root_blocks));
  return g;
}

/// The Ergun law of the drop's cloth: the canopy fabric's, or with `--permeability F` that
/// of fabric F (its α, β and thickness: Δp = t (α V + β V²)).
inline porosity::ergun drop_porosity_law(const drop_config& c, const drop_setup& su) {
  const model::fabric_data& f = c.permeability.empty() ? su.scene.fabric : model::fabric(c.permeability);
  return porosity::ergun{f.alpha, f.beta, f.thickness};
}

/// The fabric column of summary.csv: the canopy's fabric, followed by "+F_permeability"
/// when its through-flow follows another fabric F's law (so runs group by what the cloth
/// was; F the canopy's own fabric is the default run, label and signature alike).
inline std::string drop_fabric_label(const drop_config& c, const drop_setup& su) {
  std::string label(su.scene.fabric.name);
  if (drop_permeability_swapped(c, su)) label += "+" + c.permeability + "_permeability";
  return label;
}

/// The rings of cloth_bands.csv: the canopy's cut pattern from the vent edge to the skirt in
/// cloth_band_count rings of equal width along the seams, ring 0 at the vent (the crown) and
/// the last at the skirt. A triangle goes by its centroid's seam distance, the distance along
/// the seams of the pattern's row through it, s = r cos(φ − φ_c)/cos(π/N) (r, φ its polar
/// coordinates on the pattern, φ_c the centreline of its gore; the rows are chords of the
/// gores, model::flat_circular_canopy), so the ring boundaries follow the rows and a ring is
/// the same cloth whatever the canopy's shape. Returned per triangle of the scene (−1 for one
/// that is not the canopy's).
inline constexpr int cloth_band_count = 4;
inline std::vector<int> cloth_bands(const model::drop_scene& sc) {
  std::vector<int> band(sc.triangles.size(), -1);
  const auto& cm = sc.canopy;
  const auto& pat = cm.positions;
  const int N = cm.params.gores;
  const double Rv = cm.vent_radius, Rs = cm.skirt_radius, half = std::numbers::pi / N;
  for (std::size_t e = 0; e < sc.triangles.size() && e < cm.triangles.size() && e < cm.gore.size(); ++e) {
    const auto& t = sc.triangles[e];
    if (t != cm.triangles[e] || std::size_t(t[0]) >= pat.size() || std::size_t(t[1]) >= pat.size() ||
        std::size_t(t[2]) >= pat.size())
      continue;
    const Eigen::Vector3d c = (pat[std::size_t(t[0])] + pat[std::size_t(t[1])] + pat[std::size_t(t[2])]) / 3.0;
    const double phi_c = 2.0 * half * (cm.gore[e] + 0.5);
    const double seam = std::hypot(c.x(), c.y()) * std::cos(std::atan2(c.y(), c.x()) - phi_c) / std::cos(half);
    const double u = (seam - Rv) / (Rs - Rv);
    band[e] = std::clamp(int(std::floor(u * cloth_band_count)), 0, cloth_band_count - 1);
  }
  return band;
}

namespace detail {

/// One run of a built drop: the stepper (constructed in place: the coupling holds
/// pointers into it), its outputs and its loop.
template <class Fluid, class Coupling>
class drop_run {
 public:
  using stepper_type = explicit_stepper<Fluid, structure::drop_assembly, Coupling, drop_frame_target_t<Fluid>>;
  static constexpr bool block_mesh = coupling::block_fluid<Fluid>;
  /// Level subcycling is possible: a block mesh and a coupling that patches its faces.
  static constexpr bool can_subcycle = block_mesh && requires(stepper_type & s) { s.step_subcycled(1.0); };

  /// `levels`: the block mesh's finest level (block meshes only).
  drop_run(const drop_config& c, const drop_setup& su, Fluid&& f, structure::drop_assembly&& a, Coupling&& cpl,
           int levels = 0)
      : levels_(levels),
        c_(c),
        su_(su),
        s_(std::move(f), std::move(a), std::move(cpl), drop_frame_target<Fluid>(su.params.gravity)),
        observe_(su.scene),
        pgs_{su.alpha},
        p_offset_(pgs_.pressure_offset(su.params.air_pressure)),
        c_air_(gas::ideal{}.sound_speed(su.params.air_density, su.params.air_pressure)),
        files_(!c.out.empty() && (!c.halo || c.halo->rank() == 0)),
        filter_(io::gaussian_lowpass(c.force_cutoff, c.history_every)),
        signature_(drop_signature(c, su)) {
    if constexpr (block_mesh) {
      if (c.halo) s_.fluid().set_halo(c.halo);
    } else {
      require(!c.halo, "parachute_drop: only the block mesh (--mesh blocks) runs over several processes");
    }
  }
  drop_run(const drop_run&) = delete;
  drop_run& operator=(const drop_run&) = delete;

  drop_result run(const drop_progress& progress) {
    drop_result res;
    const auto& nd = s_.structure().node_set();
    history_ = &res.history;
    if (!c_.restart.empty()) res.history = restart();
    if (c_.captive_speed > 0) hold_captive();
    open_outputs();
    emit(false);  // carried rows: those whose filter window is complete
    if constexpr (block_mesh) {
      if (c_.restart.empty()) regrid();
      static_rebalance_at_ = s_.steps() + 5;
      res.cells = long(s_.fluid().cell_count());
    } else {
      const auto& g = s_.fluid().grid();
      res.cells = long(g.n(0)) * g.n(1) * g.n(2);
    }
    res.nodes = long(nd.size());
    res.triangles = long(su_.scene.triangles.size());
    res.fabric = drop_fabric_label(c_, su_);
    if (!c_.quiet) {
      char mesh[160];
      if constexpr (block_mesh)
        std::snprintf(mesh, sizeof mesh, "%ld blocks of %d^3, levels 0-%d", long(s_.fluid().block_count()),
                      c_.block_size, levels_);
      else
        std::snprintf(mesh, sizeof mesh, "%ldx%ldx%ld", long(s_.fluid().grid().n(0)), long(s_.fluid().grid().n(1)),
                      long(s_.fluid().grid().n(2)));
      std::fprintf(stderr,
                   "parachute_drop: %s canopy, %s, %s: %ld fluid cells (%s, h = %.4g m near the canopy), "
                   "%ld structure nodes, %zu triangles, coupling %s, %s box, PGS alpha %g, t_end %.3g s\n",
                   su_.params.name.c_str(), res.fabric.c_str(), c_.resolution.c_str(), res.cells, mesh, su_.box.cell,
                   res.nodes, su_.scene.triangles.size(), c_.coupling.c_str(), c_.box.c_str(), su_.alpha, c_.t_end);
    }
    const auto t0 = std::chrono::steady_clock::now();
    long substeps = 0;
    try {
      substeps = loop(res.history, progress);
    } catch (...) {
      // Stopped by an error: the rows still waiting for their filter window, with the
      // end-of-run rule, so history.csv holds every row computed.
      try {
        emit(true);
      } catch (...) {
      }
      throw;
    }
    emit(true);
    if (hist_) hist_->close();
    res.steps = s_.steps();
    res.substeps_per_step = double(substeps) / double(std::max(1L, s_.steps()));
    res.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    res.times = s_.timings();
    res.mean_cells = counted_steps_ ? cell_steps_ / double(counted_steps_) : double(res.cells);
    res.max_cells = std::max(res.cells, max_cells_);
    res.regrids = regrids_;
    res.canopy_travel_ratio = travel_ratio_;
    if (mesh_csv_) mesh_csv_->close();
    if (cloth_csv_) cloth_csv_->close();
    if (bands_csv_) bands_csv_->close();
    if (!c_.quiet)  // subcycled, a step is one of the coarsest level, holding 2^levels of the finest
      std::fprintf(stderr,
                   "parachute_drop: %ld fluid steps%s, %.1f structure substeps per step; wall %.1f s (frame %.1f, "
                   "exchange %.1f, structure %.1f, fluid %.1f)\n",
                   res.steps, c_.subcycle ? " of the coarsest level" : "", res.substeps_per_step, res.wall,
                   res.times.move_frame, res.times.exchange, res.times.structure, res.times.fluid);
    if (!c_.quiet && block_mesh)
      std::fprintf(stderr,
                   "parachute_drop: block mesh: %.0f leaf cells on average over the steps, %ld at most, %ld regrids "
                   "changed it (mesh.csv); the canopy moved at most %.2f of the travel its buffer allowed between "
                   "regrids\n",
                   res.mean_cells, res.max_cells, res.regrids, res.canopy_travel_ratio);
    io::summary_options so;
    so.force_cutoff = c_.force_cutoff;
    so.sample_interval = c_.history_every;
    res.summary = io::summarize(res.history, res.fabric, so);
    if (!c_.quiet) report(res.summary);
    if (files_) io::write_drop_summary(out() / "summary.csv", res.summary);
    return res;
  }

 private:
  std::filesystem::path out() const { return std::filesystem::path(c_.out); }

  /// The read-out behind the summary row, on stderr (io::summary_report).
  void report(const io::drop_summary& m) const {
    std::fputs(io::summary_report(m, c_.force_cutoff, "parachute_drop: ").c_str(), stderr);
  }

  /// The time loop from the start (its first row) or the restored state to t_end; returns
  /// the structure substeps taken.
  long loop(std::vector<io::drop_history_row>& history, const drop_progress& progress) {
    if (c_.restart.empty()) record(history);
    write_outputs();
    // Output times are n·history_every with an integer n (not a running sum), so a run
    // restarted from a checkpoint picks exactly the steps of the uninterrupted run.
    long n_out = long(std::floor(s_.time() / c_.history_every + 1e-6)) + 1;
    double next_out = c_.history_every * double(n_out);
    const std::vector<double>& slices = c_.slice_times;
    std::size_t next_slice = 0;
    while (next_slice < slices.size() && slices[next_slice] <= s_.time() + 1e-9 && !c_.restart.empty()) ++next_slice;
    while (!c_.out.empty() && next_slice < slices.size() && slices[next_slice] <= 0) {
      write_slice(0.0);
      ++next_slice;
    }
    long substeps = 0;
    while (s_.time() < c_.t_end - 1e-12) {
      if constexpr (block_mesh) {
        if (!c_.static_mesh && s_.steps() % c_.refine_every == 0) regrid();
        else if (c_.static_mesh && s_.steps() == static_rebalance_at_)
          s_.fluid().rebalance();  // a mesh that stays: cut once by the measured costs (over MPI)
      }
      const double dt = next_step(std::min(next_out, c_.t_end));
      check_fixed_box();
      update_wall_distance();
      if constexpr (can_subcycle) {
        if (c_.subcycle) s_.step_subcycled(dt);
        else s_.step(dt);
      } else {
        s_.step(dt);
      }
      if constexpr (block_mesh) {
        cell_steps_ += double(s_.fluid().cell_count());
        ++counted_steps_;
      }
      substeps += s_.last_substeps();
      if (s_.time() >= next_out - 1e-9 * c_.history_every || s_.time() >= c_.t_end - 1e-12) {
        record(history);
        write_outputs();
        next_out = c_.history_every * double(++n_out);
        while (!c_.out.empty() && next_slice < slices.size() && s_.time() >= slices[next_slice] - 1e-9)
          write_slice(slices[next_slice++]);
      }
      if (progress) progress(s_.time(), s_.steps(), false);
    }
    if (progress) progress(s_.time(), s_.steps(), true);
    return substeps;
  }

  /// The stepper's state from the checkpoint (its scene signature compared first); the
  /// history rows up to its time, from the checkpoint.
  std::vector<io::drop_history_row> restart() {
    // A captive run may give the cloth another fabric's law: the checkpoint is of a run
    // with the canopy's own.
    io::scene_signature sig = signature_;
    if (c_.captive_speed > 0) {
      drop_config own = c_;
      own.permeability.clear();
      sig = drop_signature(own, su_);
    }
    io::drop_history_record previous;
    io::load_checkpoint(c_.restart, sig, s_, previous);
    // The checkpoint holds the fluid, not the far field: a run restarted with another α
    // (or scene pressure) would put the restored air against a different ambient (the
    // signature names α; this guards a scene pressure that is not in it).
    const double q = corner_pressure(), q_inf = pgs_.scaled_ambient(su_.params.air_pressure);
    require(q > 0.5 * q_inf && q < 2.0 * q_inf, "parachute_drop: checkpoint '", c_.restart, "' holds air at ", q,
            " Pa in a corner cell, but this run's ambient is ", q_inf, " Pa (PGS alpha ", su_.alpha,
            "): restart with the --pgs and scene of the run that wrote it");
    require(c_.t_end > s_.time() + 1e-12, "parachute_drop: t_end ", c_.t_end,
            " s is not after the time of checkpoint '", c_.restart, "', ", s_.time(), " s: nothing to run");
    require(!previous.rows.empty() && previous.rows.back().t <= s_.time() + 1e-12, "parachute_drop: checkpoint '",
            c_.restart, "' holds ", previous.rows.size(), " history rows, the last not at or before its time ",
            s_.time(), " s");
    // Every process read the whole mesh; each keeps what it computes and its ghosts read.
    if constexpr (block_mesh)
      if (distributed()) s_.fluid().release_fetched();
    if (!c_.quiet)
      std::fprintf(stderr, "parachute_drop: restarted from %s at t = %.6g s (%zu history rows carried)\n",
                   c_.restart.c_str(), s_.time(), previous.rows.size());
    return std::move(previous.rows);
  }

  /// --captive: hold the structure in its restored shape, moving at the captive speed
  /// along the canopy's axis (vent centre → line confluence).
  void hold_captive() {
    const auto& nd = s_.structure().node_set();
    const Eigen::Vector3d axis = nd.position(su_.scene.suspension.confluence) - observe_.vent_point(nd);
    require(axis.norm() > 0, "parachute_drop: --captive: the canopy's axis has zero length");
    const Eigen::Vector3d V = c_.captive_speed * axis.normalized();
    using scope = structure::drop_assembly::hold_scope;
    const bool whole = c_.captive_hold == "structure";
    s_.structure().hold(V, whole ? scope::structure : scope::bodies);
    if (!c_.quiet && whole)
      std::fprintf(stderr,
                   "parachute_drop: captive canopy: the riser force, C_D, v_T and descent mode of history.csv and "
                   "summary.csv describe the held structure, not a descent\n");
    if (!c_.quiet)
      std::fprintf(stderr,
                   "parachute_drop: captive canopy: %s at t = %.6g s, moving at %.4g m/s along the canopy's axis "
                   "(%.4f, %.4f, %.4f); its drag is in cloth_pressure.csv\n",
                   whole ? "the structure held in its shape" : "the payload held (the canopy and lines free)",
                   s_.time(), c_.captive_speed, V.x() / c_.captive_speed, V.y() / c_.captive_speed,
                   V.z() / c_.captive_speed);
  }

  /// history.csv (its header; the rows follow through `emit`); the VTK series.
  void open_outputs() {
    next_vtk_ = s_.time();
    next_ckpt_ = s_.time() + c_.checkpoint_every;
    if (!files_) return;
    hist_.emplace(out() / "history.csv");
    if constexpr (block_mesh) {
      // mesh.csv: the block mesh after every regrid that changed it.
      std::vector<std::string> cols{"t", "step", "blocks", "cells"};
      for (int l = 0; l <= levels_; ++l) cols.push_back("cells_level_" + std::to_string(l));
      mesh_csv_.emplace(out() / "mesh.csv", std::move(cols), resume_options());
    }
    if constexpr (cloth_sides) {
      cloth_csv_.emplace(out() / "cloth_pressure.csv",
                         std::vector<std::string>(std::begin(cloth_columns), std::end(cloth_columns)),
                         resume_options());
      std::vector<std::string> cols{"t"};
      for (int k = 1; k <= cloth_band_count; ++k)
        for (const char* name : {"area", "windward_cp", "leeward_cp", "pressure_drag_coefficient", "through_fraction"})
          cols.push_back("band" + std::to_string(k) + "_" + name);
      bands_csv_.emplace(out() / "cloth_bands.csv", std::move(cols), resume_options());
      band_of_ = cloth_bands(su_.scene);
    }
    if (c_.vtk_every > 0) {
      std::filesystem::create_directories(out() / "vtk");
      pvd_.emplace(out() / "drop.pvd", c_.restart.empty() ? std::numeric_limits<double>::quiet_NaN() : s_.time());
    }
  }

  /// A CSV beside history.csv: a new file, or on a restart the old one's rows up to now.
  io::csv_options resume_options() const {
    io::csv_options o;
    if (!c_.restart.empty()) o.resume_after = s_.time();
    return o;
  }

  /// The columns of cloth_pressure.csv (embedded coupling; definitions in record_cloth).
  static constexpr const char* cloth_columns[] = {
      "t",           "projected_area", "windward_pressure",         "leeward_pressure", "through_flow",
      "windward_cp", "leeward_cp",     "pressure_drag_coefficient", "through_fraction", "side_force_coefficient"};

  /// A row of cloth_pressure.csv: the canopy's cloth seen along the stream e = −V/|V| (V the
  /// payload's velocity; the box axis when it is at rest), from the embedded coupling's wall
  /// pressures of the last step (coupling::cloth_side_means): S = projected_area (m²), the
  /// windward and leeward pressures as physical gauge pressures p − p∞ (Pa; PGS leaves
  /// differences physical), the through-flow Q (m³/s) along the canopy elements' normals (the
  /// flat pattern's +z: out of the canopy, from its mouth side to its crown side, as the
  /// fabric law gives it at each face's wall pressure jump); with q = ½ ρ∞ |V|²,
  /// windward_cp and leeward_cp = (p − p∞)/q, pressure_drag_coefficient = (p_w − p_l) S/(q S0)
  /// (the cloth's pressure load along the stream on S0 = π D0²/4; in a steady descent without
  /// swing about the history's drag_coefficient, the rest the swept terms; in a swing about
  /// cos θ of it, the load leaving the payload's path: validation §3.5),
  /// through_fraction = Q/(|V| S), side_force_coefficient = |F − (F·e) e|/(q S0) with F the
  /// cloth's pressure load vector (the load across the stream: the lift of a canopy at an
  /// angle to it; validation §3.7). The two pressures and the five coefficients are nan while
  /// no face is seen along e (S = 0: before the first step), the coefficients also while the
  /// payload is at rest.
  void record_cloth(const io::drop_history_row& r) {
    if constexpr (cloth_sides) {
      if (!cloth_csv_) return;
      const Eigen::Vector3d V = structure::payload(s_.structure()).body().mass_centre_velocity();
      const double v = V.norm();
      const Eigen::Vector3d e = v > 0 ? Eigen::Vector3d(-V / v) : Eigen::Vector3d(s_.fluid().pose().R.col(2));
      const auto cs = s_.coupling().cloth_sides(e);
      const double q_inf = pgs_.scaled_ambient(su_.params.air_pressure);
      const double pw = cs.windward_pressure - q_inf, pl = cs.leeward_pressure - q_inf;
      const double q = 0.5 * su_.params.air_density * v * v, nan = std::numeric_limits<double>::quiet_NaN();
      const bool seen = cs.projected_area > 0, moving = seen && q > 0;
      cloth_csv_->row(
          {r.t, cs.projected_area, seen ? pw : nan, seen ? pl : nan, cs.through_flow, moving ? pw / q : nan,
           moving ? pl / q : nan, moving ? (pw - pl) * cs.projected_area / (q * su_.params.nominal_area()) : nan,
           moving ? cs.through_flow / (v * cs.projected_area) : nan,
           moving ? (cs.pressure_load - cs.pressure_load.dot(e) * e).norm() / (q * su_.params.nominal_area()) : nan});
      // cloth_bands.csv: the same per ring of the cut pattern (cloth_bands), the pressure
      // drag and the through-fraction on the whole canopy's q S0 and V S, so the bands add up.
      std::vector<double> row{r.t};
      for (int k = 0; k < cloth_band_count; ++k) {
        const auto b = s_.coupling().cloth_sides(e, [&](index_t el) {
          return std::size_t(el) < band_of_.size() && band_of_[std::size_t(el)] == k;
        });
        const double bw = b.windward_pressure - q_inf, bl = b.leeward_pressure - q_inf;
        const bool bseen = b.projected_area > 0 && moving;
        row.insert(row.end(),
                   {b.projected_area, bseen ? bw / q : nan, bseen ? bl / q : nan,
                    bseen ? (bw - bl) * b.projected_area / (q * su_.params.nominal_area()) : (moving ? 0.0 : nan),
                    moving ? b.through_flow / (v * cs.projected_area) : nan});
      }
      bands_csv_->row(row);
    } else {
      (void)r;
    }
  }

  /// The history row of now, the αM guard, the row to history.csv.
  void record(std::vector<io::drop_history_row>& history) {
    history.push_back(observe_(s_.time(), s_.structure()));
    record_cloth(history.back());
    const io::drop_history_row& r = history.back();
    const double alpha = su_.alpha;
    if (alpha > 1.0 && !warned_mach_ && !c_.quiet && alpha * r.speed / c_air_ > 0.3) {
      warned_mach_ = true;
      std::fprintf(stderr,
                   "\nparachute_drop: warning: at t = %.3g s the payload moves at %.3g m/s, alpha M = %.2f > 0.3 with "
                   "PGS alpha %g: compressibility errors grow as (alpha M)^2; use --pgs %.0f or lower for this speed\n",
                   r.t, r.speed, alpha * r.speed / c_air_, alpha, std::max(1.0, std::floor(0.2 * c_air_ / r.speed)));
    }
    emit(false);
  }

  /// The rows whose open-force filter window is complete (every row left when `end`):
  /// their open_force_filtered filled, written to history.csv and flushed.
  void emit(bool end) {
    const auto rows = end ? filter_.finish(*history_) : filter_.complete(*history_);
    if (!hist_ || rows.empty()) return;
    for (const auto& r : rows) hist_->append(r);
    hist_->flush();
  }

  /// VTK files and the checkpoint when their instants are reached (on every process: a
  /// distributed mesh brings each process the blocks it writes, collectively; process 0
  /// writes, but for the fluid's VTK pieces, one per process).
  void write_outputs() {
    const bool vtk = !c_.out.empty() && c_.vtk_every > 0 && s_.time() >= next_vtk_ - 1e-9 * c_.history_every;
    const bool ckpt = !c_.out.empty() && c_.checkpoint_every > 0 && s_.time() >= next_ckpt_ - 1e-9 * c_.history_every;
    if constexpr (block_mesh)
      if (distributed()) {
        auto& f = s_.fluid();
        if (vtk) {  // a piece's blocks and their face neighbours (the vorticity's)
          const auto r = io::piece_blocks(f.block_count(), c_.halo->rank(), c_.halo->size());
          std::vector<index_t> piece;
          for (index_t id = r.first; id < r.last; ++id) piece.push_back(id);
          f.fetch(f.with_face_neighbours(piece));
        }
        if (ckpt) f.gather_to(0);  // the whole mesh on the process writing the file
      }
    if (vtk) {
      char nm[64];
      std::snprintf(nm, sizeof nm, "%09.5f", s_.time());
      io::vtk_options vo;
      vo.pressure_offset = p_offset_;
      // Several processes: each writes its piece of the block mesh, process 0 the .pvtu index.
      const bool pieces = block_mesh && c_.halo && c_.halo->size() > 1;
      const std::string fs = c_.out + "/vtk/structure_" + nm + ".vtu", ff = c_.out + "/vtk/fluid_" + nm +
                                                                            (pieces       ? ".pvtu"
                                                                             : block_mesh ? ".vtu"
                                                                                          : ".vts");
      if constexpr (block_mesh)
        if (pieces) {
          std::filesystem::create_directories(out() / "vtk");
          io::write_pvtu_piece(ff, s_.fluid(), vo, c_.halo->rank(), c_.halo->size());
        }
      if (pvd_) {
        io::write_vtu(fs, s_.structure());
        if constexpr (block_mesh) {
          if (!pieces) io::write_vtu(ff, s_.fluid(), vo);  // leaf cells as hexahedra
        } else {
          io::write_vts(ff, s_.fluid(), vo);
        }
        pvd_->add(s_.time(), ff, 0);
        pvd_->add(s_.time(), fs, 1);
      }
      next_vtk_ += c_.vtk_every;
    }
    if (ckpt) {
      if (files_) io::save_checkpoint(c_.out + "/checkpoint.ckpt", signature_, s_, io::drop_history_record{*history_});
      next_ckpt_ += c_.checkpoint_every;
    }
    if constexpr (block_mesh)
      if (distributed() && (vtk || ckpt)) s_.fluid().release_fetched();
  }

  void write_slice(double t_label) {
    if constexpr (block_mesh)
      if (distributed()) {  // the blocks the mid-plane ξ_y ≈ 0 cuts, to the writing process
        auto& f = s_.fluid();
        const double h = f.layout().cell_width(1, f.tree().finest_level());
        f.fetch(files_ ? f.blocks_meeting(1, -h, h) : std::vector<index_t>{});
      }
    if (files_)
      io::write_drop_slice(out(), t_label, s_.fluid(), s_.structure().node_set(), su_.scene.canopy_nodes,
                           structure::payload(s_.structure()).body().mass_centre_velocity(), p_offset_);
    if constexpr (block_mesh)
      if (distributed()) s_.fluid().release_fetched();
  }

  /// Whether the block mesh is split over several processes.
  bool distributed() const { return c_.halo && c_.halo->size() > 1; }

  /// Block mesh: refine to the canopy's current place (drop_block_target) and, with
  /// --refine-vorticity X, where the wake turns the velocity by more than X times the
  /// payload's speed (at least 1 m/s) across a cell (blocks::leaf_indicator on
  /// vorticity_indicator, one level per regrid); a row of mesh.csv when the mesh changed
  /// (and for the first mesh).
  void regrid() {
    if constexpr (block_mesh) {
      auto& f = s_.fluid();
      // Subcycled, a step of the coarsest level holds 2^levels steps of the finest, each of
      // which the coupling's travel limit allows a cell: the buffer counts those, or, when a
      // regrid comes every step, twice the canopy's travel at its present speed over the
      // coming step (its length from the present mesh, and the step is held to it) plus a cell.
      const int finest_steps = c_.refine_every * (c_.subcycle ? 1 << levels_ : 1);
      const auto& nd = s_.structure().node_set();
      double window = 0;
      step_cap_ = std::numeric_limits<double>::infinity();
      if (finest_steps > 1 && c_.refine_every == 1 && !c_.static_mesh) window = stable_step();
      const double travel = drop_canopy_travel(f, nd, su_.scene.canopy_nodes, levels_, finest_steps, window);
      if (travel < double(finest_steps)) step_cap_ = window;
      note_canopy_travel(travel);
      const auto canopy = drop_block_target(f, nd, su_.scene.canopy_nodes, su_.scene.triangles, levels_, travel);
      const auto column = drop_column_target(f.layout(), su_.box, c_.refine_column || c_.static_mesh ? levels_ : 0);
      const auto near = fluid::blocks::max_of{canopy, column};
      bool changed = false;
      if (c_.refine_vorticity > 0) {
        const double U = std::max(1.0, structure::payload(s_.structure()).body().mass_centre_velocity().norm());
        const double hi = c_.refine_vorticity * U;
        changed = f.regrid(fluid::blocks::max_of{near, fluid::blocks::leaf_indicator(f.tree(), f.vorticity_indicator(),
                                                                                     hi, 0.25 * hi, levels_)},
                           levels_);
      } else {
        changed = f.regrid(near, levels_);
      }
      if (!changed && mesh_rows_ > 0) return;
      if (changed) ++regrids_;
      max_cells_ = std::max(max_cells_, long(s_.fluid().cell_count()));
      if (!mesh_csv_) return;
      std::vector<double> row{s_.time(), double(s_.steps()), double(s_.fluid().block_count()),
                              double(s_.fluid().cell_count())};
      row.resize(row.size() + std::size_t(levels_ + 1), 0.0);
      const double per_block = double(s_.fluid().block_cells()) * double(s_.fluid().block_cells()) *
                               double(s_.fluid().block_cells());
      for (const auto& q : s_.fluid().tree().leaves()) row[4 + std::size_t(q.level)] += per_block;
      mesh_csv_->row(row);
      ++mesh_rows_;
    }
  }

  /// The canopy's largest displacement relative to the box since the last regrid, as a
  /// fraction of the travel that regrid's buffer allowed (kept as the run's maximum,
  /// drop_result::canopy_travel_ratio); then this regrid's positions and travel.
  void note_canopy_travel(double travel) {
    const auto& f = s_.fluid();
    const auto& nd = s_.structure().node_set();
    const std::size_t n = std::size_t(su_.scene.canopy_nodes);
    if (travel_from_.size() == n && travel_allowed_ > 0) {
      double moved = 0;
      for (std::size_t i = 0; i < n; ++i)
        moved = std::max(moved, (f.pose().to_box(nd.position(index_t(i))) - travel_from_[i]).norm());
      travel_ratio_ = std::max(travel_ratio_, moved / travel_allowed_);
    }
    travel_from_.resize(n);
    for (std::size_t i = 0; i < n; ++i) travel_from_[i] = f.pose().to_box(nd.position(index_t(i)));
    travel_allowed_ = travel * drop_cell_width(f.layout(), levels_);
  }

  /// Mixing length: d_w from the structure's nodes (canopy and lines, box coordinates of
  /// now) within reach C_l L_ref/κ (on a block, min(C_l L_ref, C_Δ Δ)/κ), where κ d_w can
  /// be the closure's smallest length (fluid/wall_distance.hpp); refreshed before every
  /// step, on the blocks this process computes. (A checkpoint's wall distance is therefore
  /// not the same bytes for every process count; it is refilled before the next step.)
  void update_wall_distance() {
    if constexpr (Fluid::needs_wall_distance) {
      auto& f = s_.fluid();
      const auto& nd = s_.structure().node_set();
      const Eigen::Matrix3d Rt = f.pose().R.transpose();
      wall_points_.resize(std::size_t(nd.size()));
      for (index_t i = 0; i < nd.size(); ++i) wall_points_[std::size_t(i)] = Rt * (nd.position(i) - f.pose().X);
      // Over MPI, the blocks this process computes (their ghosts too: a ghost's eddy
      // viscosity is its neighbour's), each within the closure's reach for its cells.
      f.wall_distance_from(wall_points_);
    }
  }

  /// Pressure of a corner cell of the box (the restart's check of the ambient).
  double corner_pressure() const {
    if constexpr (block_mesh) {
      const auto& b = s_.fluid().block_at(0);
      return to_prim(fluid::detail::load_cons(fluid::detail::conserved_ptrs(b.U), b.grid.index(0, 0, 0)),
                     s_.fluid().gas())
          .p;
    } else {
      return s_.fluid().primitive(0, 0, 0).p;
    }
  }

  /// The stable step, refused when it collapses, shortened to land on `target`.
  double next_step(double target) {
    // Held to the step the last regrid's canopy buffer was made for (once: the cap is
    // the coming step's only).
    const double dt = std::min(stable_step(), std::exchange(step_cap_, std::numeric_limits<double>::infinity()));
    if (!(dt > 1e-9 * c_.history_every) || !std::isfinite(dt))
      throw numerical_failure(parafsi::detail::concat("parachute_drop: the stable step collapsed to ", dt, " s at t = ",
                                                      s_.time(), " s (coupling ", c_.coupling, "); stopping"),
                              -1, s_.time());
    return landing_step(dt, target - s_.time());
  }

  /// The stable step on the present mesh (of the coarsest level when subcycled).
  double stable_step() {
    if constexpr (can_subcycle) return c_.subcycle ? s_.stable_dt_subcycled(c_.cfl) : s_.stable_dt(c_.cfl);
    else return s_.stable_dt(c_.cfl);
  }

  /// Fixed box: stop with a message before the payload leaves the refined column.
  void check_fixed_box() const {
    if (!su_.fixed_box) return;
    const auto& f = s_.fluid();
    const Eigen::Vector3d xp = structure::payload(s_.structure()).body().mass_centre();
    const Eigen::Vector3d xi = f.pose().R.transpose() * (xp - f.pose().X);
    const double fall = su_.box.fall;
    if (xi.z() < -fall)
      throw numerical_failure(parafsi::detail::concat("parachute_drop: the payload has fallen ", -xi.z(),
                                                      " m, beyond the fixed box's fall length ", fall,
                                                      " m, at t = ", s_.time(), " s; raise --fixed-fall"),
                              -1, s_.time());
  }

  int levels_ = 0;                          ///< block mesh: the finest level
  std::optional<io::csv_writer> mesh_csv_;  ///< block mesh: mesh.csv
  /// The coupling reports the pressures on the two sides of the cloth (embedded).
  static constexpr bool cloth_sides = requires(const Coupling& c) { c.cloth_sides(Eigen::Vector3d::UnitZ()); };
  std::optional<io::csv_writer> cloth_csv_;   ///< embedded coupling: cloth_pressure.csv
  std::optional<io::csv_writer> bands_csv_;   ///< embedded coupling: cloth_bands.csv
  std::vector<int> band_of_;                  ///< the ring (cloth_bands) of each canopy triangle
  std::vector<Eigen::Vector3d> wall_points_;  ///< mixing length: the structure's nodes in box coordinates
  long mesh_rows_ = 0, regrids_ = 0, max_cells_ = 0, counted_steps_ = 0;
  /// Block mesh: the longest step the last regrid's canopy buffer allows (drop_canopy_travel).
  double step_cap_ = std::numeric_limits<double>::infinity();
  /// Block mesh: the canopy's box positions at the last regrid, the distance its buffer
  /// allowed them to travel, and the largest fraction of it used (note_canopy_travel).
  std::vector<Eigen::Vector3d> travel_from_;
  double travel_allowed_ = 0, travel_ratio_ = 0;
  long static_rebalance_at_ = 0;  ///< --static-mesh: the step of its one cut by measured cost
  double cell_steps_ = 0;         ///< Σ over steps of the leaf cells
  const drop_config& c_;
  const drop_setup& su_;
  stepper_type s_;
  io::drop_observer observe_;
  fluid::pressure_gradient_scaling pgs_;
  double p_offset_, c_air_;
  bool files_;
  io::drop_history_filter filter_;
  std::optional<io::drop_history_writer> hist_;
  std::optional<io::pvd_writer> pvd_;
  double next_vtk_ = 0, next_ckpt_ = 0;
  bool warned_mach_ = false;
  io::scene_signature signature_;
  std::vector<io::drop_history_row>* history_ = nullptr;  ///< the rows so far, saved with a checkpoint
};

/// f(viscosity, frame) for the setup's choices (resolved once: everything below is
/// compile-time).
template <class F>
drop_result with_fluid_policies(const drop_setup& su, const std::string& closure_name, F&& f) {
  auto with_frame = [&](auto viscosity, auto closure) -> drop_result {
    if (su.fixed_box) return f(viscosity, closure, frame::fixed{});
    frame::follow_payload follow;
    follow.axis = {0.0, 0.0, -1.0};  // box −z turns to the payload velocity
    follow.max_rate = 10.0;          // rad/s
    return f(viscosity, closure, follow);
  };
  if (!su.viscous) return with_frame(viscosity::inviscid{}, turbulence::none{});
  viscosity::constant visc;
  visc.mu_value = su.params.air_viscosity;
  if (closure_name == "mixing_length") {
    turbulence::prandtl_mixing_length ml;
    ml.ref_length = su.params.canopy.nominal_diameter;
    ml.mu_cap = 1000.0 * su.params.air_viscosity;
    return with_frame(visc, ml);
  }
  if (closure_name == "smagorinsky") {
    turbulence::smagorinsky sm;
    sm.mu_cap = 1000.0 * su.params.air_viscosity;
    return with_frame(visc, sm);
  }
  return with_frame(visc, turbulence::none{});
}

}  // namespace detail

/// Run the drop of `c` (rules in the file comment); `progress` is told every step.
inline drop_result run_drop(const drop_config& c, const drop_progress& progress = {}) {
  const drop_setup su = make_drop_setup(c);
  const model::drop_scene& S = su.scene;
  const model::drop_scene_parameters& P = su.params;
  if (!c.out.empty()) std::filesystem::create_directories(c.out);
  const fluid::rectilinear_grid grid = make_drop_grid(su.box);
  // Pressure-gradient scaling: the air is held at p∞/α² (sound speed c/α); outputs show
  // physical pressures p∞ + (q − p∞/α²).
  const fluid::pressure_gradient_scaling pgs{su.alpha};
  pgs.validate();
  const fluid::prim<double> air{P.air_density, {0.0, 0.0, 0.0}, pgs.scaled_ambient(P.air_pressure)};
  auto bc = boundary::set::all(boundary::far_field{air.rho, air.u, air.p});
  bc.layer = {3, 0.5};
  return detail::with_fluid_policies(su, c.closure(), [&](auto visc, auto closure, auto frame) -> drop_result {
    structure::drop_assembly chute = structure::make_drop_assembly(S, c.membrane_damping);
    const porosity::ergun law = drop_porosity_law(c, su);
    if (c.mesh == "blocks") {
      // The block mesh: one level to start with, refined to the canopy before the first step.
      const auto [lay, levels] = make_drop_blocks(su.box, c.block_size, c.root_blocks);
      fluid::block_solver fl{fluid::blocks::tree(lay.root_blocks), lay,  bc,      flux::hllc_lm{},
                             recon::muscl<limiter::van_leer>{},    visc, closure, frame};
      fl.fill_uniform(air);
      place_drop_box(fl, su.box, chute);
      if (parallel::max_threads() > 1) fl.set_threading(true);
      if (c.coupling == "embedded") {
        coupling::embedded_options eo;
        eo.impedance = c.impedance;
        eo.law_on = coupling::through_flow_law_named(c.through_flow);
        auto go = [&](auto cpl) -> drop_result {
          detail::drop_run<decltype(fl), decltype(cpl)> run{c,     su, std::move(fl), std::move(chute), std::move(cpl),
                                                            levels};
          return run.run(progress);
        };
        if (c.one_sided()) return go(coupling::embedded<porosity::ergun, true>{law, eo});
        return go(coupling::embedded{law, eo});
      }
      coupling::penalty_options po;
      po.pfac = c.pfac;
      po.stiffening = c.stiffening;
      po.damping_ratio = c.coupling_damping;
      using C = coupling::penalty<porosity::ergun>;
      detail::drop_run<decltype(fl), C> run{c, su, std::move(fl), std::move(chute), C{law, po}, levels};
      return run.run(progress);
    }
    fluid::solver fl{grid, bc, flux::hllc_lm{}, recon::muscl<limiter::van_leer>{}, visc, closure, frame};
    fl.initialize([&](const Eigen::Vector3d&) { return air; });
    place_drop_box(fl, su.box, chute);
    if (parallel::max_threads() > 1) fl.set_threading(true);
    auto go = [&](auto cpl) -> drop_result {
      detail::drop_run<decltype(fl), decltype(cpl)> run{c, su, std::move(fl), std::move(chute), std::move(cpl)};
      return run.run(progress);
    };
    if (c.coupling == "embedded") {
      coupling::embedded_options eo;
      eo.impedance = c.impedance;
      eo.law_on = coupling::through_flow_law_named(c.through_flow);
      if (c.one_sided()) return go(coupling::embedded<porosity::ergun, true>{law, eo});
      return go(coupling::embedded{law, eo});
    }
    coupling::penalty_options po;
    po.pfac = c.pfac;
    po.stiffening = c.stiffening;
    po.damping_ratio = c.coupling_damping;
    return go(coupling::penalty{law, po});
  });
}

}  // namespace parafsi::scene
