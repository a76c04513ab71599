/// \file block_solver.hpp
/// The compressible ALE Navier–Stokes finite volumes of solver.hpp on a block-structured
/// mesh: the same moving box, split into blocks of n³ uniform cells that are the leaves of
/// a 2:1-balanced octree (blocks/tree.hpp). Each block is a small rectilinear grid with two
/// ghost layers, swept by the very kernels of the box solver (detail/sweep.hpp …), so a
/// one-level block mesh gives the box solver's answer to round-off. One time step for all
/// levels (the membranes sit on the finest level, which sets the step anyway); every
/// Runge–Kutta stage is the recipe
///   exchange face ghosts (copy · restrict · prolong, blocks/exchange.hpp; with a viscosity
///   policy the edge ghosts one cell deep too) → boundary ghosts → primitives where the kernels read
///   them → three flux sweeps per block, keeping boundary-face fluxes → viscous pass (with
///   a viscosity policy; its boundary-face fluxes join the kept ones) → coarse–fine flux
///   correction (blocks/flux_correction.hpp) → the coupling's face patches → sources and
///   sponge → update,
/// which conserves mass, momentum and energy to round-off across levels. Blocks run in
/// parallel (OpenMP) with serial kernels inside, so results do not depend on the thread
/// count.
///
/// The frame (translate, rigid, follow_payload), the gas and the flux, reconstruction and
/// time policies are those of solver.hpp, and so are the optional per-cell sources (held
/// constant over a step) and the far-field sponge: σ = s c_∞/L_s ((L − d)/L)³ with d the
/// cell centre's distance from a far-field face in root-level cells less ½ and L_s = L
/// root-level cells, which is the box solver's layer on a one-level mesh. Viscosity, heat
/// conduction and eddy-viscosity closures run per block (μ_t and the mixing length's wall
/// distance in mesh-wide fields; a block's wall distance covers its ghosts too).
///
/// References: Berger M.J., Colella P. (1989) J. Comput. Phys. 82:64;
///   Stone J.M. et al. (2020) ApJS 249:4 (Athena++); Zhang W. et al. (2019) JOSS 4:1370 (AMReX).
#pragma once
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <tuple>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/policy.hpp"
#include "../core/soa.hpp"
#include "blocks/exchange.hpp"
#include "blocks/flux_correction.hpp"
#include "blocks/halo.hpp"
#include "blocks/layout.hpp"
#include "blocks/refine.hpp"
#include "blocks/tree.hpp"
#include "boundary/condition.hpp"
#include "detail/ghosts.hpp"
#include "detail/patch_faces.hpp"
#include "detail/primitives.hpp"
#include "detail/sources.hpp"
#include "detail/stable_dt.hpp"
#include "detail/stage.hpp"
#include "detail/sweep.hpp"
#include "detail/update.hpp"
#include "detail/viscous.hpp"
#include "fields.hpp"
#include "flux/ale.hpp"
#include "flux/hllc_lm.hpp"
#include "frame/fixed.hpp"
#include "gas.hpp"
#include "grid.hpp"
#include "patch.hpp"
#include "reconstruction/muscl.hpp"
#include "solver.hpp"
#include "time/ssp_rk2.hpp"
#include "turbulence/none.hpp"
#include "view.hpp"
#include "viscosity/inviscid.hpp"
#include "wall_distance.hpp"

namespace parafsi::fluid {

template <class Flux = flux::hllc_lm, class Recon = recon::muscl<limiter::van_leer>,
          class Turbulence = turbulence::none, class Viscosity = viscosity::inviscid, class Frame = frame::fixed,
          class Time = time::ssp_rk2>
class block_solver {
 public:
  using flux_type = Flux;
  using recon_type = Recon;
  using frame_type = Frame;
  using time_type = Time;
  using turbulence_type = Turbulence;
  using viscosity_type = Viscosity;
  static constexpr bool is_viscous = Viscosity::active || Turbulence::active;
  static constexpr bool has_eddy_viscosity = Turbulence::active;
  static constexpr bool needs_wall_distance = [] {
    if constexpr (Turbulence::active) return Turbulence::needs_wall_distance;
    else return false;
  }();
  /// Per-thread scratch of the viscous pass (one block at a time), none when inviscid.
  using viscous_storage = std::conditional_t<is_viscous, soa_of_t<viscous_fields>, empty_storage>;
  /// Eddy viscosity (and the mixing length's wall distance) per cell, mesh-wide like U.
  using turbulence_storage = std::conditional_t<
      has_eddy_viscosity,
      std::conditional_t<needs_wall_distance, paged_soa<field::mu_t, field::wall_distance>, paged_soa<field::mu_t>>,
      empty_storage>;
  static constexpr index_t ng = rectilinear_grid::ghosts;
  // Mesh-wide fields in paged storage (core/soa.hpp): zero when made, memory only where
  // written, so a process of a distributed run pays for the blocks it holds.
  using cons_storage = paged_soa_of_t<conserved_fields>;
  using prim_storage = paged_soa_of_t<primitive_fields>;
  using source_storage = paged_soa_of_t<source_fields>;
  /// io::save_checkpoint / load_checkpoint store the block mesh in this section.
  static constexpr const char* checkpoint_section = "fluid_blocks";

  /// A block's part of a mesh-wide field storage, read like an soa (get<Tag>(), data(f)):
  /// every field is one array over all blocks, block b's cells at b · stride(), so a cell
  /// of the mesh is one flat index (global_index) for the couplings.
  template <class Storage>
  struct slice {
    Storage* storage = nullptr;
    index_t offset = 0;
    template <class Tag>
    double* get() const noexcept {
      return storage->template get<Tag>() + offset;
    }
    double* data(std::size_t f) const noexcept { return storage->data(f) + offset; }
    explicit operator bool() const noexcept { return storage != nullptr; }
  };

  /// One leaf of the mesh: its grid (box coordinates), state, rates and face register.
  struct block {
    blocks::location where;
    rectilinear_grid grid;
    slice<cons_storage> U, U0, dU;
    slice<prim_storage> W;
    slice<source_storage> sources;  ///< per-cell sources (after enable_sources)
    slice<turbulence_storage> T;    ///< eddy viscosity (and wall distance), if a closure
    double* faces = nullptr;        ///< face register [axis][side][component][n²], in the mesh-wide paged array
    std::optional<soa<field::sponge_sigma>> sponge;  ///< sponge rate where the layer reaches
    std::array<bool, 6> boundary{};                  ///< faces on the box boundary filled by a condition
    std::vector<char> bad_rows;
    mutable std::vector<double> rate_slots;  ///< stable_dt's per-row maxima
  };

  template <policy... Ps>
  block_solver(blocks::tree tree, block_layout layout, boundary::set bc, const Ps&... policies)
      : block_solver(std::move(tree), layout, std::move(bc), std::shared_ptr<blocks::halo>{}, policies...) {}

  /// Split over processes from the start (see set_halo): each process allocates, fills and
  /// initializes only the blocks it computes, so none ever holds the whole mesh; a mesh
  /// made whole and then split (set_halo) holds it until the split. Collective.
  template <policy... Ps>
  block_solver(blocks::tree tree, block_layout layout, boundary::set bc, std::shared_ptr<blocks::halo> h,
               const Ps&... policies)
      : tree_(std::move(tree)),
        layout_(layout),
        bc_(std::move(bc)),
        gas_(pick_value<kind::gas, gas::ideal>(policies...)),
        flux_(pick_value<kind::flux, Flux>(policies...)),
        recon_(pick_value<kind::reconstruction, Recon>(policies...)),
        turb_(pick_value<kind::turbulence, Turbulence>(policies...)),
        visc_(pick_value<kind::viscosity, Viscosity>(policies...)),
        frame_(pick_value<kind::frame, Frame>(policies...)) {
    layout_.validate();
    gas_.validate();
    if constexpr (requires { visc_.validate(); }) visc_.validate();
    if constexpr (requires { turb_.validate(); }) turb_.validate();
    bc_.validate();
    for (int d = 0; d < 3; ++d) {
      const bool plo = std::holds_alternative<boundary::periodic>(bc_.face[std::size_t(2 * d)]);
      const bool phi = std::holds_alternative<boundary::periodic>(bc_.face[std::size_t(2 * d + 1)]);
      require(plo == phi, "fluid::block_solver: periodic boundary on axis ", d, " must be set on both faces");
      require(plo == tree_.periodic(d), "fluid::block_solver: axis ", d, " is ", plo ? "" : "not ",
              "periodic in the boundary set but ", tree_.periodic(d) ? "" : "not ", "in the block tree");
      require(tree_.root_blocks()[std::size_t(d)] == layout_.root_blocks[std::size_t(d)],
              "fluid::block_solver: the tree has ", tree_.root_blocks()[std::size_t(d)], " root blocks on axis ", d,
              " but the layout ", layout_.root_blocks[std::size_t(d)]);
    }
    sponge_target_ = detail::sponge_target(bc_, gas_, sponge_target_);
    halo_ = std::move(h);
    build();
    fill_uniform({1.18, {0.0, 0.0, 0.0}, 101325.0});
    gathered_ = !split();
  }

  block_solver(const block_solver&) = delete;  // blocks point into the solver's storage
  block_solver& operator=(const block_solver&) = delete;
  block_solver(block_solver&&) = default;  // the storage lives on the heap: pointers stay valid
  block_solver& operator=(block_solver&&) = default;

  // ------------------------------------------------------------------ set-up and access
  void fill_uniform(const prim<double>& w) {
    validate_state(w, "fill_uniform");
    const cons<double> q = to_cons(w, gas_);
    const auto U = detail::conserved_ptrs(*U_);
    if (!split()) {
      for (index_t c = 0; c < U_->size() + index_t(simd::width); ++c) detail::store_cons(U, c, q);
      return;
    }
    for (index_t id : computed_)  // split: the blocks this process computes
      for (index_t c = stride_ * id; c < stride_ * (id + 1); ++c) detail::store_cons(U, c, q);
  }
  /// Initialise every leaf cell from f(ξ) → prim<double> (ξ: cell centre, box coordinates);
  /// split over processes, the cells of the blocks this process computes.
  template <class F>
  void initialize(F&& f) {
    for_each_own_cell([&](block& b, index_t i, index_t j, index_t k) {
      const Eigen::Vector3d xi{b.grid.centre(0, i), b.grid.centre(1, j), b.grid.centre(2, k)};
      const prim<double> w = f(xi);
      validate_state(w, "initialize");
      detail::store_cons(detail::conserved_ptrs(b.U), b.grid.index(i, j, k), to_cons(w, gas_));
    });
  }
  /// Cell-average initialisation by m³-point midpoint quadrature of f(ξ) → prim.
  template <class F>
  void initialize_averaged(F&& f, int m) {
    require(m >= 1, "initialize_averaged: need m >= 1");
    for_each_own_cell([&](block& b, index_t i, index_t j, index_t k) {
      const auto& g = b.grid;
      cons<double> acc{0, {0, 0, 0}, 0};
      for (int c = 0; c < m; ++c)
        for (int bb = 0; bb < m; ++bb)
          for (int a = 0; a < m; ++a) {
            const Eigen::Vector3d xi{g.face(0, i) + g.width(0, i) * (a + 0.5) / m,
                                     g.face(1, j) + g.width(1, j) * (bb + 0.5) / m,
                                     g.face(2, k) + g.width(2, k) * (c + 0.5) / m};
            const prim<double> w = f(xi);
            validate_state(w, "initialize_averaged");
            acc = acc + to_cons(w, gas_);
          }
      detail::store_cons(detail::conserved_ptrs(b.U), g.index(i, j, k), acc * (1.0 / double(m * m * m)));
    });
  }
  /// f(block, i, j, k) over every leaf cell of the blocks this process computes (all of
  /// them when not split), blocks in tree order.
  template <class F>
  void for_each_own_cell(F&& f) {
    if (!split()) return for_each_cell(f);
    for (index_t id : computed_)
      for (index_t k = 0; k < n_; ++k)
        for (index_t j = 0; j < n_; ++j)
          for (index_t i = 0; i < n_; ++i) f(blocks_[std::size_t(id)], i, j, k);
  }
  /// Whether the mesh is split over more than one process.
  bool split() const noexcept { return halo_ && halo_->size() > 1; }
  /// f(block, i, j, k) over every leaf cell, blocks in tree order.
  template <class F>
  void for_each_cell(F&& f) {
    for (auto& b : blocks_)
      for (index_t k = 0; k < n_; ++k)
        for (index_t j = 0; j < n_; ++j)
          for (index_t i = 0; i < n_; ++i) f(b, i, j, k);
  }
  template <class F>
  void for_each_cell(F&& f) const {
    for (const auto& b : blocks_)
      for (index_t k = 0; k < n_; ++k)
        for (index_t j = 0; j < n_; ++j)
          for (index_t i = 0; i < n_; ++i) f(b, i, j, k);
  }

  /// The leaf and cell holding the point ξ (box coordinates); {−1, 0} outside the box.
  std::pair<index_t, index_t> locate(const Eigen::Vector3d& xi) const {
    const blocks::cell_address a = blocks::find_cell(tree_, layout_, xi);
    if (a.block < 0) return {-1, 0};
    return {a.block, blocks_[std::size_t(a.block)].grid.index(a.ijk[0], a.ijk[1], a.ijk[2])};
  }
  /// Primitive state of the leaf cell holding ξ.
  prim<double> sample(const Eigen::Vector3d& xi) const {
    const auto [b, c] = locate(xi);
    require(b >= 0, "fluid::block_solver::sample: point outside the box");
    return to_prim(detail::load_cons(detail::conserved_ptrs(blocks_[std::size_t(b)].U), c), gas_);
  }

  void set_time(double t) { t_ = t; }
  double time() const noexcept { return t_; }
  long steps() const noexcept { return steps_; }
  frame::pose& pose() noexcept { return pose_; }
  const frame::pose& pose() const noexcept { return pose_; }
  Frame& frame() noexcept { return frame_; }
  const gas::ideal& gas() const noexcept { return gas_; }
  const blocks::tree& tree() const noexcept { return tree_; }
  const block_layout& layout() const noexcept { return layout_; }
  index_t block_cells() const noexcept { return n_; }
  index_t block_count() const noexcept { return index_t(blocks_.size()); }
  const block& block_at(index_t id) const noexcept { return blocks_[std::size_t(id)]; }
  index_t cell_count() const noexcept { return block_count() * n_ * n_ * n_; }
  void set_threading(bool on) noexcept { threaded_ = on; }
  const phase_times& timings() const noexcept { return times_; }
  void reset_timings() noexcept { times_ = {}; }

  std::string name() const {
    return std::string("fluid::block_solver<") + Flux::name() + ", recon:" + Recon::name() + ", " + Frame::name() +
           ", " + Time::name() + ", blocks of " + std::to_string(n_) + "^3>";
  }

  /// Enable the per-cell source hook on every block (zero-initialised; kept through
  /// regrids, which zero them): momentum N/m³ and energy W/m³ (inertial), mass kg/(m³ s).
  void enable_sources() {
    sources_on_ = true;
    if (!S_) allocate_sources();
  }
  bool has_sources() const noexcept { return sources_on_; }
  /// Source array of block `id`: component 0–2 momentum, 3 energy, 4 mass.
  double* source(index_t id, int component) {
    require(sources_on_, "fluid::block_solver::source: call enable_sources() first");
    const auto& S = blocks_[std::size_t(id)].sources;
    switch (component) {
      case 0: return S.template get<field::s_mx>();
      case 1: return S.template get<field::s_my>();
      case 2: return S.template get<field::s_mz>();
      case 3: return S.template get<field::s_E>();
      default: return S.template get<field::s_rho>();
    }
  }
  /// Cells per block in the mesh-wide arrays (ghosts and SIMD padding included).
  index_t stride() const noexcept { return stride_; }
  /// Flat index of cell `cell` (block-local index) of block `id` in the mesh-wide arrays.
  index_t global_index(index_t id, index_t cell) const noexcept { return id * stride_ + cell; }
  /// The mesh-wide conserved storage (block id at id · stride()).
  const cons_storage& conserved_storage() const noexcept { return *U_; }

