/// \file halo.hpp
/// What a block mesh split over several processes needs, without naming how the data
/// travel (the MPI implementation is mpi/block_halo.hpp, behind its own target).
///
/// Every process keeps the whole tree, its exchange plans and flux corrections, and the
/// mesh-wide arrays in paged storage, backed only for the blocks it holds (its own and those
/// its ghost plans read; docs/guide_mpi.md, Memory), and computes only the blocks it owns: a contiguous range of the
/// leaves' Morton order, cut by cost (`partition`, with the blocks' measured seconds per
/// step as weights: fluid::block_solver::rebalance), and the blocks every process computes
/// (optionally, e.g. for coupling::penalty: the finest level, where a coupling reads and
/// writes the air). A stage of the block solver then reads four kinds of data another
/// process computed:
///   - the interior cells that its own blocks' ghost plans read (copies, restrictions and
///     the prolongation stencils, blocks/exchange.hpp): `plan_reads` lists them;
///   - the face-register entries of finer blocks that its coarse blocks' flux corrections
///     read (blocks/flux_correction.hpp): `correction_reads`;
///   - the cells a coupling's patched faces read (fluid::block_solver's fetch_slots: the
///     stage's state and primitives around a face, to the process solving it), the heads of
///     the solved face records (gathered to every process, so the replicated structure gets
///     the same loads) and the whole records (to the processes computing the cells they
///     change; `exchange`);
///   - reductions: the stable step (a maximum, exact) and sums over the mesh, which are
///     formed per block and added in block order on every process, so that they do not
///     depend on the number of processes.
/// A block is computed by its owner (or by every process, from the same inputs) with the
/// serial kernels, and a value is moved, never recomputed differently, so a run gives the
/// same bits on any number of processes.
///
/// References: Burstedde C., Wilcox L.C., Ghattas O. (2011) SIAM J. Sci. Comput. 33:1103
///   (p4est: partition of the Morton order by weight); Stone J.M. et al. (2020) ApJS 249:4
///   (Athena++: MeshBlocks distributed along the Z-order curve, boundary buffers per
///   neighbour).
#pragma once
#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "../../core/config.hpp"
#include "../../core/error.hpp"
#include "exchange.hpp"
#include "flux_correction.hpp"
#include "tree.hpp"