  /// Mesh-wide source array (global_index): component 0–2 momentum, 3 energy, 4 mass.
  double* source(int component) { return source(0, component); }
  /// Read-only view of the state over the mesh-wide arrays: cells are global indices
  /// (global_index); the view's grid is null (a block's grid is block_at(id).grid).
  fluid::view view() const noexcept {
    fluid::view v = fluid::view::of(blocks_[0].grid, pose_, gas_, *U_);
    v.grid = nullptr;
    return v;
  }
  /// Volume of the cell at a global index.
  double cell_volume(index_t global) const noexcept {
    return blocks_[std::size_t(global / stride_)].grid.cell_volume(global % stride_);
  }

  /// The turbulence closure (its constants).
  const Turbulence& turbulence() const noexcept { return turb_; }
  /// Wall distance d_w of block `id`'s cells, ghosts included (the mixing-length closure;
  /// 1e30 = far until filled, e.g. by distance_to_points(block_at(id).grid, …, ghosts = true);
  /// a regrid resets it).
  double* wall_distance(index_t id) requires needs_wall_distance {
    return blocks_[std::size_t(id)].T.template get<field::wall_distance>();
  }
  /// The wall distance of every block this process computes (ghosts included) from the
  /// structure's `points` (box coordinates), each block searching only the points within
  /// the closure's reach for its own filter width Δ = (h_x h_y h_z)^(1/3) (its widths, ghosts
  /// included, at their largest): the same eddy viscosity as an unbounded search, at a
  /// fraction of the cost on fine blocks (wall_distance.hpp). Blocks in parallel; each
  /// block's seconds count in its partition weight (rebalance()).
  void wall_distance_from(std::span<const Eigen::Vector3d> points) requires needs_wall_distance {
    parallel::for_range(0, index_t(computed_.size()), [&](index_t k) {
      const index_t id = computed_[std::size_t(k)];
      const auto t0 = std::chrono::steady_clock::now();
      const rectilinear_grid& g = blocks_[std::size_t(id)].grid;
      double hmax[3];
      for (int d = 0; d < 3; ++d) {
        const double* w = g.widths(d);
        hmax[d] = *std::max_element(w - rectilinear_grid::ghosts, w + g.n(d) + rectilinear_grid::ghosts);
      }
      distance_to_points(g, points, turb_.wall_reach(std::cbrt(hmax[0] * hmax[1] * hmax[2])),
                         std::span<double>(wall_distance(id), std::size_t(g.total_cells())), true);
      add_block_cost(id, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    });
  }
  /// Eddy viscosity μ_t of the mesh (global_index; after the last stage).
  const double* eddy_viscosity() const requires has_eddy_viscosity { return T_->template get<field::mu_t>(); }

  /// Sponge rate σ of a leaf cell (0 outside the layer).
  double sponge_rate(index_t id, index_t cell) const noexcept {
    const block& b = blocks_[std::size_t(id)];
    return b.sponge ? b.sponge->template get<field::sponge_sigma>()[cell] : 0.0;
  }

  /// Sums over leaf cells: per block (its cells in order), then the blocks' sums in tree
  /// order, so the result is the same bits on any number of processes (collective when
  /// distributed).
  fluid::totals totals() const {
    constexpr int w = 6;
    std::vector<double> part(blocks_.size() * w, 0.0);
    for (index_t id : computed_) {
      const block& b = blocks_[std::size_t(id)];
      fluid::totals t;
      for (index_t k = 0; k < n_; ++k)
        for (index_t j = 0; j < n_; ++j)
          for (index_t i = 0; i < n_; ++i)
            t.add(detail::load_cons(detail::conserved_ptrs(b.U), b.grid.index(i, j, k)), b.grid.cell_volume(i, j, k));
      double* o = part.data() + std::size_t(id) * w;
      o[0] = t.mass;
      o[1] = t.momentum[0];
      o[2] = t.momentum[1];
      o[3] = t.momentum[2];
      o[4] = t.energy;
      o[5] = t.kinetic;
    }
    if (halo_) halo_->gather_blocks(part, w);
    fluid::totals t;
    for (std::size_t id = 0; id < blocks_.size(); ++id) {
      const double* o = part.data() + id * w;
      t.mass += o[0];
      t.momentum[0] += o[1];
      t.momentum[1] += o[2];
      t.momentum[2] += o[3];
      t.energy += o[4];
      t.kinetic += o[5];
    }
    return t;
  }

  // ------------------------------------------------------------------ distributed runs
  /// Split the mesh over processes (blocks/halo.hpp; mpi/block_halo.hpp over MPI): from now
  /// on this process computes only its blocks [first, last) and `h` brings what they read of
  /// the others'. Every process must hold the same mesh and state when this is called, and
  /// make the same calls after it (stepping, stable_dt, totals, regrid, fetch, gather). The
  /// others' blocks are stale or zero: bring them before reading cells this process does
  /// not own (sample, for_each_cell, output) with fetch (the blocks it will read), gather
  /// (every block, every process) or gather_to (every block, one process: before it writes
  /// a checkpoint, which holds the whole mesh, so any number of processes can read it), and
  /// free them with release_fetched. This call copies the blocks the process holds into new
  /// arrays (paged storage) and frees the rest; a solver made with the halo never holds them.
  /// A coupling reads and writes cells near the replicated structure. A recording patcher's
  /// faces (coupling::embedded) are solved each by the process computing its high cell,
  /// which receives the cells the face reads (fetch_slots); every process adds every face's
  /// load from its record's head in list order, and the processes computing the cells a
  /// face changes replay its whole record in list order (send_records); another patcher's
  /// faces are processed by every process, with every face's cells (share_slots). So the
  /// structure gets the same loads everywhere and every cell its corrections in the same
  /// order. A
  /// coupling that reads the air elsewhere (coupling::penalty's points) needs the blocks it
  /// touches computed by every process (mpi::block_halo's replicate_finest) and stops with a
  /// message otherwise. With an eddy-viscosity closure the wall distance is the caller's, on
  /// the blocks this process computes (computed_blocks(), ghosts included).
  void set_halo(std::shared_ptr<blocks::halo> h) {
    halo_ = std::move(h);
    weight_.clear();   // a new split: uniform until costs are measured
    gathered_ = true;  // the caller's promise: every process holds the same state
    attach_halo();
    if (split()) {
      keep_held_storage();
      attach_halo();      // the halo reads the new arrays
      gathered_ = false;  // the others' blocks are no longer held here
    }
  }
  const blocks::halo* halo() const noexcept { return halo_.get(); }
  /// Whether every process computes block id (always, when not distributed).
  bool computed_everywhere(index_t id) const { return !halo_ || halo_->everywhere(id); }
  /// The conserved state of the listed cells (global indices; any order, repeats allowed)
  /// from the processes computing them to every process (collective: every process passes
  /// the same list; a no-op when not distributed). A coupling calls it for the cells it
  /// reads near the replicated structure (coupling::embedded's impedance term).
  void share_cells(const std::vector<index_t>& cells) { share_slots(cells, false); }
  /// The blocks this process computes (tree order): all without a halo.
  const std::vector<index_t>& computed_blocks() const noexcept { return computed_; }
  /// Add `seconds` to the measured cost of computed block `id` (distributed runs; ignored
  /// without a halo): a caller's own per-block work, e.g. the drop's wall distance, so the
  /// partition weighs it too. Safe from threads working on different blocks.
  void add_block_cost(index_t id, double seconds) noexcept {
    if (halo_) cost_[std::size_t(id)] += seconds;
  }
  /// The weight of each block in the last partition (tree order; every process the same):
  /// 1 until the first repartition, then the blocks' measured seconds per step (see
  /// rebalance()).
  std::vector<double> partition_weights() const {
    return weight_.size() == blocks_.size() ? weight_ : std::vector<double>(blocks_.size(), 1.0);
  }
  /// Cut the mesh again by the blocks' measured cost (collective; a no-op without a halo).
  /// Each process times the work of the blocks it computes (their ghost fill, sweeps, viscous pass,
  /// corrections, sources and update, the coupling faces whose high cell they hold, and
  /// what the caller adds with add_block_cost); the seconds per step since the last
  /// partition, gathered to every process, become the block weights of blocks::partition.
  /// A regrid that changes the mesh does this itself (a new leaf weighs what the old leaf
  /// covering it did, or the mean of the old leaves it merges), and so does the first
  /// regrid call that leaves the mesh as it is while the partition still weighs every
  /// block 1 (after set_halo or a restart); this call is for a mesh that stays.
  /// Replicated blocks (halo::everywhere) weigh the mean of the others. A block that
  /// changes process is fetched from its old owner (halo::fetch_blocks; no whole-state
  /// gather); the results do not change by a bit, only who computes what.
  void rebalance() {
    if (!split()) return;
    reattach_if_moved();
    std::vector<double> w = measured_weights(tree_, tree_);
    // The blocks this process takes over come from their present owners.
    forecast_ = halo_->would_compute(tree_, weights_or_uniform(w, blocks_.size()));
    std::vector<index_t> wanted;
    for (index_t id = 0; id < block_count(); ++id)
      if (forecast_[std::size_t(id)] && !computes_[std::size_t(id)]) wanted.push_back(id);
    for (index_t id : wanted) initialize_block_storage(id);  // its ghosts; the fetch brings its cells
    halo_->fetch_blocks(wanted);
    weight_ = std::move(w);
    attach_halo();
    agree(forecast_ == computes_, "fluid::block_solver::rebalance: the partition differs from its forecast");
  }
  /// Every block's interior cells from its owner to every process (collective; a no-op
  /// when not distributed).
  void gather() {
    reattach_if_moved();
    if (split()) halo_->gather_state();
    gathered_ = true;
  }
  /// The listed blocks' interior cells (and eddy viscosity, with a closure) from the
  /// processes computing them to this one (collective; each process lists the blocks it is
  /// about to read, e.g. a VTK piece's blocks and their face neighbours, or those a slice
  /// cuts). Unlike gather() it brings only those, so the process stays backed for its own
  /// blocks and these; release_fetched() frees them again. A no-op when not split.
  void fetch(const std::vector<index_t>& ids) {
    if (!split()) return;
    reattach_if_moved();
    const bool valid = std::all_of(ids.begin(), ids.end(), [&](index_t id) { return id >= 0 && id < block_count(); });
    agree(valid, "fluid::block_solver::fetch: a listed block is not a leaf of the mesh");  // every process stops
    std::vector<index_t> wanted;
    for (index_t id : ids)
      if (!computes_[std::size_t(id)]) wanted.push_back(id);
    std::sort(wanted.begin(), wanted.end());
    wanted.erase(std::unique(wanted.begin(), wanted.end()), wanted.end());
    for (index_t id : wanted) initialize_block_state(id);  // its ghosts at rest, its wall distance far
    halo_->fetch_blocks(wanted);
    gathered_ = false;
  }
  /// Every block's interior cells to process `rank` only (collective): before that process
  /// writes a checkpoint (the whole mesh on it, the others unchanged).
  void gather_to(int rank) {
    require(!halo_ || (rank >= 0 && rank < halo_->size()), "fluid::block_solver::gather_to: no process ", rank);
    if (!split()) {
      gathered_ = true;  // one process holds every block
      return;
    }
    std::vector<index_t> all;
    if (halo_->rank() == rank)
      for (index_t id = 0; id < block_count(); ++id) all.push_back(id);
    fetch(all);
    gathered_ = halo_->rank() == rank;
  }
  /// Free the memory of the blocks brought by fetch, gather_to or gather (collective): the
  /// process keeps the blocks it computes and those their ghost plans read, as after a
  /// regrid. The partition and the measured block costs stay; no result changes.
  void release_fetched() {
    if (!split()) return;
    reattach_if_moved();
    const std::vector<double> cost = cost_;
    const long steps = cost_steps_;
    keep_held_storage();
    attach_halo();  // the halo reads the new arrays; the same partition (weights unchanged)
    cost_ = cost;
    cost_steps_ = steps;
    gathered_ = false;
  }
  /// The leaves whose extent along `axis` (box coordinates) meets [lo, hi], in tree order.
  std::vector<index_t> blocks_meeting(int axis, double lo, double hi) const {
    require(axis >= 0 && axis < 3 && lo <= hi, "fluid::block_solver::blocks_meeting: bad axis or interval");
    std::vector<index_t> out;
    for (index_t id = 0; id < block_count(); ++id) {
      const auto& g = blocks_[std::size_t(id)].grid;
      if (g.face(axis, 0) <= hi && g.face(axis, n_) >= lo) out.push_back(id);
    }
    return out;
  }
  /// The listed leaves and every leaf across one of their faces (of any level; periodic
  /// axes wrap), in tree order without repeats: what a cell's face neighbours can be.
  std::vector<index_t> with_face_neighbours(const std::vector<index_t>& ids) const {
    std::vector<char> mark(blocks_.size(), 0);
    auto under = [&](auto&& self, const blocks::location& q) -> void {
      const blocks::cover c = tree_.find(q);
      if (c.kind == blocks::cover::leaf) mark[std::size_t(c.id)] = 1;
      else if (c.kind == blocks::cover::finer)
        for (int ch = 0; ch < 8; ++ch) self(self, q.child(ch));
    };
    for (index_t id : ids) {
      require(id >= 0 && id < block_count(), "fluid::block_solver::with_face_neighbours: no block ", id);
      mark[std::size_t(id)] = 1;
      const blocks::location q = blocks_[std::size_t(id)].where;
      for (int d = 0; d < 3; ++d)
        for (int side : {-1, 1}) {
          blocks::location n = q;
          n.l[std::size_t(d)] += side;
          under(under, n);
        }
    }
    std::vector<index_t> out;
    for (index_t id = 0; id < block_count(); ++id)
      if (mark[std::size_t(id)]) out.push_back(id);
    return out;
  }
  /// What a halo reads and writes: the tree, plans, corrections, storage and block costs.
  blocks::mesh_view mesh_view() {
    blocks::mesh_view m;
    m.n = n_;
    m.leaves = &tree_;
    m.plan = &plan_;
    m.corrections = &corrections_;
    m.U = &U_all_;
    m.registers.resize(blocks_.size());
    m.weight = weights_or_uniform(weight_, blocks_.size());
    for (std::size_t id = 0; id < blocks_.size(); ++id) m.registers[id] = blocks_[id].faces;
    if constexpr (has_eddy_viscosity) {
      m.mu_t.resize(blocks_.size());
      for (std::size_t id = 0; id < blocks_.size(); ++id) m.mu_t[id] = blocks_[id].T.template get<field::mu_t>();
    }
    return m;
  }

  // ------------------------------------------------------------------ stepping
  /// Largest stable step over all blocks: CFL / max Σ_d (|u_d − w_d| + c)/h_d.
  double stable_dt(double cfl = 0.5) const { return cfl / max_rate(cfl, false, "stable_dt"); }

  frame::motion plan_motion(double dt) const {
    frame::pose p = pose_;
    frame_.plan(p, t_, dt);
    return p.current_motion();
  }

  /// One Runge–Kutta step with the box motion m and the face patches of `patcher` (see
  /// solver::step and patch.hpp): a patched face is named by its high cell's global index
  /// and axis; its low cell is the same-level neighbour (in the block or the next one).
  template <face_patcher Patcher>
  void step(double dt, const frame::motion& m, Patcher& patcher) {
    require(dt > 0.0 && std::isfinite(dt), "fluid::block_solver::step: dt must be positive and finite, got ", dt);
    gathered_ = !halo_;
    reattach_if_moved();
    pose_.set_motion(m);
    save_stage_start();
    double pose_time = 0.0;
    for (int s = 0; s < Time::stages; ++s) {
      const double c = Time::c[std::size_t(s)];
      if (c != pose_time) {
        pose_.advance((c - pose_time) * dt);
        pose_time = c;
      }
      compute_rhs(t_ + c * dt, s, patcher);
      update(Time::a[std::size_t(s)], Time::b[std::size_t(s)], dt, t_ + dt, s + 1 == Time::stages);
    }
    if (pose_time != 1.0) pose_.advance((1.0 - pose_time) * dt);
    t_ += dt;
    ++steps_;
    ++cost_steps_;
  }
  template <face_patcher Patcher>
  void step(double dt, Patcher& patcher) {
    step(dt, plan_motion(dt), patcher);
  }
  void step(double dt, const frame::motion& m) {
    no_patches none;
    step(dt, m, none);
  }
  void step(double dt) { step(dt, plan_motion(dt)); }

  // ------------------------------------------------------------------ level subcycling
  /// Largest stable step of the coarsest level under level subcycling (step_subcycled):
  /// level ℓ takes steps of dt / 2^(ℓ − ℓ_min), so dt = CFL / max over blocks of
  /// 2^(ℓ_min − ℓ) Σ_d (|u_d − w_d| + c)/h_d (viscous limit included as in stable_dt).
  double stable_dt_subcycled(double cfl = 0.5) const { return cfl / max_rate(cfl, true, "stable_dt_subcycled"); }

  /// One step dt of the coarsest level with level subcycling (Berger & Colella 1989, on
  /// the leaves): level ℓ takes 2^(ℓ − ℓ_min) steps of dt / 2^(ℓ − ℓ_min), recursively,
  /// each level's step before the two of the next finer level over the same interval.
  ///   - A finer neighbour's ghosts are its restriction at the start of the coarse step
  ///     (it has not advanced yet), in every stage; a coarser neighbour's are prolonged
  ///     from its state interpolated linearly in time between the start and the end of its
  ///     step, at the stage's time.
  ///   - Conservation: each coarse cell at a coarse–fine face is corrected after the finer
  ///     level's two steps by dt (F̄_c − F̄_f)/Δx (refluxing), F̄_c its own flux weighted by
  ///     the Runge–Kutta stage weights, F̄_f the area mean of the fine fluxes weighted by
  ///     the stage weights and dt_f/dt, so mass, momentum and energy are conserved to
  ///     round-off.
  ///   - One level: the same operations as step(dt) (bit for bit with SSP-RK2 in a fixed
  ///     frame; on a moving box the stage poses are advanced from the step's start, which
  ///     can differ from step()'s in the last bits).
  ///   - A coupling's face patches (patch.hpp) act in the finest level's stages, and must
  ///     lie on the finest level; `finest.before(t, dt_f)` is called before each step of
  ///     the finest level (pose() then that step's start) and `finest.after(t + dt_f,
  ///     dt_f)` after it, in time order, so a coupling can find its faces and advance the
  ///     structure with the finest level (explicit_stepper::step_subcycled).
  /// On one process; the box motion m as in step().
  template <face_patcher Patcher, class Finest>
  void step_subcycled(double dt, const frame::motion& m, Patcher& patcher, Finest&& finest) {
    require(dt > 0.0 && std::isfinite(dt), "fluid::block_solver::step_subcycled: dt must be positive and finite, got ",
            dt);
    require(!halo_, "fluid::block_solver::step_subcycled: level subcycling runs on one process only");
    gathered_ = true;
    pose_.set_motion(m);
    prepare_subcycling();
    sub_.pose0 = pose_;
    sub_.t0 = t_;
    advance_level(sub_.lmin, t_, dt, t_, dt, patcher, finest);
    pose_ = sub_.pose0;
    pose_.advance(dt);
    t_ += dt;
    ++steps_;
    ++cost_steps_;
  }
  void step_subcycled(double dt, const frame::motion& m) {
    no_patches none;
    step_subcycled(dt, m, none, no_finest_hooks{});
  }
  void step_subcycled(double dt) { step_subcycled(dt, plan_motion(dt)); }
  /// step_subcycled's calls around the finest level's steps, when nothing is to be done.
  struct no_finest_hooks {
    void before(double, double) const noexcept {}
    void after(double, double) const noexcept {}
  };
  /// The number of finest-level steps in one step_subcycled (2^(finest − coarsest level)).
  long finest_substeps() const noexcept {
    const auto [lmin, lmax] = level_range();
    return 1L << (lmax - lmin);
  }
  /// The coarsest and finest levels of the leaves.
  std::pair<int, int> level_range() const noexcept {
    int lmin = blocks_.empty() ? 0 : blocks_[0].where.level, lmax = lmin;
    for (const block& b : blocks_) {
      lmin = std::min(lmin, b.where.level);
      lmax = std::max(lmax, b.where.level);
    }
    return {lmin, lmax};
  }

  /// Global index of the leaf cell beside cell `global` along `axis` (side 0: low, 1: high)
  /// if it is a cell of the same level (the same block or a same-level neighbour block,
  /// across a periodic axis too); −1 if that side is another level or outside the box.
  index_t neighbour(index_t global, int axis, int side) const {
    const index_t id = global / stride_, lc = global % stride_;
    const block& b = blocks_[std::size_t(id)];
    std::array<index_t, 3> ijk = b.grid.ijk(lc);
    const index_t step = side ? 1 : -1;
    ijk[std::size_t(axis)] += step;
    if (ijk[std::size_t(axis)] >= 0 && ijk[std::size_t(axis)] < n_) return global + step * b.grid.stride(axis);
    blocks::location q = b.where;
    q.l[std::size_t(axis)] += step;
    if (!tree_.wrap(q)) return -1;
    const index_t nid = tree_.id_of(q);
    if (nid < 0) return -1;
    ijk[std::size_t(axis)] = side ? 0 : n_ - 1;
    return global_index(nid, b.grid.index(ijk[0], ijk[1], ijk[2]));
  }

  // ------------------------------------------------------------------ checkpoint
  /// Checkpoint (io/archive.hpp): the signature (type, ghosts, layout, gas), then time,
  /// steps, pose, frame, the leaves (level and position; a restart rebuilds the tree and
  /// its plans from them) and every block's conserved fields (ghosts and padding
  /// included) and sources.
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& self) {
    if constexpr (!Archive::loading)
      require(!self.halo_ || self.gathered_,
              "fluid::block_solver: a distributed mesh is written after gather_to(this process) or gather(), from "
              "one process");
    ar.check("type", self.name(), "the solver type");
    ar.check("state_layout", std::string("interior cells, blocks in tree order"),
             "the layout of the stored state (an earlier version stored whole blocks with their ghosts)");
    ar.check("ghosts", std::int64_t(ng), "the number of ghost layers");
    for (int d = 0; d < 3; ++d) {
      const std::string a = std::to_string(d);
      ar.check("layout.lo" + a, self.layout_.lo[std::size_t(d)], "the box's lower corner on axis " + a);
      ar.check("layout.hi" + a, self.layout_.hi[std::size_t(d)], "the box's upper corner on axis " + a);
      ar.check("layout.root_blocks" + a, std::int64_t(self.layout_.root_blocks[std::size_t(d)]),
               "the root blocks on axis " + a);
    }
    ar.check("block_stride", std::int64_t(self.stride_),
             "the cells per block in the field arrays (cells + SIMD padding; another SIMD width?)");
    ar.check("gas.gamma", self.gas_.gamma, "gas gamma");
    ar.check("gas.R", self.gas_.R, "gas constant R");
    ar("time", self.t_);
    ar("steps", self.steps_);
    ar("pose.X", self.pose_.X);
    ar("pose.R", self.pose_.R);
    ar("pose.V", self.pose_.V);
    ar("pose.Omega", self.pose_.Omega);
    ar("frame", self.frame_);
    std::int64_t count = self.tree_.size();
    ar("leaf_count", count);
    std::vector<std::int64_t> leaves;
    if constexpr (Archive::loading) {
      if (count < 1 || count > (std::int64_t(1) << 40)) ar.fail("leaf_count ", count, " is not a number of blocks");
      leaves.resize(std::size_t(4 * count));
    } else {
      for (const auto& q : self.tree_.leaves()) leaves.insert(leaves.end(), {q.level, q.l[0], q.l[1], q.l[2]});
    }
    ar("leaves", leaves);
    bool sources = self.sources_on_;
    ar("sources", sources);
    if constexpr (Archive::loading) {
      std::vector<blocks::location> list(static_cast<std::size_t>(count));
      for (std::size_t i = 0; i < list.size(); ++i)
        list[i] = {int(leaves[4 * i]), {leaves[4 * i + 1], leaves[4 * i + 2], leaves[4 * i + 3]}};
      std::array<bool, 3> per{self.tree_.periodic(0), self.tree_.periodic(1), self.tree_.periodic(2)};
      self.tree_ = blocks::tree::from_leaves(self.layout_.root_blocks, per, list);
      self.sources_on_ = self.sources_on_ || sources;
      self.weight_.clear();  // a new mesh: uniform weights until costs are measured
      self.build();
    }
    // The conserved state of the interior cells only (the ghosts are filled again before
    // they are read: a stage fills them first, and so does a regrid's prolongation).
    self.interior_fields(ar, "conserved", *self.U_);
    if (sources) ar.fields("sources", *self.S_);
    if constexpr (has_eddy_viscosity) ar.fields("turbulence", *self.T_);
  }

  /// Every field of `st` as one array of the blocks' interior cells (block by block in tree
  /// order, i fastest): written from, or read into, the mesh-wide arrays.
  template <class Archive, class... Tags>
  void interior_fields(Archive& ar, const std::string& group, paged_soa<Tags...>& st) const {
    const blocks::block_index at{n_};
    const std::size_t n3 = std::size_t(n_ * n_ * n_), nb = blocks_.size();
    std::vector<double> buf(n3 * nb);
    auto one = [&](const char* name, double* a) {
      auto each = [&](auto&& f) {
        for (std::size_t id = 0; id < nb; ++id)
          for (index_t k = 0, o = 0; k < n_; ++k)
            for (index_t j = 0; j < n_; ++j)
              for (index_t i = 0; i < n_; ++i, ++o)
                f(buf[id * n3 + std::size_t(o)], a[std::size_t(stride_) * id + std::size_t(at(i, j, k))]);
      };
      if constexpr (Archive::loading) {
        ar.array(group + "." + name, buf.data(), buf.size());
        each([](double& v, double& cell) { cell = v; });
      } else {
        each([](double& v, double& cell) { v = cell; });
        ar.array(group + "." + name, std::as_const(buf).data(), buf.size());
      }
    };
    (one(Tags::name, st.template get<Tags>()), ...);
  }

  /// Per leaf (tree order), max over its cells of |ω| h: the vorticity magnitude (central
  /// differences of the velocity across the cell, ghosts filled from the neighbours first)
  /// times the cell's smallest width, in m/s: how much the velocity turns across one cell,
  /// a measure of how well the leaf resolves the vortical flow it holds (the wake); the
  /// input of blocks::leaf_indicator.
  /// Distributed, each process computes its blocks' values (their ghosts through the halo's
  /// state exchange) and the values are gathered (collective).
  std::vector<double> vorticity_indicator() {
    reattach_if_moved();
    if (halo_) {
      halo_->begin_state();
      halo_->end_state();
    }
    const auto geo = detail::geometry(pose_);
    for_computed([&](index_t id) { fill_block_ghosts(id, t_, geo); });
    std::vector<double> out(blocks_.size(), 0.0);
    for_computed([&](index_t id) {
      const block& b = blocks_[std::size_t(id)];
      const auto& g = b.grid;
      const auto U = detail::conserved_ptrs(b.U);
      auto vel = [&](index_t c, int a) { return U[1 + a][c] / U[0][c]; };
      const double h = std::min({g.width(0, 0), g.width(1, 0), g.width(2, 0)});
      double m = 0;
      for (index_t k = 0; k < n_; ++k)
        for (index_t j = 0; j < n_; ++j)
          for (index_t i = 0; i < n_; ++i) {
            const index_t c = g.index(i, j, k);
            const index_t ijk[3] = {i, j, k};
            double G[3][3];  // G[a][d] = ∂u_a/∂ξ_d (components along the box axes of the inertial frame's u)
            for (int d = 0; d < 3; ++d) {
              const index_t st = g.stride(d);
              const double inv = 1.0 / (g.centre(d, ijk[d] + 1) - g.centre(d, ijk[d] - 1));
              for (int a = 0; a < 3; ++a) G[a][d] = (vel(c + st, a) - vel(c - st, a)) * inv;
            }
            // The stored velocity has inertial components; the box axes are R's columns, so
            // the curl in box coordinates is that of Rᵀu: ω_box = Rᵀ ω (the same magnitude).
            const Eigen::Matrix3d J = pose_.R.transpose() * Eigen::Matrix3d{{G[0][0], G[0][1], G[0][2]},
                                                                            {G[1][0], G[1][1], G[1][2]},
                                                                            {G[2][0], G[2][1], G[2][2]}};
            const Eigen::Vector3d w(J(2, 1) - J(1, 2), J(0, 2) - J(2, 0), J(1, 0) - J(0, 1));
            m = std::max(m, w.norm() * h);
          }
      out[std::size_t(id)] = m;
    });
    if (halo_) halo_->gather_blocks(out, 1);
    return out;
  }

  // ------------------------------------------------------------------ regrid
  /// Adapt the mesh to `target(location) → level`: a leaf below its target level is split
  /// (with the balance splits it needs), a family of 8 leaves that all want a coarser level
  /// is merged where the balance allows. The state moves conservatively: a new finer leaf
  /// takes limited-linear prolongation of its old ancestor cell (minmod slopes from the
  /// old mesh, ghosts included, offsets of the fine centres in coarse widths, so the
  /// children average back to the parent), a new coarser leaf the volume mean of the old
  /// cells it covers. Levels are capped at max_level. Returns whether the mesh changed.
  /// Distributed, a call may change the blocks this process computes even when it returns
  /// false (the first cut by measured cost, see rebalance()): refresh per-block data of your
  /// own (e.g. a wall distance) from computed_blocks() before the next step. It moves no
  /// whole state: each process builds the new blocks it will compute (the halo's forecast
  /// of the new partition) from the old blocks it fetches (fetch_sources); the other blocks
  /// hold zeros (and take no memory, paged storage) until the halo or gather() brings their
  /// cells.
  template <class Target>
  bool regrid(Target&& target, int max_level) {
    require(max_level >= 0 && max_level <= blocks::tree::max_depth,
            "fluid::block_solver::regrid: max_level must be "
            "in [0, ",
            blocks::tree::max_depth, "], got ", max_level);
    // Each location's target once (the merge passes ask again for the leaves the refine
    // pass asked about).
    std::unordered_map<std::uint64_t, int> targets;
    auto want = [&](const blocks::location& q) {
      const auto [it, fresh] = targets.try_emplace(blocks::tree::key(q), 0);
      if (fresh) it->second = std::min(max_level, int(target(q)));
      return it->second;
    };
    blocks::tree next = tree_;
    next.refine_where(max_level, [&](const blocks::location& q) { return want(q) > q.level; });
    for (bool merged = true; merged;) {
      merged = false;
      for (const auto& q : std::vector<blocks::location>(next.leaves())) {
        // Each parent once per pass, at its first child (its 8 children, when all are leaves,
        // are consecutive in the Morton order). A parent that a merge beside it makes
        // mergeable later in the pass waits for the next pass; merges only enable merges and
        // the loop runs until none happens, so the tree is the same.
        if (q.level == 0 || !(q.l[0] % 2 == 0 && q.l[1] % 2 == 0 && q.l[2] % 2 == 0) || !next.is_leaf(q)) continue;
        const blocks::location p = q.parent();
        bool all = true;
        for (int c = 0; c < 8 && all; ++c) all = next.is_leaf(p.child(c)) && want(p.child(c)) < p.level + 1;
        if (all && next.coarsen(p)) merged = true;
      }
    }
    if (next.leaves() == tree_.leaves()) {
      // The first partition weighed every block 1; once costs are measured, cut by them
      // (once: later partitions come with the regrids that change the mesh, or rebalance()).
      if (split() && weight_.empty() && cost_steps_ > 0) rebalance();
      return false;
    }
    // Split over processes, each process builds only the new blocks it will compute, from
    // the old blocks it fetches (fetch_sources); otherwise every block from every block.
    const bool split = this->split();
    reattach_if_moved();
    std::vector<double> next_weight = halo_ ? measured_weights(tree_, next) : std::vector<double>{};
    if (split) fetch_sources(next, next_weight);
    else fill_ghosts_all(t_, 0, block_count());  // the old mesh's ghosts feed the prolongation slopes
    std::vector<block> old = std::move(blocks_);
    const std::unique_ptr<cons_storage> old_U = std::move(U_);  // the old blocks' slices point here
    const std::unique_ptr<turbulence_storage> old_T = std::move(T_);
    blocks::tree old_tree = std::move(tree_);
    tree_ = std::move(next);
    weight_ = std::move(next_weight);  // the old mesh's costs, on the new leaves
    build();
    if (split)
      agree(forecast_ == computes_,
            "fluid::block_solver::regrid: the partition differs from its forecast (the halo's rebuild and "
            "would_compute must cut alike)");
    transfer(old, old_tree);
    if constexpr (has_eddy_viscosity) transfer_eddy_viscosity(old, old_tree);
    gathered_ = !split;  // the other processes' new blocks are not built here
    return true;
  }