namespace parafsi::fluid::blocks {

/// The first block of each of `parts` processes (and the block count at the end): the
/// leaves' order cut into contiguous ranges of nearly equal total weight (each cut where the
/// running sum first reaches r/parts of the total). Every range is non-empty when there are
/// at least as many blocks as parts.
inline std::vector<index_t> partition(const std::vector<double>& weight, int parts) {
  require(parts >= 1, "blocks::partition: need at least one part, got ", parts);
  const index_t nb = index_t(weight.size());
  double total = 0.0;
  for (double w : weight) {
    require(w > 0.0 && w < 1e300, "blocks::partition: block weights must be positive and finite");
    total += w;
  }
  // prefix[b]: the weight of blocks [0, b); block b goes to the part its centre falls in.
  std::vector<double> prefix(std::size_t(nb) + 1, 0.0);
  for (index_t b = 0; b < nb; ++b) prefix[std::size_t(b + 1)] = prefix[std::size_t(b)] + weight[std::size_t(b)];
  std::vector<index_t> start(std::size_t(parts) + 1, nb);
  start[0] = 0;
  index_t b = 0;
  for (int r = 1; r < parts; ++r) {
    const double goal = total * double(r) / double(parts);
    while (b < nb && 0.5 * (prefix[std::size_t(b)] + prefix[std::size_t(b + 1)]) < goal) ++b;
    // At least one block per part while there are enough of them.
    const index_t lo = std::min(nb, start[std::size_t(r - 1)] + (nb >= parts ? 1 : 0));
    const index_t hi = std::max(lo, nb - (nb >= parts ? index_t(parts - r) : 0));
    b = std::clamp(b, lo, hi);
    start[std::size_t(r)] = b;
  }
  return start;
}

/// A cell of a block (local flat index, ghosts included).
struct cell_ref {
  index_t block, cell;
  friend auto operator<=>(const cell_ref&, const cell_ref&) = default;
};

/// Every cell of another block that the ghost plan of block `dst` reads, through f(cell_ref).
template <class F>
void plan_reads(const block_plan& p, index_t n, F&& f) {
  constexpr index_t g = rectilinear_grid::ghosts;
  const index_t sy = n + 2 * g, sz = sy * sy;
  for (const auto& bx : p.copies)
    for (index_t c = 0; c < bx.extent[2]; ++c)
      for (index_t r = 0; r < bx.extent[1]; ++r)
        for (index_t a = 0; a < bx.extent[0]; ++a) f(cell_ref{bx.src_block, bx.src + a + r * sy + c * sz});
  auto eight = [&](index_t b, index_t c) {
    for (index_t o : {index_t(0), index_t(1), sy, sy + 1, sz, sz + 1, sz + sy, sz + sy + 1}) f(cell_ref{b, c + o});
  };
  for (const auto& it : p.restrictions) eight(it.src_block, it.src);
  auto value = [&](const value_ref& v) {
    if (v.block < 0) return;
    if (v.restricted) eight(v.block, v.cell);
    else f(cell_ref{v.block, v.cell});
  };
  for (const auto& grp : p.prolongations) {
    value(grp.centre);
    for (const auto& s : grp.side) value(s);
  }
}

/// Values per face register of a block of n³ cells: [axis][side][component][n²].
inline index_t register_size(index_t n) noexcept { return 3 * 2 * 5 * n * n; }

/// Every register entry of a finer block that the flux corrections of coarse block `id`
/// read, through f(cell_ref{fine block, offset in its register}).
template <class F>
void correction_reads(const std::vector<flux_correction>& fcs, index_t n, F&& f) {
  const index_t n2 = n * n;
  for (const auto& fc : fcs) {
    const index_t side = 1 - fc.side;  // the fine block's face towards the coarse cell
    for (index_t comp = 0; comp < 5; ++comp)
      for (index_t face : fc.fine_face)
        f(cell_ref{fc.fine_block, (index_t(fc.axis) * 10 + side * 5 + comp) * n2 + face});
  }
}

/// The owner of each block for the partition `starts` (blocks [starts[r], starts[r + 1]) on r).
inline std::vector<int> owners(const std::vector<index_t>& starts) {
  std::vector<int> out(std::size_t(starts.back()), 0);
  for (std::size_t r = 0; r + 1 < starts.size(); ++r)
    for (index_t b = starts[r]; b < starts[r + 1]; ++b) out[std::size_t(b)] = int(r);
  return out;
}

/// One value that travels between two processes in a stage: `what` (a cell or a register
/// entry) from process `from`, which owns its block, to process `to`, which reads it.
struct transfer {
  int from, to;
  cell_ref what;
  friend auto operator<=>(const transfer&, const transfer&) = default;
};

/// Every cell (state exchange) or register entry (flux correction) that crosses between
/// processes in a stage, sorted by (from, to, block, cell) and without repeats: the exchange
/// lists of every process at once (a process sends the entries with from == its rank,
/// grouped by `to`, and receives those with to == its rank), and the communication model's
/// counts (bench/halo_model.cpp). Block b is computed by process owner[b], or by every
/// process if everywhere[b] (a replicated block: a coupling's region); a process receives
/// what the blocks it computes read of blocks it does not compute, from their owners.
inline std::pair<std::vector<transfer>, std::vector<transfer>> plan_transfers(
    const std::vector<block_plan>& plan, const std::vector<std::vector<flux_correction>>& corrections, index_t n,
    const std::vector<int>& owner, const std::vector<char>& everywhere, int processes) {
  std::vector<transfer> state, regs;
  for (std::size_t b = 0; b < plan.size(); ++b) {
    const int r0 = everywhere[b] ? 0 : owner[b], r1 = everywhere[b] ? processes : owner[b] + 1;
    for (int to = r0; to < r1; ++to) {
      auto note = [&](std::vector<transfer>& out) {
        return [&, to](const cell_ref& c) {
          const std::size_t src = std::size_t(c.block);
          if (!everywhere[src] && owner[src] != to) out.push_back({owner[src], to, c});
        };
      };
      plan_reads(plan[b], n, note(state));
      correction_reads(corrections[b], n, note(regs));
    }
  }
  for (auto* v : {&state, &regs}) {
    std::sort(v->begin(), v->end());
    v->erase(std::unique(v->begin(), v->end()), v->end());
  }
  return {std::move(state), std::move(regs)};
}

/// The same for contiguous ranges (blocks [starts[r], starts[r + 1]) on process r) and no
/// replicated blocks.
inline std::pair<std::vector<transfer>, std::vector<transfer>> plan_transfers(
    const std::vector<block_plan>& plan, const std::vector<std::vector<flux_correction>>& corrections, index_t n,
    const std::vector<index_t>& starts) {
  return plan_transfers(plan, corrections, n, owners(starts), std::vector<char>(plan.size(), 0),
                        int(starts.size()) - 1);
}

/// What a halo reads and writes of a block mesh (block_solver::mesh_view()).
struct mesh_view {
  index_t n = 0;  ///< cells per block edge
  const tree* leaves = nullptr;
  const std::vector<block_plan>* plan = nullptr;
  const std::vector<std::vector<flux_correction>>* corrections = nullptr;
  const block_fields* U = nullptr;  ///< per block: its 5 conserved arrays (ghosts included)
  std::vector<double*> registers;   ///< per block: its face register (register_size(n) values)
  std::vector<double*> mu_t;        ///< per block: its eddy viscosity (none without a closure)
  std::vector<double> weight;       ///< per block: its cost, for the partition
};

/// Message counters of a halo (its own bookkeeping, for the communication model).
struct halo_counters {
  std::int64_t messages = 0;          ///< point-to-point messages sent
  std::int64_t bytes = 0;             ///< bytes in them
  std::int64_t exchanges = 0;         ///< state exchanges (one per stage, one per vorticity_indicator)
  std::int64_t gathers = 0;           ///< item gathers (gather_items: the coupling's face heads per stage, share_cells)
  std::int64_t gathered_bytes = 0;    ///< bytes they assembled on every process
  std::int64_t state_gathers = 0;     ///< whole-state gathers (gather_state: output, checkpoints)
  std::int64_t fetched_blocks = 0;    ///< blocks received by fetch_blocks (regrids, repartitions)
  std::int64_t fetched_bytes = 0;     ///< bytes in them
  std::int64_t sparse_exchanges = 0;  ///< exchange() calls (the embedded coupling's cells and records, per stage)
  std::int64_t sparse_bytes = 0;      ///< bytes this process sent in them
};

/// The interface the block solver calls at the points of a stage where another process's
/// data are read (block_solver::set_halo). All calls are collective: every process makes
/// them in the same order.
class halo {
 public:
  virtual ~halo() = default;
  /// The mesh is new (construction, regrid, restart): partition it and plan the messages;
  /// returns the blocks this process computes, in tree order.
  virtual std::vector<index_t> rebuild(const mesh_view& m) = 0;
  /// Bring the cells the owned blocks' ghost plans read from their owners (before a stage),
  /// in two halves: begin_state() starts the messages, end_state() waits for them and
  /// stores the cells; between the two the solver works on the blocks that read no other
  /// process's cells (reads_remote(id) false).
  virtual void begin_state() = 0;
  virtual void end_state() = 0;
  /// Whether the ghost plan of computed block `id` reads cells this process does not compute.
  virtual bool reads_remote(index_t id) const = 0;
  /// Whether computed block `id` holds register entries another process's corrections read.
  virtual bool sends_registers(index_t id) const = 0;
  /// Whether the flux corrections of computed block `id` read register entries of blocks
  /// this process does not compute.
  virtual bool corrects_remote(index_t id) const = 0;
  /// Bring the finer blocks' register entries the owned coarse blocks' corrections read,
  /// in two halves: begin_registers() (once every block with sends_registers(id) is swept)
  /// starts the messages, end_registers() waits and stores them; between the two the solver
  /// sweeps the blocks that send nothing and corrects those with corrects_remote(id) false.
  virtual void begin_registers() = 0;
  virtual void end_registers() = 0;
  /// Every block's interior cells (and eddy viscosity, with a closure) to every process
  /// (before a checkpoint or output).
  virtual void gather_state() = 0;
  /// Which leaves of the mesh `leaves` with block costs `weight` this process would compute
  /// (per leaf, 1 or 0) if rebuild were called with them: the same partition, without
  /// adopting it (a regrid asks before it moves the state).
  virtual std::vector<char> would_compute(const tree& leaves, const std::vector<double>& weight) const = 0;
  /// The interior cells (and eddy viscosity, with a closure) of the listed blocks of the
  /// present mesh from the processes computing them to this one; blocks this process
  /// computes are left as they are. Every process passes its own list (collective): a
  /// regrid or a new partition moves only what each process's new blocks are built from.
  virtual void fetch_blocks(const std::vector<index_t>& wanted) = 0;
  /// The maximum of a value over the processes.
  virtual double max(double local) = 0;
  /// per_block holds `width` values per block, filled for the blocks this process computes:
  /// fill the rest from their owners.
  virtual void gather_blocks(std::vector<double>& per_block, int width) = 0;
  /// Whether every process computes block b (a replicated block).
  virtual bool everywhere(index_t b) const = 0;
  /// The process computing partitioned block b (meaningless for a replicated block).
  virtual int owner(index_t b) const = 0;
  /// out[r] to process r, in[r] from process r, for every r (out[rank()] stays here and
  /// in[rank()] is left empty): one count per pair, then a message where one is non-empty
  /// (collective; each process passes its own lists). The embedded coupling's cells go to
  /// the processes solving its faces and the solved records to those owning their cells.
  virtual void exchange(const std::vector<std::vector<double>>& out, std::vector<std::vector<double>>& in) = 0;
  /// Items held by blocks: item_block[i] is the block holding item i, values holds `width`
  /// values per item, filled for the items of the blocks this process owns (not the
  /// replicated ones): fill the others' from their owners; the items of replicated blocks
  /// are left as they are. Every process passes the same item_block.
  virtual void gather_items(const std::vector<index_t>& item_block, std::vector<double>& values, int width) = 0;
  /// This process's rank and the number of processes.
  virtual int rank() const = 0;
  virtual int size() const = 0;
  virtual halo_counters counters() const = 0;
};

}  // namespace parafsi::fluid::blocks