  /// μ_t onto the new leaves (the first stable step after a regrid needs it): a cell takes the
  /// value of the old cell holding its centre, a coarser cell the largest of the old cells it
  /// covers (the stricter viscous step). The wall distance starts again at 1e30 (refill it).
  void transfer_eddy_viscosity(const std::vector<block>& old, const blocks::tree& old_tree) {
    const index_t n = n_;
    for_computed([&](index_t id) {
      block& nb = blocks_[std::size_t(id)];
      double* mu = nb.T.template get<field::mu_t>();
      const blocks::location q = nb.where;
      for (index_t kk = 0; kk < n; ++kk)
        for (index_t j = 0; j < n; ++j)
          for (index_t i = 0; i < n; ++i) {
            const index_t G[3] = {q.l[0] * n + i, q.l[1] * n + j, q.l[2] * n + kk};
            double m = 0;
            // The old leaves over this cell's volume: its covering leaf, or its descendants.
            auto visit = [&](auto&& self, const blocks::location& at, int level, const index_t* g) -> void {
              const blocks::cover c = old_tree.find(at);
              if (c.kind == blocks::cover::leaf) {
                const block& ob = old[std::size_t(c.id)];
                const int k = level - ob.where.level;  // ≥ 0: the old leaf is as coarse or coarser
                index_t C[3];
                for (int d = 0; d < 3; ++d) C[d] = (g[d] >> k) - ob.where.l[std::size_t(d)] * n;
                m = std::max(m, ob.T.template get<field::mu_t>()[ob.grid.index(C[0], C[1], C[2])]);
                return;
              }
              if (c.kind != blocks::cover::finer) return;
              for (int o = 0; o < 8; ++o) {  // the cell's 8 children on the next level
                const index_t h[3] = {2 * g[0] + (o & 1), 2 * g[1] + ((o >> 1) & 1), 2 * g[2] + ((o >> 2) & 1)};
                const blocks::location child{level + 1, {h[0] / n, h[1] / n, h[2] / n}};
                self(self, child, level + 1, h);
              }
            };
            visit(visit, q, q.level, G);
            mu[nb.grid.index(i, j, kk)] = m;
          }
    });
  }

 private:
  // ------------------------------------------------------------------ mesh
  void build() {
    n_ = layout_.block_cells;
    const std::size_t nleaf = std::size_t(tree_.size());
    blocks_.assign(nleaf, block{});
    const index_t n2 = n_ * n_;
    const index_t per_block = (n_ + 2 * ng) * (n_ + 2 * ng) * (n_ + 2 * ng);
    stride_ = index_t(simd::padded(std::size_t(per_block))) + index_t(simd::width);
    const index_t total = stride_ * index_t(nleaf);
    U_ = std::make_unique<cons_storage>(total);
    U0_ = std::make_unique<cons_storage>(total);
    dU_ = std::make_unique<cons_storage>(total);
    W_ = std::make_unique<prim_storage>(total);
    S_.reset();
    if constexpr (has_eddy_viscosity) T_ = std::make_unique<turbulence_storage>(total);
    for (std::size_t id = 0; id < nleaf; ++id) {
      block& b = blocks_[id];
      b.where = tree_.leaf(index_t(id));
      std::array<axis, 3> ax;
      for (int d = 0; d < 3; ++d) {
        // Faces from the level's global index, x_I = lo + (hi − lo) I / N_L, so blocks
        // share their faces exactly with each other and with the box solver's uniform grid.
        const std::size_t du = std::size_t(d);
        const index_t N = tree_.extent(d, b.where.level) * n_;
        const index_t I0 = b.where.l[du] * n_;
        ax[du].faces.resize(std::size_t(n_) + 1);
        for (index_t i = 0; i <= n_; ++i)
          ax[du].faces[std::size_t(i)] = layout_.lo[du] +
                                         (layout_.hi[du] - layout_.lo[du]) * double(I0 + i) / double(N);
        b.boundary[std::size_t(2 * d)] = !tree_.periodic(d) && b.where.l[du] == 0;
        b.boundary[std::size_t(2 * d + 1)] = !tree_.periodic(d) && b.where.l[du] + 1 == tree_.extent(d, b.where.level);
      }
      b.grid = rectilinear_grid(std::move(ax[0]), std::move(ax[1]), std::move(ax[2]));
      b.bad_rows.assign(std::size_t(n2), 0);
      setup_sponge(b);
    }
    if (sources_on_) allocate_sources();
    allocate_registers();
    attach_slices();
    plan_ = blocks::build_plan(tree_, n_, /*edges=*/is_viscous);
    corrections_ = blocks::build_flux_corrections(tree_, n_);
    sub_.ready = false;  // level subcycling's lists follow the mesh
    threaded_ = cell_count() >= 32768 && nleaf >= 2;
    attach_halo();
    for_computed([&](index_t id) { initialize_block_storage(id); });
  }

  /// Storage for the blocks this process holds only: the mesh-wide arrays made anew, with
  /// the cells of the blocks it computes and of those their ghost plans read copied over;
  /// the other blocks become zero and cost no memory (paged storage). After a new split,
  /// whose state was replicated on every process.
  void keep_held_storage() {
    std::vector<char> held(blocks_.size(), 0);
    for (index_t id : computed_) {
      held[std::size_t(id)] = 1;
      blocks::plan_reads(plan_[std::size_t(id)], n_,
                         [&](const blocks::cell_ref& c) { held[std::size_t(c.block)] = 1; });
    }
    // The state and eddy viscosity (and wall distance) of every held block; the stage copy,
    // rates and primitives only of the computed ones (no other block's are read). The
    // sources stay as they are: a caller writes them on every process (set_halo), and
    // nothing moves them between processes.
    auto keep = [&](auto& array, const std::vector<char>& which) {
      using storage = typename std::remove_reference_t<decltype(array)>::element_type;
      if (!array) return;
      auto fresh = std::make_unique<storage>(array->size());
      for (std::size_t id = 0; id < which.size(); ++id) {
        if (!which[id]) continue;
        const index_t off = stride_ * index_t(id);
        for (std::size_t f = 0; f < storage::field_count; ++f)
          std::copy_n(array->data(f) + off, stride_, fresh->data(f) + off);
      }
      array = std::move(fresh);
    };
    allocate_registers();  // the halo reads them anew (attach_halo after this)
    keep(U_, held);
    keep(U0_, computes_);
    keep(dU_, computes_);
    keep(W_, computes_);
    if constexpr (has_eddy_viscosity) keep(T_, held);
    attach_slices();
  }

  /// Every block's slices of the mesh-wide arrays (block id at id · stride()), and the
  /// state pointers the exchange plans use.
  void attach_slices() {
    U_all_.resize(blocks_.size());
    for (std::size_t id = 0; id < blocks_.size(); ++id) {
      block& b = blocks_[id];
      const index_t off = stride_ * index_t(id);
      b.U = {U_.get(), off};
      b.U0 = {U0_.get(), off};
      b.dU = {dU_.get(), off};
      b.W = {W_.get(), off};
      if (S_) b.sources = {S_.get(), off};
      if constexpr (has_eddy_viscosity) b.T = {T_.get(), off};
      U_all_[id] = detail::conserved_ptrs(b.U);
    }
  }

  /// The arrays of a block this process computes, before anything else writes them: cells
  /// that no exchange, boundary or transfer writes (corner ghosts, the outer edge ghosts)
  /// hold a gas at rest (ρ = 1, p = (γ − 1)·1), since the primitives and the viscous pass
  /// compute on every cell of a block and only finite values there are harmless; the wall
  /// distance is far (1e30). The blocks of other processes stay zero (and cost no memory)
  /// except the cells the halo brings (interior cells that ghost plans read).
  void initialize_block_storage(index_t id) {
    initialize_block_state(id);
    const index_t off = stride_ * id, end = off + stride_;
    std::fill(U0_->template get<field::rho>() + off, U0_->template get<field::rho>() + end, 1.0);
    std::fill(U0_->template get<field::E>() + off, U0_->template get<field::E>() + end, 1.0);
    for (std::size_t f = 0; f < prim_storage::field_count; ++f) std::fill(W_->data(f) + off, W_->data(f) + end, 1.0);
  }
  /// A block brought from another process (fetch, regrid, rebalance): its state a gas at
  /// rest and its wall distance far (1e30), before its cells arrive.
  void initialize_block_state(index_t id) {
    const index_t off = stride_ * id, end = off + stride_;
    auto& u = *U_;  // a block held before may carry momentum: all five fields
    for (std::size_t f = 0; f < cons_storage::field_count; ++f) std::fill(u.data(f) + off, u.data(f) + end, 0.0);
    std::fill(u.template get<field::rho>() + off, u.template get<field::rho>() + end, 1.0);
    std::fill(u.template get<field::E>() + off, u.template get<field::E>() + end, 1.0);
    if constexpr (needs_wall_distance)
      std::fill(T_->template get<field::wall_distance>() + off, T_->template get<field::wall_distance>() + end, 1e30);
  }

  /// The blocks this process computes, from the halo (all without one), listed by what they
  /// wait for in a stage: their ghosts (local, or remote and sending registers, or remote)
  /// and their corrections (local or remote registers).
  void attach_halo() {
    computed_.clear();
    attached_to_ = this;
    cost_.assign(blocks_.size(), 0.0);  // measured anew for the next partition
    cost_steps_ = 0;
    if (halo_) computed_ = halo_->rebuild(mesh_view());
    else
      for (index_t id = 0; id < block_count(); ++id) computed_.push_back(id);
    computes_.assign(blocks_.size(), 0);
    for (index_t id : computed_) computes_[std::size_t(id)] = 1;
    for (auto* v : {&local_ids_, &remote_send_ids_, &remote_ids_, &correct_local_ids_, &correct_remote_ids_})
      v->clear();
    for (index_t id : computed_) {
      if (!halo_ || !halo_->reads_remote(id)) local_ids_.push_back(id);
      else (halo_->sends_registers(id) ? remote_send_ids_ : remote_ids_).push_back(id);
      (halo_ && halo_->corrects_remote(id) ? correct_remote_ids_ : correct_local_ids_).push_back(id);
    }
  }

  /// The halo holds pointers into this object (its tree, plans and storage table): after a
  /// move, attach again (collective: every process moves its solver alike).
  void reattach_if_moved() {
    if (halo_ && attached_to_ != this) attach_halo();
  }

  /// f(id) for every block this process computes, in parallel over blocks.
  template <class F>
  void for_computed(F&& f) const {
    for_ids(computed_, f);
  }
  /// f(id) for the blocks in ids, in parallel over blocks.
  template <class F>
  void for_ids(const std::vector<index_t>& ids, F&& f) const {
    detail::par_for(threaded_, 0, index_t(ids.size()), [&](index_t k) { f(ids[std::size_t(k)]); });
  }

  void allocate_sources() {
    S_ = std::make_unique<source_storage>(stride_ * block_count());
    for (std::size_t id = 0; id < blocks_.size(); ++id) blocks_[id].sources = {S_.get(), stride_ * index_t(id)};
  }

  /// The blocks' face registers, one paged array (zero, backed where written: the blocks a
  /// process sweeps and the finer blocks whose entries its corrections receive). They hold
  /// one stage's fluxes, written before they are read, so a new array needs no copy.
  void allocate_registers() {
    const std::size_t size = std::size_t(blocks::register_size(n_));
    registers_ = zeroed_array(size * blocks_.size());
    for (std::size_t id = 0; id < blocks_.size(); ++id) blocks_[id].faces = registers_.data() + id * size;
  }

  detail::face_register register_of(block& b, int axis) noexcept {
    const std::size_t n2 = std::size_t(n_ * n_);
    double* base = b.faces + std::size_t(axis) * 10 * n2;
    detail::face_register r;
    for (std::size_t f = 0; f < 5; ++f) {
      r.lo[f] = base + f * n2;
      r.hi[f] = base + (5 + f) * n2;
    }
    return r;
  }

  /// f(), its seconds added to block id's measured cost when distributed (rebalance()).
  /// The partition's block weights: `w` when it has one per block, else 1 for every block
  /// (nothing measured yet).
  static std::vector<double> weights_or_uniform(const std::vector<double>& w, std::size_t blocks) {
    return w.size() == blocks ? w : std::vector<double>(blocks, 1.0);
  }

  /// Distributed: stop every process, not only this one, when `ok` fails on any (a shared
  /// verdict, collective), so that none is left waiting in the next collective call.
  void agree(bool ok, const char* what) const {
    if ((halo_ && halo_->max(ok ? 0.0 : 1.0) > 0.0) || !ok) throw error(what);
  }

  template <class F>
  void costed(index_t id, F&& f) {
    if (halo_) detail::timed(cost_[std::size_t(id)], f);
    else f();
  }

  /// Weights of the leaves of `next` from the costs measured on the mesh `old` (the current
  /// one before a regrid; computed_, cost_ and the halo still describe it), the same on every
  /// process (collective): seconds per step of each block, gathered from the processes
  /// computing them (without a step since the last cut, the last weights; none: empty,
  /// uniform); a new leaf takes the weight of the old leaf covering it, or the mean of the
  /// old leaves one level finer it merges; replicated or unmeasured blocks the mean.
  std::vector<double> measured_weights(const blocks::tree& old, const blocks::tree& next) {
    const std::size_t nold = std::size_t(old.size());
    std::vector<double> per(nold, 0.0);
    if (cost_steps_ == 0) {                   // no step since the last cut (the same on every process)
      if (weight_.size() != nold) return {};  // nothing measured yet: uniform
      per = weight_;                          // carry the last weights onto the new leaves
    } else {
      for (index_t id : computed_)
        if (!halo_->everywhere(id)) per[std::size_t(id)] = cost_[std::size_t(id)] / double(cost_steps_);
      halo_->gather_blocks(per, 1);
    }
    double sum = 0.0;
    long count = 0;
    for (std::size_t b = 0; b < nold; ++b) {
      if (halo_->everywhere(index_t(b)) || !(per[b] > 0.0 && std::isfinite(per[b]))) per[b] = -1.0;
      else {
        sum += per[b];
        ++count;
      }
    }
    const double mean = count > 0 ? sum / double(count) : 1.0;
    std::vector<double> w(std::size_t(next.size()), mean);
    for (index_t id = 0; id < next.size(); ++id) {
      const blocks::location q = next.leaf(id);
      const blocks::cover c = old.find(q);
      if (c.kind == blocks::cover::leaf) {
        if (per[std::size_t(c.id)] > 0.0) w[std::size_t(id)] = per[std::size_t(c.id)];
      } else if (c.kind == blocks::cover::finer) {
        double s = 0.0;
        int k = 0;
        for (int o = 0; o < 8; ++o) {
          const blocks::cover f = old.find(q.child(o));
          if (f.kind == blocks::cover::leaf && f.level == q.level + 1 && per[std::size_t(f.id)] > 0.0) {
            s += per[std::size_t(f.id)];
            ++k;
          }
        }
        if (k > 0) w[std::size_t(id)] = s / double(k);
      }
    }
    return w;
  }

  /// U⁰ ← U on every block's span from its first to its last interior cell (the update
  /// reads the interior cells only).
  void save_stage_start() { save_stage_start(computed_); }
  void save_stage_start(const std::vector<index_t>& ids) {
    const index_t first = blocks::block_index{n_}(0, 0, 0);
    const index_t count = blocks::block_index{n_}(n_ - 1, n_ - 1, n_ - 1) + 1 - first;
    for_ids(ids, [&](index_t id) {
      block& b = blocks_[std::size_t(id)];
      const auto U = detail::conserved_ptrs(std::as_const(b.U));
      const auto U0 = detail::conserved_ptrs(b.U0);
      for (int f = 0; f < 5; ++f)
        for (index_t c = first; c < first + count; ++c) U0[f][c] = U[f][c];
    });
  }
  void validate_state(const prim<double>& w, const char* where) const {
    require(std::isfinite(w.rho) && w.rho > 0.0, "fluid::block_solver::", where, ": density must be > 0, got ", w.rho);
    require(std::isfinite(w.p) && w.p > 0.0, "fluid::block_solver::", where, ": pressure must be > 0, got ", w.p);
    require(std::isfinite(w.u.x) && std::isfinite(w.u.y) && std::isfinite(w.u.z), "fluid::block_solver::", where,
            ": velocity must be finite");
  }

  // ------------------------------------------------------------------ phases
  /// max over the blocks this process computes (all processes: a reduction) of the wave
  /// rate Σ_d (|u_d − w_d| + c)/h_d with the viscous limit, each block's scaled by
  /// 2^(ℓ_min − ℓ) when the levels are subcycled (its step is 2^(ℓ − ℓ_min) times shorter).
  double max_rate(double cfl, bool subcycled, const char* who) const {
    require(cfl > 0.0 && cfl <= 1.0, "fluid::block_solver::", who, ": CFL must be in (0, 1], got ", cfl);
    rate_.resize(blocks_.size());  // no allocation once sized (per-block row slots likewise)
    for_computed([&](index_t id) {
      const block& b = blocks_[std::size_t(id)];
      const double* mu_t = nullptr;
      if constexpr (has_eddy_viscosity) mu_t = b.T.template get<field::mu_t>();
      rate_[std::size_t(id)] = detail::max_wave_rate<is_viscous>(b.grid, gas_, pose_, detail::conserved_ptrs(b.U),
                                                                 visc_, turb_, mu_t, cfl, b.rate_slots, false);
    });
    const int lmin = subcycled ? level_range().first : 0;
    double lam = 0.0;
    for (index_t id : computed_) {
      const double r = rate_[std::size_t(id)];
      lam = std::max(lam, subcycled ? std::ldexp(r, lmin - blocks_[std::size_t(id)].where.level) : r);
    }
    if (halo_) lam = halo_->max(lam);  // exact: every process takes the same step
    require(std::isfinite(lam) && lam > 0.0, "fluid::block_solver::", who,
            ": non-finite wave speed (a cell's state is NaN or infinite, or its pressure and density differ in sign)");
    return lam;
  }

  /// One buffer set per thread of the block loop, handed to the serial kernels inside.
  void ensure_buffers() {
    bufs_.resize(std::size_t(parallel::max_threads()));
    for (auto& set : bufs_) detail::ensure_row_buffers(set, n_);
    if constexpr (is_viscous) {
      const index_t cells = blocks_[0].grid.total_cells();
      if (visc_bufs_.size() < bufs_.size()) visc_bufs_.resize(bufs_.size());
      for (auto& vs : visc_bufs_)
        if (vs.size() < cells) vs.resize(cells, 0.0);
    }
  }

  /// The weights β_s of the stages' rates in the step, U^{n+1} = U^n + Δt Σ_s β_s L_s, from
  /// the Shu–Osher form U^(s+1) = a_s U^n + b_s (U^(s) + Δt L_s) (a_s + b_s = 1): ½, ½ for
  /// SSP-RK2, 1/6, 1/6, 2/3 for SSP-RK3.
  static constexpr std::array<double, Time::stages> stage_weights() {
    std::array<double, Time::stages> beta{};
    for (int s = 0; s < Time::stages; ++s) {
      for (int j = 0; j < s; ++j) beta[std::size_t(j)] *= Time::b[std::size_t(s)];
      beta[std::size_t(s)] = Time::b[std::size_t(s)];
    }
    return beta;
  }

  /// Level subcycling's lists for the present mesh: the blocks of each level, the coarser
  /// cells each level's ghost plans read (prolonged from), and one accumulator pair per
  /// coarse–fine correction.
  void prepare_subcycling() {
    if (sub_.ready) return;
    sub_.ready = true;
    std::tie(sub_.lmin, sub_.lmax) = level_range();
    const std::size_t levels = std::size_t(sub_.lmax - sub_.lmin + 1);
    sub_.level_ids.assign(levels, {});
    sub_.coarser.assign(levels, {});
    for (index_t id = 0; id < block_count(); ++id)
      sub_.level_ids[std::size_t(blocks_[std::size_t(id)].where.level - sub_.lmin)].push_back(id);
    for (std::size_t l = 1; l < levels; ++l) {
      std::vector<index_t>& cells = sub_.coarser[l];
      for (index_t id : sub_.level_ids[l])
        blocks::plan_reads(plan_[std::size_t(id)], n_, [&](const blocks::cell_ref& r) {
          if (blocks_[std::size_t(r.block)].where.level + 1 == blocks_[std::size_t(id)].where.level)
            cells.push_back(global_index(r.block, r.cell));
        });
      std::sort(cells.begin(), cells.end());
      cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
    }
    sub_.acc_coarse.resize(blocks_.size());
    sub_.acc_fine.resize(blocks_.size());
    for (std::size_t id = 0; id < blocks_.size(); ++id) {
      sub_.acc_coarse[id].assign(5 * corrections_[id].size(), 0.0);
      sub_.acc_fine[id].assign(5 * corrections_[id].size(), 0.0);
    }
  }

  /// Level l's step from T by dt, inside its coarser level's step from Tp by dtp (itself
  /// for the coarsest level), then the finer level's two steps and the refluxing.
  template <class Patcher, class Finest>
  void advance_level(int l, double T, double dt, double Tp, double dtp, Patcher& patcher, Finest& finest) {
    const std::size_t li = std::size_t(l - sub_.lmin);
    const std::vector<index_t>& ids = sub_.level_ids[li];
    constexpr std::array<double, Time::stages> beta = stage_weights();
    const bool finest_level = l == sub_.lmax;
    if (finest_level) {
      pose_ = sub_.pose0;
      if (T != sub_.t0) pose_.advance(T - sub_.t0);
      finest.before(T, dt);
      for (const patch_face& f : patcher.patch_faces())
        require(f.high >= 0 && f.high < stride_ * block_count() &&
                    blocks_[std::size_t(f.high / stride_)].where.level == sub_.lmax,
                "fluid::block_solver::step_subcycled: a patched face (cell ", f.high,
                ") is not on the finest level: the membrane must lie on the finest level (refine around it)");
    }
    save_stage_start(ids);
    for (index_t id : ids)
      std::fill(sub_.acc_coarse[std::size_t(id)].begin(), sub_.acc_coarse[std::size_t(id)].end(), 0.0);
    ensure_buffers();
    for (int s = 0; s < Time::stages; ++s) {
      const double tau = T + Time::c[std::size_t(s)] * dt;
      pose_ = sub_.pose0;
      if (tau != sub_.t0) pose_.advance(tau - sub_.t0);
      const auto geo = detail::geometry(pose_);
      // The coarser level at the stage's time, for the prolonged ghosts.
      double theta = li > 0 ? (tau - Tp) / dtp : 1.0;
      if (std::fabs(theta - 1.0) < 1e-12) theta = 1.0;
      if (theta != 1.0) detail::timed(times_.boundaries, [&] { interpolate_coarser(li, theta); });
      ghosts_and_sweeps(ids, tau, geo);
      if (theta != 1.0) detail::timed(times_.boundaries, [&] { restore_coarser(li); });
      // This stage's fluxes at the coarse–fine faces into the accumulators: this level's
      // own as the coarse side, and as the fine side of the coarser level's faces.
      for_ids(ids, [&](index_t id) { accumulate_coarse(id, beta[std::size_t(s)]); });
      if (li > 0)
        for_ids(sub_.level_ids[li - 1], [&](index_t id) { accumulate_fine(id, beta[std::size_t(s)] * dt / dtp); });
      if (finest_level && !patcher.patch_faces().empty())
        detail::timed(times_.fluxes, [&] { patch_faces(geo, s, patcher); });
      if (sources_on_ || bc_.layer.cells > 0)
        detail::timed(times_.sources, [&] { for_ids(ids, [&](index_t id) { add_sources(id); }); });
      update(ids, Time::a[std::size_t(s)], Time::b[std::size_t(s)], dt, T + dt, s + 1 == Time::stages);
    }
    if (finest_level) finest.after(T + dt, dt);
    if (l < sub_.lmax) {
      for (index_t id : ids)
        std::fill(sub_.acc_fine[std::size_t(id)].begin(), sub_.acc_fine[std::size_t(id)].end(), 0.0);
      advance_level(l + 1, T, 0.5 * dt, T, dt, patcher, finest);
      advance_level(l + 1, T + 0.5 * dt, 0.5 * dt, T, dt, patcher, finest);
      for_ids(ids, [&](index_t id) { reflux(id, dt); });
      check_refluxed(ids, T + dt);
    }
  }

  /// The refluxed cells of blocks `ids` still a gas (ρ > 0, p > 0), or a message naming one.
  void check_refluxed(const std::vector<index_t>& ids, double t) const {
    for (index_t id : ids) {
      const block& b = blocks_[std::size_t(id)];
      const auto U = detail::conserved_ptrs(std::as_const(b.U));
      for (const auto& fc : corrections_[std::size_t(id)]) {
        const auto q = detail::load_cons(U, fc.cell);
        const double p = gas_.pressure(q.rho, q.m.x, q.m.y, q.m.z, q.E);
        if (!(q.rho > 0.0) || !(p > 0.0) || !std::isfinite(p)) {
          const auto ijk = b.grid.ijk(fc.cell);
          const Eigen::Vector3d x = pose_.to_inertial(
              {b.grid.centre(0, ijk[0]), b.grid.centre(1, ijk[1]), b.grid.centre(2, ijk[2])});
          throw numerical_failure(
              parafsi::detail::concat("fluid::block_solver::step_subcycled: non-physical state after the coarse-fine "
                                      "flux correction in block ",
                                      id, " cell (", ijk[0], ", ", ijk[1], ", ", ijk[2], ") at x = (", x[0], ", ", x[1],
                                      ", ", x[2], ") m, t = ", t, " s: rho = ", q.rho, " kg/m^3, p = ", p,
                                      " Pa; reduce the time step (CFL)"),
              global_index(id, fc.cell), t);
        }
      }
    }
  }

  /// The coarser cells level li's plans prolong from (sub_.coarser): their step's end
  /// state kept aside and U set to (1 − θ) U⁰ + θ U.
  void interpolate_coarser(std::size_t li, double theta) {
    const std::vector<index_t>& cells = sub_.coarser[li];
    sub_.kept.resize(5 * cells.size());
    double* U[5];
    const double* U0[5];
    for (std::size_t f = 0; f < 5; ++f) {
      U[f] = U_->data(f);
      U0[f] = U0_->data(f);
    }
    for (std::size_t k = 0; k < cells.size(); ++k) {
      const index_t g = cells[k];
      for (std::size_t f = 0; f < 5; ++f) {
        sub_.kept[5 * k + f] = U[f][g];
        U[f][g] = (1.0 - theta) * U0[f][g] + theta * U[f][g];
      }
    }
  }
  void restore_coarser(std::size_t li) {
    const std::vector<index_t>& cells = sub_.coarser[li];
    for (std::size_t f = 0; f < 5; ++f) {
      double* U = U_->data(f);
      for (std::size_t k = 0; k < cells.size(); ++k) U[cells[k]] = sub_.kept[5 * k + f];
    }
  }
  /// Coarse block id's own fluxes at its coarse–fine faces, weight w.
  void accumulate_coarse(index_t id, double w) {
    block& b = blocks_[std::size_t(id)];
    std::vector<double>& acc = sub_.acc_coarse[std::size_t(id)];
    const auto& list = corrections_[std::size_t(id)];
    for (std::size_t k = 0; k < list.size(); ++k) {
      const auto& fc = list[k];
      const detail::face_register rc = register_of(b, fc.axis);
      const auto& coarse = fc.side ? rc.hi : rc.lo;
      for (int f = 0; f < 5; ++f) acc[5 * k + std::size_t(f)] += w * coarse[f][fc.coarse_face];
    }
  }
  /// The finer blocks' fluxes at coarse block id's coarse–fine faces (area means), weight w.
  void accumulate_fine(index_t id, double w) {
    std::vector<double>& acc = sub_.acc_fine[std::size_t(id)];
    const auto& list = corrections_[std::size_t(id)];
    for (std::size_t k = 0; k < list.size(); ++k) {
      const auto& fc = list[k];
      const detail::face_register rf = register_of(blocks_[std::size_t(fc.fine_block)], fc.axis);
      const auto& fine = fc.side ? rf.lo : rf.hi;
      for (int f = 0; f < 5; ++f)
        acc[5 * k + std::size_t(f)] += w * (0.25 * ((fine[f][fc.fine_face[0]] + fine[f][fc.fine_face[1]]) +
                                                    (fine[f][fc.fine_face[2]] + fine[f][fc.fine_face[3]])));
    }
  }
  /// Coarse block id after its finer neighbours' steps: each coarse–fine face's flux over
  /// the step replaced by the finer level's, U += dt σ (F̄_c − F̄_f)/Δx.
  void reflux(index_t id, double dt) {
    block& b = blocks_[std::size_t(id)];
    const auto U = detail::conserved_ptrs(b.U);
    const std::vector<double>& ac = sub_.acc_coarse[std::size_t(id)];
    const std::vector<double>& af = sub_.acc_fine[std::size_t(id)];
    const auto& list = corrections_[std::size_t(id)];
    for (std::size_t k = 0; k < list.size(); ++k) {
      const auto& fc = list[k];
      const double id_c = b.grid.inv_widths(fc.axis)[0];
      for (int f = 0; f < 5; ++f) {
        const double Fc = ac[5 * k + std::size_t(f)], Ff = af[5 * k + std::size_t(f)];
        U[f][fc.cell] += dt * ((fc.side ? Fc - Ff : Ff - Fc) * id_c);
      }
    }
  }

  /// dU of one stage at time t on every block, then the coupling's face patches.
  template <class Patcher>
  void compute_rhs(double t, int stage, Patcher& patcher) {
    using detail::timed;
    const auto geo = detail::geometry(pose_);
    ensure_buffers();
    // Each block gets its ghosts and its sweeps (ghosts_and_sweeps), then the coarse–fine
    // corrections.
    auto corrections = [&](const std::vector<index_t>& ids) {
      timed(times_.fluxes, [&] { for_ids(ids, [&](index_t id) { costed(id, [&] { correct_fluxes(id); }); }); });
    };
    if (halo_) {
      // Each exchange travels while blocks that do not wait for it are worked on: the
      // state, while the blocks with local ghosts are swept; the registers (leaving once
      // the blocks other processes read them of are swept), while the remaining blocks are
      // swept and the corrections that read only local registers are made. Every block
      // gets the same operations as on one process, so the order changes no bit.
      timed(times_.exchange, [&] { halo_->begin_state(); });
      ghosts_and_sweeps(local_ids_, t, geo);
      timed(times_.exchange, [&] { halo_->end_state(); });
      ghosts_and_sweeps(remote_send_ids_, t, geo);
      timed(times_.exchange, [&] { halo_->begin_registers(); });
      ghosts_and_sweeps(remote_ids_, t, geo);
      corrections(correct_local_ids_);
      timed(times_.exchange, [&] { halo_->end_registers(); });
      corrections(correct_remote_ids_);
    } else {
      ghosts_and_sweeps(local_ids_, t, geo);
      corrections(correct_local_ids_);
    }
    if (!patcher.patch_faces().empty()) timed(times_.fluxes, [&] { patch_faces(geo, stage, patcher); });
    if (sources_on_ || bc_.layer.cells > 0)
      timed(times_.sources, [&] { for_computed([&](index_t id) { costed(id, [&] { add_sources(id); }); }); });
  }

  /// Each block of `ids` gets its ghosts at time t and then, while they are in cache, its
  /// sweeps (the ghosts read other blocks' interior state, which no sweep writes, so the
  /// fused order changes no bit). The loop's wall time is split between `boundaries` and
  /// `fluxes` in the ratio of the seconds the threads spent on each (summed per thread, in
  /// thread order).
  void ghosts_and_sweeps(const std::vector<index_t>& ids, double t, const detail::stage_geometry& geo) {
    using detail::timed;
    ghost_seconds_.assign(bufs_.size(), 0.0);
    work_seconds_.assign(bufs_.size(), 0.0);
    const auto start = std::chrono::steady_clock::now();
    for_ids(ids, [&](index_t id) {
      const std::size_t tid = std::size_t(parallel::thread_id());
      costed(id, [&] {
        timed(work_seconds_[tid], [&] {
          timed(ghost_seconds_[tid], [&] { fill_block_ghosts(id, t, geo); });
          sweep_block(id, geo);
        });
      });
    });
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    double g = 0.0, w = 0.0;
    for (std::size_t k = 0; k < ghost_seconds_.size(); ++k) {
      g += ghost_seconds_[k];
      w += work_seconds_[k];
    }
    const double share = w > 0.0 ? wall * (g / w) : 0.0;
    times_.boundaries += share;
    times_.fluxes += wall - share;
  }

  /// Primitives and the three flux sweeps of block id (and its viscous pass), keeping its
  /// boundary faces' fluxes in its face register.
  void sweep_block(index_t id, const detail::stage_geometry& geo) {
    block& b = blocks_[std::size_t(id)];
    auto& bufs = bufs_[std::size_t(parallel::thread_id())];
    if constexpr (is_viscous)  // the viscous pass reads the whole ghost ring
      detail::compute_primitives(b.grid.total_cells(), gas_, detail::conserved_ptrs(std::as_const(b.U)),
                                 detail::primitive_ptrs(b.W), false);
    else
      detail::compute_primitives_sweeps(b.grid, gas_, detail::conserved_ptrs(std::as_const(b.U)),
                                        detail::primitive_ptrs(b.W));
    const detail::face_kernel<Flux, Recon> fk{flux_, recon_, gas_, b.grid, detail::primitive_ptrs(std::as_const(b.W))};
    const auto dU = detail::conserved_ptrs(b.dU);
    detail::sweep<0>(fk, geo, dU, bufs, false, register_of(b, 0));
    detail::sweep<1>(fk, geo, dU, bufs, false, register_of(b, 1));
    detail::sweep<2>(fk, geo, dU, bufs, false, register_of(b, 2));
    if constexpr (is_viscous) add_viscous(b, geo, visc_bufs_[std::size_t(parallel::thread_id())]);
  }

  /// The viscous and heat fluxes of block b (detail/viscous.hpp, on the block's grid with its
  /// ghost layers) added to its rates; its boundary faces' fluxes are taken off the face
  /// register, which then holds the total flux F − F_v that the coarse–fine correction
  /// replaces (so the viscous flux is corrected too and conservation holds across levels).
  void add_viscous(block& b, const detail::stage_geometry& geo, viscous_storage& vs) {
    const auto W = detail::primitive_ptrs(std::as_const(b.W));
    const auto dU = detail::conserved_ptrs(b.dU);
    const index_t n = n_;
    auto keep = [&](int d, double* const* Fv) {
      const detail::face_register reg = register_of(b, d);
      const int a1 = d == 0 ? 1 : 0, a2 = d == 2 ? 1 : 2;  // transverse axes, register order
      for (index_t q = 0; q < n; ++q)
        for (index_t p = 0; p < n; ++p) {
          index_t lo[3], hi[3];
          lo[a1] = hi[a1] = p;
          lo[a2] = hi[a2] = q;
          lo[d] = 0;
          hi[d] = n;
          const index_t r = p + n * q, cl = b.grid.index(lo[0], lo[1], lo[2]), ch = b.grid.index(hi[0], hi[1], hi[2]);
          for (int f = 1; f < 5; ++f) {
            reg.lo[f][r] -= Fv[f - 1][cl];
            reg.hi[f][r] -= Fv[f - 1][ch];
          }
        }
    };
    if constexpr (has_eddy_viscosity)
      detail::viscous_pass<Viscosity, Turbulence, viscous_storage, slice<turbulence_storage>>{visc_,  turb_, gas_,
                                                                                              b.grid, vs,    b.T,
                                                                                              false}(geo, W, dU, keep);
    else
      detail::viscous_pass<Viscosity, Turbulence, viscous_storage, empty_storage>{visc_, turb_,    gas_, b.grid,
                                                                                  vs,    no_turb_, false}(geo, W, dU,
                                                                                                          keep);
  }

  /// The coupling's patched faces (detail/patch_faces.hpp): each face's regular flux is
  /// recomputed on the high cell's block, whose ghost layer holds the low cell (a same-level
  /// copy), and the two cells' rates are corrected, dU_low += (F − F_lo)/Δx,
  /// dU_high −= (F − F_hi)/Δx. Both cells must be leaf cells of one level inside the box.
  /// With a one-sided patcher the membrane sees the cells' one-sided values and the
  /// unblocked neighbouring faces are recomputed with them, each cell on its own block (its
  /// stencil of two cells on the open side lies in that block's ghost layer), as on the box:
  /// the same values and corrections, to round-off, on one level.
  /// A recording patcher (patch.hpp) has its faces solved first, each on the process
  /// computing its high cell, which alone receives the cells the face reads (fetch_slots),
  /// into one record per face (the fluxes, the patcher's value and the rate changes). Every
  /// process receives every record's head and replays the patcher's sums in list order; a
  /// whole record goes only to the processes computing a cell it changes, which replay it
  /// onto those cells in list order (send_records). Any other patcher is called face by face
  /// in list order by every process, with every face's cells on every process
  /// (share_slots). Both give the bits of one process.
  template <class Patcher>
  void patch_faces(const detail::stage_geometry& geo, int stage, Patcher& patcher) {
    constexpr bool one_sided = detail::wants_one_sided<Patcher>() && Recon::second_order;
    const std::span<const patch_face> faces = patcher.patch_faces();
    for (std::size_t pi = 0; pi < faces.size(); ++pi) {
      const index_t c = faces[pi].high;
      const int d = faces[pi].axis;
      require(d >= 0 && d < 3 && c >= 0 && c < stride_ * block_count(), "fluid::block_solver: bad patched face ", pi,
              " (cell ", c, ", axis ", d, ")");
      const block& b = blocks_[std::size_t(c / stride_)];
      const auto ijk = b.grid.ijk(c % stride_);
      const index_t m = neighbour(c, d, 0);
      require(ijk[0] >= 0 && ijk[0] < n_ && ijk[1] >= 0 && ijk[1] < n_ && ijk[2] >= 0 && ijk[2] < n_ && m >= 0,
              "fluid::block_solver: patched face ", pi, " (cell ", c, ", axis ", d,
              ") is not between two leaf cells of one level inside the box: the membrane must lie on one level "
              "(refine around it)");
    }
    // Distributed: the cells the faces read come first from the processes computing them
    // (to every process: each solves the faces of its cells, or every face).
    if (halo_) {
      if constexpr (recording_face_patcher<Patcher>) {
        // Only to the process solving each face (the one computing its high cell).
        patch_zone<one_sided>(faces, zone_,
                              [&](std::size_t pi) { return computes_[std::size_t(faces[pi].high / stride_)] != 0; });
        fetch_slots(zone_);
      } else {
        patch_zone<one_sided>(faces, zone_, [](std::size_t) { return true; });
        share_slots(zone_, true);
      }
    }
    if constexpr (one_sided) {
      if (blocked_.size() != std::size_t(stride_ * block_count()))
        blocked_.assign(std::size_t(stride_ * block_count()), 0);
      for (const patch_face& f : faces) {
        blocked_[std::size_t(f.high)] |= std::uint8_t(1u << (2 * f.axis));
        blocked_[std::size_t(neighbour(f.high, f.axis, 0))] |= std::uint8_t(1u << (2 * f.axis + 1));
      }
    }
    const fluid::view state = view();
    const auto dU = detail::conserved_ptrs(*dU_);
    if constexpr (recording_face_patcher<Patcher>) {
      solve_faces<one_sided>(geo, stage, patcher, faces, state);
      replay_faces(stage, patcher, faces.size(), dU);
    } else {
      for (std::size_t pi = 0; pi < faces.size(); ++pi) {
        face_context fc;
        cons<double> F, Flo, Fhi;
        face_record_ix ix;
        regular_patch<one_sided>(geo, stage, faces, pi, fc, F, ix, [&](const double* dF, const face_change_at& at) {
          detail::shift_face_change(dF, at.ga, at.ixa, at.a_in, at.gb, at.ixb, at.b_in, dU);
        });
        Flo = F;
        Fhi = F;
        patcher.patch(fc, state, Flo, Fhi);
        detail::apply_face_patch(F, Flo, Fhi, fc.low, ix.low, true, fc.high, ix.high, true, dU);
      }
    }
    if constexpr (one_sided)
      for (const patch_face& f : faces) {
        blocked_[std::size_t(f.high)] = 0;
        blocked_[std::size_t(neighbour(f.high, f.axis, 0))] = 0;
      }
  }

  /// Where a neighbouring face's flux change goes (detail::shift_face_change's arguments).
  struct face_change_at {
    index_t ga, gb;
    double ixa, ixb;
    bool a_in, b_in;
  };
  /// The inverse widths of a patched face's two cells along its axis.
  struct face_record_ix {
    double low = 0, high = 0;
  };
  /// One patched face up to the patcher: its context (cells, stage, index, geometry and face
  /// states) into fc, its regular flux into F, its cells' inverse widths into ix, and, one-
  /// sided, the flux changes of the unblocked neighbouring faces through
  /// change(dF[5], where), in the order they are applied.
  template <bool OneSided, class Change>
  void regular_patch(const detail::stage_geometry& geo, int stage, std::span<const patch_face> faces, std::size_t pi,
                     face_context& fc, cons<double>& F, face_record_ix& ix, Change&& change) const {
    const index_t c = faces[pi].high;
    const int d = faces[pi].axis;
    const index_t id = c / stride_, lc = c % stride_;
    const block& b = blocks_[std::size_t(id)];
    const index_t ic = b.grid.ijk(lc)[std::size_t(d)];
    // The low cell lies in this block's ghost layer when ic = 0.
    const detail::face_kernel<Flux, Recon> fk{flux_, recon_, gas_, b.grid, detail::primitive_ptrs(std::as_const(b.W))};
    fc.low = neighbour(c, d, 0);
    fc.high = c;
    fc.stage = stage;
    fc.patch = pi;
    F = detail::regular_face(fk, geo, d, lc, fc);
    if constexpr (OneSided)
      detail::with_axis(d, [&](auto D) { one_sided_patch<decltype(D)::value>(geo, c, fc, change); });
    ix.low = b.grid.inv_widths(d)[ic - 1];
    ix.high = b.grid.inv_widths(d)[ic];
  }

  /// Faces solved on threads from this many on (below, waking threads costs more).
  static constexpr std::size_t threaded_faces = 64;
  /// A solved face, as it is replayed (doubles; cell indices are exact): area, F_lo, F_hi,
  /// the patcher's value, F, the two cells and inverse widths, and up to two
  /// neighbouring-face changes (present, dF, ga, ixa, a_in, gb, ixb, b_in).
  /// The first `head` values (area, F_lo, F_hi, the patcher's value) are what the patcher
  /// records; every process receives them. The rest go to the processes computing the cells
  /// they change.
  struct face_record {
    static constexpr int area = 0, lo = 1, hi = 6, value = 11, head = 12, F = 12, low = 17, ix_low = 18, high = 19,
                         ix_high = 20, changes = 21, change_width = 12, width = changes + 2 * change_width;
  };

  /// Solve the faces whose high cell this process computes (all of them without a halo)
  /// into face records, then share them (send_records: the heads with every process, the
  /// whole records with the processes computing the cells they change).
  template <bool OneSided, class Patcher>
  void solve_faces(const detail::stage_geometry& geo, int stage, const Patcher& patcher,
                   std::span<const patch_face> faces, const fluid::view& state) {
    constexpr int W = face_record::width;
    records_.assign(faces.size() * std::size_t(W), 0.0);
    record_block_.resize(faces.size());
    mine_.clear();
    for (std::size_t pi = 0; pi < faces.size(); ++pi) {
      record_block_[pi] = faces[pi].high / stride_;
      if (computes_[std::size_t(record_block_[pi])]) mine_.push_back(index_t(pi));
    }
    // The faces are independent (each writes its own record), so threads may share them. A
    // face that fails marks its record (area −1) and keeps its error, so that every process
    // learns of it from the gathered records and stops at the first failing face in list
    // order (replay_faces): no process is left waiting in a collective call.
    std::mutex failing;
    failed_at_ = faces.size();
    failure_ = nullptr;
    face_seconds_.assign(mine_.size(), 0.0);
    detail::par_for(threaded_ && mine_.size() >= threaded_faces, 0, index_t(mine_.size()), [&](index_t m) {
      const std::size_t pi = std::size_t(mine_[std::size_t(m)]);
      double* r = records_.data() + pi * std::size_t(W);
      try {
        detail::timed(face_seconds_[std::size_t(m)],
                      [&] { solve_face<OneSided>(geo, stage, patcher, faces, pi, state, r); });
      } catch (...) {
        r[face_record::area] = -1.0;
        const std::lock_guard<std::mutex> lock(failing);
        if (pi < failed_at_) {
          failed_at_ = pi;
          failure_ = std::current_exception();
        }
      }
    });
    if (halo_) {
      for (std::size_t m = 0; m < mine_.size(); ++m)  // each face's time to its high cell's block
        cost_[std::size_t(record_block_[std::size_t(mine_[m])])] += face_seconds_[m];
      send_records();
    }
  }

  /// Distributed: every face's head (face_record::head values: what the patcher records)
  /// to every process, from the process solving it; each whole record to the processes
  /// computing a cell whose rate it changes (its low cell and the cells of its neighbouring-
  /// face changes; all processes for a replicated block). held_ then lists, in list order,
  /// the records this process replays onto its cells.
  void send_records() {
    constexpr int W = face_record::width, H = face_record::head;
    const std::size_t count = record_block_.size();
    heads_.assign(count * std::size_t(H), 0.0);
    for (index_t pi : mine_) std::copy_n(records_.data() + std::size_t(pi) * W, H, heads_.data() + std::size_t(pi) * H);
    halo_->gather_items(record_block_, heads_, H);
    const int P = halo_->size(), me = halo_->rank();
    clear_lists(out_, P);
    std::vector<char>& to = to_;
    to.assign(std::size_t(P), 0);
    for (index_t pi : mine_) {
      if (halo_->everywhere(record_block_[std::size_t(pi)])) continue;  // every process solved it
      const double* r = records_.data() + std::size_t(pi) * W;
      if (r[face_record::area] < 0.0) continue;  // failed: every process learns it from the heads
      std::fill(to.begin(), to.end(), 0);
      auto mark = [&](index_t g) {
        if (g < 0) return;
        const index_t b = g / stride_;
        if (halo_->everywhere(b)) std::fill(to.begin(), to.end(), 1);
        else to[std::size_t(halo_->owner(b))] = 1;
      };
      mark(index_t(r[face_record::low]));
      for (int k = 0; k < 2; ++k) {
        const double* c = r + face_record::changes + k * face_record::change_width;
        if (c[0] == 0.0) continue;
        if (c[8] != 0.0) mark(index_t(c[6]));
        if (c[11] != 0.0) mark(index_t(c[9]));
      }
      for (int q = 0; q < P; ++q)
        if (to[std::size_t(q)] && q != me) {
          auto& o = out_[std::size_t(q)];
          o.push_back(double(pi));
          o.insert(o.end(), r, r + W);
        }
    }
    halo_->exchange(out_, in_);
    // This process's records and the received ones, in list order (a face is solved by one
    // process, so no face arrives twice).
    held_.clear();
    for (index_t pi : mine_) held_.emplace_back(std::size_t(pi), records_.data() + std::size_t(pi) * W);
    for (const auto& got : in_)
      for (std::size_t o = 0; o < got.size(); o += std::size_t(W) + 1)
        held_.emplace_back(std::size_t(got[o]), got.data() + o + 1);
    std::sort(held_.begin(), held_.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  }

  /// Face pi solved into its record r.
  template <bool OneSided, class Patcher>
  void solve_face(const detail::stage_geometry& geo, int stage, const Patcher& patcher,
                  std::span<const patch_face> faces, std::size_t pi, const fluid::view& state, double* r) const {
    face_context fc;
    cons<double> F;
    face_record_ix ix;
    int k = 0;
    regular_patch<OneSided>(geo, stage, faces, pi, fc, F, ix, [&](const double* dF, const face_change_at& at) {
      double* c = r + face_record::changes + k++ * face_record::change_width;
      c[0] = 1.0;
      for (int q = 0; q < 5; ++q) c[1 + q] = dF[q];
      c[6] = double(at.ga);
      c[7] = at.ixa;
      c[8] = at.a_in ? 1.0 : 0.0;
      c[9] = double(at.gb);
      c[10] = at.ixb;
      c[11] = at.b_in ? 1.0 : 0.0;
    });
    cons<double> Flo = F, Fhi = F;
    r[face_record::value] = patcher.solve_patch(fc, state, Flo, Fhi);
    r[face_record::area] = fc.area;
    put(r + face_record::F, F);
    put(r + face_record::lo, Flo);
    put(r + face_record::hi, Fhi);
    r[face_record::low] = double(fc.low);
    r[face_record::ix_low] = ix.low;
    r[face_record::high] = double(fc.high);
    r[face_record::ix_high] = ix.high;
  }

  /// Every face's record in list order: the neighbouring-face changes, the patcher's sums,
  /// the face's own correction; rates only of the cells this process computes.
  /// In two passes, which touch different sums: the patcher's, from every face's head in
  /// list order (a failed face stops every process at the first one); then the rates of the
  /// cells this process computes, from the records it holds in list order (all of them on
  /// one process), so every cell gets its changes in the one-process order.
  template <class Patcher>
  void replay_faces(int stage, Patcher& patcher, std::size_t count, const detail::fields5<double>& dU) {
    constexpr int W = face_record::width;
    const bool split = halo_ != nullptr;
    const double* heads = split ? heads_.data() : records_.data();
    const std::size_t hw = split ? std::size_t(face_record::head) : std::size_t(W);
    for (std::size_t pi = 0; pi < count; ++pi) {
      const double* r = heads + pi * hw;
      if (r[face_record::area] < 0.0) {  // the face's solver failed (solve_faces)
        if (failure_ && failed_at_ == pi) std::rethrow_exception(failure_);
        throw numerical_failure(parafsi::detail::concat("fluid::block_solver: patched face ", pi,
                                                        " failed on the process solving it (its message is there)"),
                                long(pi), t_);
      }
      face_context fc;
      fc.stage = stage;
      fc.patch = pi;
      fc.area = r[face_record::area];
      patcher.record_patch(fc, get(r + face_record::lo), get(r + face_record::hi), r[face_record::value]);
    }
    auto here = [&](index_t g) { return g >= 0 && computes_[std::size_t(g / stride_)] != 0; };
    auto apply = [&](const double* r) {
      for (int k = 0; k < 2; ++k) {
        const double* c = r + face_record::changes + k * face_record::change_width;
        if (c[0] == 0.0) continue;
        const index_t ga = index_t(c[6]), gb = index_t(c[9]);
        detail::shift_face_change(c + 1, ga, c[7], c[8] != 0.0 && here(ga), gb, c[10], c[11] != 0.0 && here(gb), dU);
      }
      const index_t low = index_t(r[face_record::low]), high = index_t(r[face_record::high]);
      detail::apply_face_patch(get(r + face_record::F), get(r + face_record::lo), get(r + face_record::hi), low,
                               r[face_record::ix_low], here(low), high, r[face_record::ix_high], here(high), dU);
    };
    if (split)
      for (const auto& h : held_) apply(h.second);
    else
      for (std::size_t pi = 0; pi < count; ++pi) apply(records_.data() + pi * std::size_t(W));
  }
  static void put(double* o, const cons<double>& u) noexcept {
    o[0] = u.rho;
    o[1] = u.m.x;
    o[2] = u.m.y;
    o[3] = u.m.z;
    o[4] = u.E;
  }
  static cons<double> get(const double* o) noexcept { return {o[0], {o[1], o[2], o[3]}, o[4]}; }

  /// The storage slots (block · stride + local, ghosts included) the processing of the
  /// patched faces reads: along each face's axis, the high cell and, one-sided, the low cell
  /// and the cells below and above them (as step_ref walks them), each with the two slots
  /// either side of it in its block's grid (the kernels' stencils), clipped to the grid;
  /// else the high cell's slots and the low cell (the patcher's view). Each once, in the
  /// order first met.
  template <bool OneSided, class Keep>
  void patch_zone(std::span<const patch_face> faces, std::vector<index_t>& zone, Keep&& keep) {
    zone.clear();
    constexpr index_t ng = rectilinear_grid::ghosts;
    // Each slot once, in the order first met (the same on every process): a mark per slot
    // instead of a sort, which cost 3 % of a large drop's step.
    if (zone_mark_.size() != std::size_t(stride_ * block_count()))
      zone_mark_.assign(std::size_t(stride_ * block_count()), 0);
    auto add = [&](index_t g) {
      if (zone_mark_[std::size_t(g)]) return;
      zone_mark_[std::size_t(g)] = 1;
      zone.push_back(g);
    };
    auto around = [&](index_t id, index_t local, int d) {
      const rectilinear_grid& g = blocks_[std::size_t(id)].grid;
      const index_t ia = g.ijk(local)[std::size_t(d)], st = g.stride(d);
      for (index_t k = -2; k <= 2; ++k)
        if (ia + k >= -ng && ia + k < n_ + ng) add(id * stride_ + local + k * st);
    };
    auto unmark = [&] {
      for (index_t g : zone) zone_mark_[std::size_t(g)] = 0;
    };
    try {
      list_zone<OneSided>(faces, around, add, keep);
    } catch (...) {
      unmark();  // a refused face (step_ref) leaves no marks behind
      throw;
    }
    unmark();
  }
  /// Every face is walked (step_ref refuses a level boundary beside a face alike on every
  /// process); the slots of the faces keep(pi) accepts are listed.
  template <bool OneSided, class Around, class Add, class Keep>
  void list_zone(std::span<const patch_face> faces, Around& around, Add& add, Keep& keep) const {
    for (std::size_t pi = 0; pi < faces.size(); ++pi) {
      const patch_face& f = faces[pi];
      const index_t c = f.high;
      const int d = f.axis;
      const bool kept = keep(pi);
      if (kept) around(c / stride_, c % stride_, d);
      if constexpr (OneSided) {
        const cell_ref hc{c / stride_, c % stride_,
                          blocks_[std::size_t(c / stride_)].grid.ijk(c % stride_)[std::size_t(d)], c};
        const cell_ref lc = step_ref(hc, d, 0), below = step_ref(lc, d, 0), above = step_ref(hc, d, 1);
        if (kept)
          for (const cell_ref& r : {lc, below, above}) around(r.id, r.local, d);
      } else if (kept) {
        add(neighbour(c, d, 0));
      }
    }
  }

  /// `lists` with one empty list per process, keeping their capacity (no allocation per stage).
  static void clear_lists(std::vector<std::vector<double>>& lists, int processes) {
    lists.resize(std::size_t(processes));
    for (auto& l : lists) l.clear();
  }

  /// The conserved state and the stage's primitives at storage slots (block · stride +
  /// local, ghosts included) from the processes computing their blocks to this one, which
  /// reads them (collective; each process passes its own slots): one list of slots to each
  /// owner, then their values back (halo::exchange twice). Slots of blocks this process
  /// computes are left as they are.
  void fetch_slots(const std::vector<index_t>& slots) {
    const int P = halo_->size();
    clear_lists(asks_, P);
    for (index_t g : slots) {
      const index_t id = g / stride_;
      if (computes_[std::size_t(id)]) continue;
      asks_[std::size_t(halo_->owner(id))].push_back(double(g));  // exact below 2^53
    }
    halo_->exchange(asks_, asked_);
    const auto& asks = asks_;
    const auto& asked = asked_;
    clear_lists(out_, P);
    const auto U = detail::conserved_ptrs(*U_);
    const auto W = detail::primitive_ptrs(*W_);
    for (int r = 0; r < P; ++r) {
      auto& o = out_[std::size_t(r)];
      for (double x : asked[std::size_t(r)]) {
        const auto g = std::size_t(x);
        for (int f = 0; f < 5; ++f) o.push_back(U[f][g]);
        for (int f = 0; f < 5; ++f) o.push_back(W[f][g]);
      }
    }
    halo_->exchange(out_, in_);
    for (int r = 0; r < P; ++r) {
      const auto& a = asks[std::size_t(r)];
      const auto& v = in_[std::size_t(r)];
      // An internal invariant (an owner answers every slot asked of it, in order): a breach
      // is a bug, stopped here on the process that sees it.
      require(v.size() == 10 * a.size(), "fluid::block_solver: process ", r, " answered ", v.size() / 10, " of ",
              a.size(), " cells");
      for (std::size_t k = 0; k < a.size(); ++k) {
        const auto g = std::size_t(a[k]);
        for (int f = 0; f < 5; ++f) U[f][g] = v[10 * k + std::size_t(f)];
        for (int f = 0; f < 5; ++f) W[f][g] = v[10 * k + 5 + std::size_t(f)];
      }
    }
  }

  /// The conserved state (and with `primitives` the stage's primitives) at storage slots
  /// (block · stride + local, ghosts included) from the processes computing their blocks
  /// to every process (collective, the same slots everywhere). Replicated blocks' slots
  /// are left out: every process holds them.
  void share_slots(const std::vector<index_t>& slots, bool primitives) {
    if (!halo_) return;
    reattach_if_moved();
    share_block_.clear();
    share_slot_.clear();
    for (index_t g : slots) {
      const index_t id = g / stride_;
      if (halo_->everywhere(id)) continue;
      share_block_.push_back(id);
      share_slot_.push_back(g);
    }
    if (share_block_.empty()) return;  // the same on every process
    const int width = primitives ? 10 : 5;
    share_vals_.assign(share_slot_.size() * std::size_t(width), 0.0);
    const auto U = detail::conserved_ptrs(*U_);
    const auto W = detail::primitive_ptrs(*W_);
    for (std::size_t i = 0; i < share_slot_.size(); ++i) {
      if (!computes_[std::size_t(share_block_[i])]) continue;
      double* v = share_vals_.data() + i * std::size_t(width);
      for (int f = 0; f < 5; ++f) v[f] = U[f][share_slot_[i]];
      if (primitives)
        for (int f = 0; f < 5; ++f) v[5 + f] = W[f][share_slot_[i]];
    }
    halo_->gather_items(share_block_, share_vals_, width);
    for (std::size_t i = 0; i < share_slot_.size(); ++i) {
      if (computes_[std::size_t(share_block_[i])]) continue;
      const double* v = share_vals_.data() + i * std::size_t(width);
      for (int f = 0; f < 5; ++f) U[f][share_slot_[i]] = v[f];
      if (primitives)
        for (int f = 0; f < 5; ++f) W[f][share_slot_[i]] = v[5 + f];
    }
  }

  /// A cell as the one-sided reconstruction reads it: the block whose grid holds it (its
  /// own, or for a ghost outside the box the block it borders), its index there, its index
  /// along the axis, and its global index (−1: a ghost outside the box).
  struct cell_ref {
    index_t id, local, ia, global;
  };
  /// The cell next to r along axis d (side 0: low, 1: high); stops the run where that
  /// neighbour is a leaf of another level: the cells whose rates a one-sided patch corrects
  /// (the face's two cells and the next one on each side) must be leaf cells of one level.
  /// The two further cells the stencil reads come from the block's ghost layer, as the
  /// sweeps read them (across a level boundary: prolonged or restricted values).
  cell_ref step_ref(const cell_ref& r, int d, int side) const {
    const block& b = blocks_[std::size_t(r.id)];
    auto ijk = b.grid.ijk(r.local);
    ijk[std::size_t(d)] += side ? 1 : -1;
    const index_t ia = ijk[std::size_t(d)];
    if (r.global >= 0 && (ia < 0 || ia >= n_)) {
      const index_t g = neighbour(r.global, d, side);
      if (g >= 0) return {g / stride_, g % stride_, side ? 0 : n_ - 1, g};
      require(b.boundary[std::size_t(2 * d + side)], "fluid::block_solver: a level boundary (block ", r.id, ", axis ",
              d, ") lies next to the cells of a membrane face: refine around the membrane");
      return {r.id, b.grid.index(ijk[0], ijk[1], ijk[2]), ia, -1};
    }
    return {r.id, b.grid.index(ijk[0], ijk[1], ijk[2]), ia,
            r.global < 0 ? -1 : global_index(r.id, b.grid.index(ijk[0], ijk[1], ijk[2]))};
  }
  /// r's blocked faces along D (blocked_ marks; a ghost outside the box has none).
  template <int D>
  detail::blocked_faces blocked_of(const cell_ref& r) const {
    constexpr std::uint8_t lo_bit = std::uint8_t(1u << (2 * D)), hi_bit = std::uint8_t(1u << (2 * D + 1));
    auto bits = [&](const cell_ref& q) { return q.global >= 0 ? blocked_[std::size_t(q.global)] : std::uint8_t(0); };
    detail::blocked_faces bf;
    bf.lo = bits(r) & lo_bit;
    bf.hi = bits(r) & hi_bit;
    if (bf.lo != bf.hi) bf.far = bits(step_ref(r, D, bf.hi ? 0 : 1)) & (bf.hi ? lo_bit : hi_bit);
    return bf;
  }
  /// The face kernel of the block whose grid holds r.
  detail::face_kernel<Flux, Recon> kernel_of(const cell_ref& r) const {
    const block& b = blocks_[std::size_t(r.id)];
    return {flux_, recon_, gas_, b.grid, detail::primitive_ptrs(std::as_const(b.W))};
  }
  /// The one-sided part of the patch of the face below cell c along D (detail/patch_faces.hpp):
  /// the membrane's face states (fc.L, fc.R), and the flux changes of the unblocked
  /// neighbouring faces, each once, through change(dF[5], where).
  template <int D, class Change>
  void one_sided_patch(const detail::stage_geometry& geo, index_t c, face_context& fc, Change& change) const {
    using side = detail::face_side<Flux, Recon>;
    const cell_ref hc{c / stride_, c % stride_, blocks_[std::size_t(c / stride_)].grid.ijk(c % stride_)[std::size_t(D)],
                      c};
    const cell_ref lc = step_ref(hc, D, 0), below = step_ref(lc, D, 0), above = step_ref(hc, D, 1);
    const auto fk_l = kernel_of(lc), fk_h = kernel_of(hc), fk_b = kernel_of(below), fk_a = kernel_of(above);
    const side L{&fk_l, lc.local, lc.ia, blocked_of<D>(lc), true}, H{&fk_h, hc.local, hc.ia, blocked_of<D>(hc), true};
    double l1[5], h1[5];
    detail::one_sided_cell_faces<D>(fk_l, L.bf, L.cell, L.ia, l1, h1);
    fc.L = detail::prim_of(h1);
    detail::one_sided_cell_faces<D>(fk_h, H.bf, H.cell, H.ia, l1, h1);
    fc.R = detail::prim_of(l1);
    auto move = [&](const cons<double>& dF, const side& a, index_t ga, const side& b, index_t gb) {
      const double d[5] = {dF.rho, dF.m.x, dF.m.y, dF.m.z, dF.E};
      const auto [ixa, ixb] = detail::face_change_widths<D>(a, b);
      change(d, face_change_at{ga, gb, ixa, ixb, a.in, b.in});
    };
    if (!L.bf.lo) {
      const side B{&fk_b, below.local, below.ia, blocked_of<D>(below), below.global >= 0};
      move(detail::neighbour_face_change<D>(geo, B, L), B, below.global, L, lc.global);
    }
    const side A{&fk_a, above.local, above.ia, blocked_of<D>(above), above.global >= 0};
    if (!H.bf.hi && !A.bf.hi) move(detail::neighbour_face_change<D>(geo, H, A), H, hc.global, A, above.global);
  }

  /// Every block's face ghosts from neighbours, then the box's boundary conditions; the
  /// edge ghosts one cell deep only for the viscous pass (its tangential differences on the
  /// first ghost layer read them), which the inviscid kernels never read; corners never.
  void fill_ghosts_all(double t, index_t first, index_t last) {
    const auto geo = detail::geometry(pose_);
    detail::par_for(threaded_, first, last, [&](index_t id) { fill_block_ghosts(id, t, geo); });
  }
  /// Block id's face ghosts from its plan (other blocks' interior cells only), then its box
  /// boundary faces' conditions.
  void fill_block_ghosts(index_t id, double t, const detail::stage_geometry& geo) {
    blocks::execute_plan(plan_[std::size_t(id)], id, U_all_, n_, gas_);
    block& b = blocks_[std::size_t(id)];
    if (b.boundary != std::array<bool, 6>{})
      detail::fill_ghosts(b.grid, bc_, gas_, geo, t, detail::conserved_ptrs(b.U), false, b.boundary, is_viscous,
                          /*edge_depth=*/1);
  }

  /// Before a distributed regrid to `next` (weights `w`, empty for uniform): the blocks this
  /// process will compute (forecast_, the halo's partition of next), the old leaves they
  /// are built from (the leaf covering each, or the leaves it merges) and, for a leaf that
  /// is prolonged, the cells its ghost plan reads (the prolongation's slopes read its
  /// ghosts) are fetched from the processes computing them; then those leaves' ghosts are
  /// filled. Everything transfer() reads is then current here, and nothing else moves.
  void fetch_sources(const blocks::tree& next, const std::vector<double>& w) {
    forecast_ = halo_->would_compute(next, weights_or_uniform(w, std::size_t(next.size())));
    std::vector<char> want(blocks_.size(), 0), prolonged(blocks_.size(), 0);
    auto under = [&](auto&& self, const blocks::location& o) -> void {
      const index_t oid = tree_.id_of(o);
      if (oid >= 0) {
        want[std::size_t(oid)] = 1;
        return;
      }
      for (int ch = 0; ch < 8; ++ch) self(self, o.child(ch));
    };
    for (index_t id = 0; id < next.size(); ++id) {
      if (!forecast_[std::size_t(id)]) continue;
      const blocks::location q = next.leaf(id);
      const blocks::cover c = tree_.find(q);
      if (c.kind == blocks::cover::leaf) {
        want[std::size_t(c.id)] = 1;
        if (tree_.leaf(c.id).level < q.level) prolonged[std::size_t(c.id)] = 1;
      } else
        for (int ch = 0; ch < 8; ++ch) under(under, q.child(ch));
    }
    std::vector<index_t> fill;
    for (index_t id = 0; id < block_count(); ++id)
      if (prolonged[std::size_t(id)]) {
        fill.push_back(id);
        blocks::plan_reads(plan_[std::size_t(id)], n_,
                           [&](const blocks::cell_ref& r) { want[std::size_t(r.block)] = 1; });
      }
    std::vector<index_t> wanted;
    for (index_t id = 0; id < block_count(); ++id)
      if (want[std::size_t(id)]) wanted.push_back(id);
    for (index_t id : wanted)
      if (!computes_[std::size_t(id)]) initialize_block_state(id);  // its ghosts; the fetch brings its cells
    halo_->fetch_blocks(wanted);
    const auto geo = detail::geometry(pose_);
    for_ids(fill, [&](index_t id) { fill_block_ghosts(id, t_, geo); });
  }

  /// Move the state of the old leaves onto the new ones this process computes (regrid).
  void transfer(const std::vector<block>& old, const blocks::tree& old_tree) {
    const index_t n = n_;
    for_computed([&](index_t id) {
      block& nbk = blocks_[std::size_t(id)];
      const blocks::location q = nbk.where;
      const auto U = detail::conserved_ptrs(nbk.U);
      const blocks::cover c = old_tree.find(q);
      if (c.kind == blocks::cover::leaf) {
        const block& ob = old[std::size_t(c.id)];
        const auto V = detail::conserved_ptrs(ob.U);
        const int k = q.level - ob.where.level;  // 0: same block; > 0: prolong
        const double scale = 1.0 / double(std::int64_t(1) << k);
        for (index_t kk = 0; kk < n; ++kk)
          for (index_t j = 0; j < n; ++j)
            for (index_t i = 0; i < n; ++i) {
              const index_t G[3] = {q.l[0] * n + i, q.l[1] * n + j, q.l[2] * n + kk};
              index_t C[3];
              double off[3];
              for (int d = 0; d < 3; ++d) {
                const index_t Cg = G[d] >> k;
                C[d] = Cg - ob.where.l[std::size_t(d)] * n;
                off[d] = (double(G[d]) + 0.5) * scale - (double(Cg) + 0.5);
              }
              const index_t src = ob.grid.index(C[0], C[1], C[2]);
              const index_t dst = nbk.grid.index(i, j, kk);
              if (k == 0) {
                for (int f = 0; f < 5; ++f) U[f][dst] = V[f][src];
                continue;
              }
              double qv[5], cv[5];
              for (int f = 0; f < 5; ++f) {
                cv[f] = V[f][src];
                qv[f] = cv[f];
                for (int d = 0; d < 3; ++d) {
                  const index_t st = ob.grid.stride(d);
                  const double a = cv[f] - V[f][src - st], b = V[f][src + st] - cv[f];
                  const double sl = a * b > 0.0 ? (std::fabs(a) < std::fabs(b) ? a : b) : 0.0;
                  qv[f] += off[d] * sl;
                }
              }
              const bool ok = qv[0] > 0.0 && gas_.pressure(qv[0], qv[1], qv[2], qv[3], qv[4]) > 0.0;
              for (int f = 0; f < 5; ++f) U[f][dst] = ok ? qv[f] : cv[f];
            }
        return;
      }
      // Coarser new leaf: volume means of the old descendants' cells.
      for (int f = 0; f < 5; ++f)
        for (index_t kk = 0; kk < n; ++kk)
          for (index_t j = 0; j < n; ++j)
            for (index_t i = 0; i < n; ++i) U[f][nbk.grid.index(i, j, kk)] = 0.0;
      auto gather = [&](auto&& self, const blocks::location& o) -> void {
        const index_t oid = old_tree.id_of(o);
        if (oid < 0) {
          for (int ch = 0; ch < 8; ++ch) self(self, o.child(ch));
          return;
        }
        const int k = o.level - q.level;
        const block& ob = old[std::size_t(oid)];
        const auto V = detail::conserved_ptrs(ob.U);
        const double w = 1.0 / double(std::int64_t(1) << (3 * k));
        for (index_t kk = 0; kk < n; ++kk)
          for (index_t j = 0; j < n; ++j)
            for (index_t i = 0; i < n; ++i) {
              const index_t G[3] = {o.l[0] * n + i, o.l[1] * n + j, o.l[2] * n + kk};
              const index_t dst = nbk.grid.index((G[0] >> k) - q.l[0] * n, (G[1] >> k) - q.l[1] * n,
                                                 (G[2] >> k) - q.l[2] * n);
              const index_t src = ob.grid.index(i, j, kk);
              for (int f = 0; f < 5; ++f) U[f][dst] += w * V[f][src];
            }
      };
      for (int ch = 0; ch < 8; ++ch) gather(gather, q.child(ch));
    });
  }

  void add_sources(index_t id) {
    block& b = blocks_[std::size_t(id)];
    const auto dU = detail::conserved_ptrs(b.dU);
    const auto U = detail::conserved_ptrs(std::as_const(b.U));
    detail::fields5<const double> src{};
    if (b.sources)
      src = {b.sources.template get<field::s_rho>(), b.sources.template get<field::s_mx>(),
             b.sources.template get<field::s_my>(), b.sources.template get<field::s_mz>(),
             b.sources.template get<field::s_E>()};
    const double* sig = b.sponge ? b.sponge->template get<field::sponge_sigma>() : nullptr;
    if (b.sources && sig) detail::add_sources<true, true>(b.grid, dU, U, src, sig, sponge_target_, false);
    else if (b.sources) detail::add_sources<true, false>(b.grid, dU, U, src, sig, sponge_target_, false);
    else if (sig) detail::add_sources<false, true>(b.grid, dU, U, src, sig, sponge_target_, false);
  }

  /// σ on the cells of a block within the layer of a far-field face (none: no array).
  void setup_sponge(block& b) const {
    const boundary::sponge& layer = bc_.layer;
    if (layer.cells <= 0) return;
    const double cinf = detail::sponge_sound_speed(bc_, gas_);
    bool any = false;
    std::vector<double> sig(std::size_t(b.grid.total_cells()), 0.0);
    for (index_t k = 0; k < n_; ++k)
      for (index_t j = 0; j < n_; ++j)
        for (index_t i = 0; i < n_; ++i) {
          const index_t ijk[3] = {i, j, k};
          double s = 0.0;
          for (int d = 0; d < 3; ++d) {
            const double h0 = layout_.block_width(d, 0) / double(n_);  // root-level cell
            for (int hi = 0; hi < 2; ++hi) {
              if (!std::holds_alternative<boundary::far_field>(bc_.face[std::size_t(2 * d + hi)])) continue;
              const double face = hi ? layout_.hi[std::size_t(d)] : layout_.lo[std::size_t(d)];
              const double gap = std::fabs(face - b.grid.centre(d, ijk[d])) - 0.5 * b.grid.width(d, ijk[d]);
              double dist = gap / h0;  // whole root cells snap to integers against round-off
              if (std::fabs(dist - std::round(dist)) < 1e-9) dist = std::round(dist);
              s = std::max(s, detail::sponge_rate(layer, cinf, double(layer.cells) * h0, dist));
            }
          }
          sig[std::size_t(b.grid.index(i, j, k))] = s;
          any = any || s > 0.0;
        }
    if (!any) return;
    b.sponge.emplace(b.grid.total_cells(), 0.0);
    double* out = b.sponge->template get<field::sponge_sigma>();
    for (std::size_t c = 0; c < sig.size(); ++c) out[c] = sig[c];
  }

  /// Replace this coarse block's fluxes at its coarse–fine faces by the fine means.
  void correct_fluxes(index_t id) {
    block& b = blocks_[std::size_t(id)];
    const auto dU = detail::conserved_ptrs(b.dU);
    for (const auto& fc : corrections_[std::size_t(id)]) {
      const detail::face_register rc = register_of(b, fc.axis);
      const detail::face_register rf = register_of(blocks_[std::size_t(fc.fine_block)], fc.axis);
      const auto& coarse = fc.side ? rc.hi : rc.lo;
      const auto& fine = fc.side ? rf.lo : rf.hi;
      const double id_c = b.grid.inv_widths(fc.axis)[0];
      for (int f = 0; f < 5; ++f) {
        const double Ff = 0.25 * ((fine[f][fc.fine_face[0]] + fine[f][fc.fine_face[1]]) +
                                  (fine[f][fc.fine_face[2]] + fine[f][fc.fine_face[3]]));
        const double Fc = coarse[f][fc.coarse_face];
        dU[f][fc.cell] += (fc.side ? Fc - Ff : Ff - Fc) * id_c;
      }
    }
  }

  void update(double a, double bcoef, double dt, double t_new, bool last) {
    update(computed_, a, bcoef, dt, t_new, last);
  }
  void update(const std::vector<index_t>& ids, double a, double bcoef, double dt, double t_new, bool last) {
    detail::timed(times_.update, [&] {
      for_ids(ids, [&](index_t id) {
        costed(id, [&] {
          block& b = blocks_[std::size_t(id)];
          const auto U = detail::conserved_ptrs(b.U);
          const auto U0 = detail::conserved_ptrs(std::as_const(b.U0));
          const auto dU = detail::conserved_ptrs(std::as_const(b.dU));
          if (last) detail::update<true>(b.grid, gas_, U, U0, dU, a, bcoef, dt, b.bad_rows.data(), false);
          else detail::update<false>(b.grid, gas_, U, U0, dU, a, bcoef, dt, b.bad_rows.data(), false);
        });
      });
      if (last)
        for (index_t id : ids) {
          const block& b = blocks_[std::size_t(id)];
          detail::check_rows(b.grid, gas_, pose_, detail::conserved_ptrs(std::as_const(b.U)), b.bad_rows.data(), t_new);
        }
    });
  }

  blocks::tree tree_;
  block_layout layout_;
  boundary::set bc_;
  gas::ideal gas_;
  Flux flux_;
  Recon recon_;
  [[no_unique_address]] Turbulence turb_;
  Viscosity visc_;
  Frame frame_;
  frame::pose pose_{};
  double t_ = 0.0;
  long steps_ = 0;
  index_t n_ = 0;
  std::vector<block> blocks_;
  index_t stride_ = 0;      ///< cells per block in the mesh-wide arrays
  zeroed_array registers_;  ///< every block's face register (allocate_registers)
  std::unique_ptr<cons_storage> U_, U0_, dU_;
  std::unique_ptr<prim_storage> W_;
  std::unique_ptr<source_storage> S_;                     ///< null until enable_sources
  std::unique_ptr<turbulence_storage> T_;                 ///< with an eddy-viscosity closure
  std::vector<std::uint8_t> blocked_;                     ///< membrane faces' marks (one-sided patches; global_index)
  std::vector<index_t> zone_, share_block_, share_slot_;  ///< patch_zone, share_slots scratch
  std::vector<double> ghost_seconds_, work_seconds_;  ///< ghosts_and_sweeps: ghosts', ghosts' + sweeps' s per thread
  std::vector<double> records_;                       ///< solve_faces: face_record::width per face
  std::vector<index_t> record_block_;                 ///< solve_faces: the block of each face's high cell
  std::vector<index_t> mine_;                         ///< solve_faces: the faces this process solves
  std::vector<double> heads_;                         ///< send_records: face_record::head per face
  std::vector<std::vector<double>> out_, in_;         ///< halo::exchange lists (fetch_slots, send_records)
  std::vector<std::vector<double>> asks_, asked_;     ///< fetch_slots: the slots asked of / by each process
  std::vector<char> to_;                              ///< send_records: the processes a record goes to
  std::vector<std::pair<std::size_t, const double*>> held_;  ///< send_records: (face, record) this process replays
  std::size_t failed_at_ = 0;                                ///< solve_faces: the first face it failed to solve
  std::exception_ptr failure_;                               ///< and that face's error
  std::vector<std::uint8_t> zone_mark_;                      ///< patch_zone: slots already listed (all 0 between calls)
  std::vector<double> share_vals_;
  std::vector<blocks::block_plan> plan_;
  std::vector<std::vector<blocks::flux_correction>> corrections_;
  /// Level subcycling (step_subcycled): the levels, each level's blocks and the coarser
  /// cells its ghost plans read (global indices), the latter's end states while they are
  /// interpolated, the coarse–fine flux accumulators (5 per correction of corrections_),
  /// the pose and time at the step's start.
  struct subcycling {
    bool ready = false;  ///< the lists describe the present mesh
    int lmin = 0, lmax = 0;
    std::vector<std::vector<index_t>> level_ids, coarser;
    std::vector<double> kept;
    std::vector<std::vector<double>> acc_coarse, acc_fine;
    frame::pose pose0{};
    double t0 = 0.0;
  } sub_;
  blocks::block_fields U_all_;
  std::vector<std::vector<detail::row_buffers>> bufs_;  ///< per thread of the block loop
  std::vector<viscous_storage> visc_bufs_;              ///< per thread of the block loop (viscous)
  [[no_unique_address]] empty_storage no_turb_{};
  bool sources_on_ = false;
  mutable std::vector<double> rate_;  ///< stable_dt's per-block maxima
  cons<double> sponge_target_{1.18, {0, 0, 0}, 101325.0 / 0.4};
  phase_times times_{};
  bool threaded_ = false;
  std::shared_ptr<blocks::halo> halo_;         ///< null: this process computes every block
  const block_solver* attached_to_ = nullptr;  ///< the object the halo's pointers point into
  bool gathered_ = true;                       ///< every block's state is current on this process (set by gather())
  std::vector<index_t> computed_;              ///< the blocks this process computes (tree order)
  std::vector<char> forecast_;                 ///< distributed regrid: the new blocks this process will compute
  std::vector<char> computes_;                 ///< per block: whether this process computes it
  // The blocks this process computes, by what they wait for in a stage (attach_halo):
  std::vector<index_t> local_ids_;           ///< ghosts all local (every block without a halo)
  std::vector<index_t> remote_send_ids_;     ///< ghosts read remote cells; other processes read their registers
  std::vector<index_t> remote_ids_;          ///< ghosts read remote cells; their registers stay here
  std::vector<index_t> correct_local_ids_;   ///< corrections read local registers only (all without a halo)
  std::vector<index_t> correct_remote_ids_;  ///< corrections read remote registers
  // Cost-weighted partition (distributed runs; rebalance()):
  std::vector<double> cost_;          ///< per block: seconds of its work since the last partition (computed blocks)
  long cost_steps_ = 0;               ///< steps since the last partition
  std::vector<double> weight_;        ///< per block: its weight in the last partition (empty: uniform)
  std::vector<double> face_seconds_;  ///< solve_faces: seconds of each face this process solved
};

template <policy... Ps>
block_solver(blocks::tree, block_layout, boundary::set, const Ps&...) -> block_solver<
    pick_t<kind::flux, flux::hllc_lm, Ps...>, pick_t<kind::reconstruction, recon::muscl<limiter::van_leer>, Ps...>,
    pick_t<kind::turbulence, turbulence::none, Ps...>, pick_t<kind::viscosity, viscosity::inviscid, Ps...>,
    pick_t<kind::frame, frame::fixed, Ps...>, pick_t<kind::time, time::ssp_rk2, Ps...>>;

}  // namespace parafsi::fluid
