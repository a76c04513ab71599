/// \file block_halo.hpp
/// The block mesh over MPI processes: fluid::blocks::halo (blocks/halo.hpp) with MPI
/// messages. Link the `parafsi::mpi` CMake target to use it; nothing else in the library
/// includes <mpi.h>.
///
///   auto halo = std::make_shared<parafsi::mpi::block_halo>(MPI_COMM_WORLD);
///   solver.set_halo(halo);   // every process: the same mesh and state before, the same calls after
///
/// On `rebuild` (construction, every regrid) each process partitions the leaves' Morton
/// order by the blocks' costs into one contiguous range per rank (blocks::partition); with
/// `replicate_finest` the finest level's blocks (every block of a one-level mesh) are left
/// out of the partition and computed by every process (a coupling's region, for a coupling that reads the air anywhere
/// near the structure: coupling::penalty). Then it lists, per other rank, what it receives from there: the
/// interior cells the ghost plans of its own blocks read (blocks::plan_reads) and the register entries their flux
/// corrections read (blocks::correction_reads), sorted by (block, cell); an MPI_Alltoall of the counts and an
/// MPI_Alltoallv of the lists (once for the state, once for the registers) hand each list to its sender, whose
/// send list it becomes, so a process walks only its own blocks' plans. rebuild is therefore collective. A state
/// exchange is then one message per neighbouring rank each way: MPI_Irecv/MPI_Isend (begin_state), the solver fills the
/// ghosts of and sweeps the owned blocks whose plans read only this rank's cells, then MPI_Waitall (end_state) and the
/// blocks that read remote cells, so the messages overlap that work. The register exchange likewise: its messages leave
/// once the blocks whose registers other ranks read are swept (begin_registers) and travel while the solver sweeps the
/// remaining blocks and corrects the coarse blocks whose corrections read only this rank's registers (end_registers
/// waits). The reductions are MPI_Allreduce (max, exact) and MPI_Allgatherv of per-block values, added in block order
/// by the caller. A coupling's items that every process needs (gather_items: the heads of the embedded coupling's face
/// records, each stage) travel by MPI_Allgatherv, each from the process computing its block, so every process replays
/// every face's load alike; what only some need (the cells a face reads, to its solver; a face's whole record, to the
/// processes owning the cells it changes) by exchange(): an MPI_Alltoall of the counts, then point-to-point messages.
/// Results are therefore bitwise those of one process.
///
/// A regrid or a new partition moves no whole state: each process forecasts the blocks it
/// will compute (would_compute, the same partition rebuild then makes) and fetches from
/// their owners only the old blocks those are built from (fetch_blocks: an all-to-all of
/// the block lists, then one message per peer each way).
///
/// Memory: the solver's mesh-wide arrays are paged storage (core/soa.hpp), so a process is
/// backed only for the blocks it computes and those their ghost plans read (the halo writes
/// their interior cells); gather_state() brings every block to every process (output).
///
/// References: Message Passing Interface Forum (2021) MPI: A Message-Passing Interface
///   Standard, version 4.0 (non-blocking point-to-point, MPI_Allgatherv);
///   Stone J.M. et al. (2020) ApJS 249:4 (Athena++: one buffer per neighbour and variable set).
#pragma once
#include <mpi.h>

#include <algorithm>
#include <cstdlib>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include "../core/config.hpp"
#include "../core/error.hpp"
#include "../fluid/blocks/halo.hpp"

namespace parafsi::mpi {

/// Whether this process was started by an MPI launcher (mpirun/mpiexec of Open MPI or
/// MPICH, Slurm's srun with PMI or PMIx): the environment variables they set.
inline bool launched() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "MPI_LOCALNRANKS"})
    if (std::getenv(v)) return true;
  return false;
}

/// MPI_Init_thread (funneled) / MPI_Finalize for a program's lifetime (a no-op if MPI is already initialised).
/// With `only_if_launched`, MPI is started only under a launcher (launched()), so a program
/// run on its own does not pay MPI's start-up; active() says whether it was.
class environment {
 public:
  environment(int& argc, char**& argv, bool only_if_launched = false) {
    int done = 0;
    MPI_Initialized(&done);
    if (!done && (!only_if_launched || launched())) {
      // OpenMP threads may run inside a process; only its main thread calls MPI.
      int provided = 0;
      MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
      owner_ = true;
      done = 1;
    }
    active_ = done != 0;
  }
  bool active() const noexcept { return active_; }
  ~environment() {
    int fin = 0;
    MPI_Finalized(&fin);
    if (owner_ && !fin) MPI_Finalize();
  }
  environment(const environment&) = delete;
  environment& operator=(const environment&) = delete;

 private:
  bool owner_ = false, active_ = false;
};

/// Options of block_halo.
struct halo_options {
  /// Every process computes the blocks of the finest level (when the mesh has more than
  /// one): the region where a coupling reads and writes the air when the structure lives on
  /// the finest level. coupling::penalty needs it; coupling::embedded does not (its faces'
  /// cells travel to each face's solver each stage), and the drop splits every level with it. The other
  /// blocks are partitioned.
  bool replicate_finest = false;
};

class block_halo final : public fluid::blocks::halo {
 public:
  using cell_ref = fluid::blocks::cell_ref;
  using lists = std::vector<std::vector<cell_ref>>;  ///< per peer rank, sorted

  using options = halo_options;

  /// Works on a duplicate of `comm` (collective), so its messages never match the caller's.
  explicit block_halo(MPI_Comm comm = MPI_COMM_WORLD, halo_options o = halo_options{}) : opt_(o) {
    MPI_Comm_dup(comm, &comm_);
    MPI_Comm_rank(comm_, &rank_);
    MPI_Comm_size(comm_, &size_);
  }
  ~block_halo() override {
    int fin = 0;
    MPI_Finalized(&fin);
    if (!fin) MPI_Comm_free(&comm_);
  }
  block_halo(const block_halo&) = delete;
  block_halo& operator=(const block_halo&) = delete;

  std::vector<index_t> rebuild(const fluid::blocks::mesh_view& m) override {
    m_ = m;
    const index_t nb = index_t(m_.plan->size());
    require(m_.leaves && m_.corrections && m_.U && index_t(m_.registers.size()) == nb &&
                index_t(m_.weight.size()) == nb,
            "mpi::block_halo: incomplete mesh view");
    // Replicated blocks, then a partition of the others' Morton order by weight.
    // (On a one-level mesh the finest level is every block: all are replicated, which is
    // correct for a coupling and divides nothing.)
    assign(*m_.leaves, m_.weight, owner_, everywhere_, owned_);
    // This process's receives, from the blocks it computes only: the cells their ghost plans
    // and the register entries their flux corrections read of blocks computed elsewhere, per
    // owner, sorted by (block, cell) without repeats (blocks::plan_transfers' order). Its
    // sends are the other processes' receives from it, which one all-to-all brings, so no
    // process walks the whole mesh's plans.
    std::vector<index_t> computed;
    remote_reader_.assign(std::size_t(nb), 0);
    remote_corrector_.assign(std::size_t(nb), 0);
    register_sender_.assign(std::size_t(nb), 0);
    state_recv_.assign(std::size_t(size_), {});
    reg_recv_.assign(std::size_t(size_), {});
    for (index_t b = 0; b < nb; ++b) {
      if (!computes(b)) continue;
      computed.push_back(b);
      fluid::blocks::plan_reads((*m_.plan)[std::size_t(b)], m_.n, [&](const cell_ref& c) {
        if (computes(c.block)) return;
        remote_reader_[std::size_t(b)] = 1;
        state_recv_[std::size_t(owner_[std::size_t(c.block)])].push_back(c);
      });
      fluid::blocks::correction_reads((*m_.corrections)[std::size_t(b)], m_.n, [&](const cell_ref& c) {
        if (computes(c.block)) return;
        remote_corrector_[std::size_t(b)] = 1;
        reg_recv_[std::size_t(owner_[std::size_t(c.block)])].push_back(c);
      });
    }
    for (auto* recv : {&state_recv_, &reg_recv_})
      for (auto& items : *recv) {
        std::sort(items.begin(), items.end());
        items.erase(std::unique(items.begin(), items.end()), items.end());
      }
    state_send_ = requests_to_sends(state_recv_);
    reg_send_ = requests_to_sends(reg_recv_);
    for (const auto& items : reg_send_)
      for (const cell_ref& c : items) register_sender_[std::size_t(c.block)] = 1;
    return computed;
  }

  void begin_state() override {
    begin(state_send_, state_recv_, 5, state_at{this});
    ++count_.exchanges;
  }
  void end_state() override { end(state_recv_, 5, state_at{this}); }
  bool reads_remote(index_t id) const override { return remote_reader_[std::size_t(id)] != 0; }

  bool sends_registers(index_t id) const override { return register_sender_[std::size_t(id)] != 0; }
  bool corrects_remote(index_t id) const override { return remote_corrector_[std::size_t(id)] != 0; }
  void begin_registers() override { begin(reg_send_, reg_recv_, 1, register_at{this}); }
  void end_registers() override { end(reg_recv_, 1, register_at{this}); }

  void gather_state() override {
    const index_t n = m_.n;
    const int fields = m_.mu_t.empty() ? 5 : 6;  // the conserved state, and μ_t with a closure
    const fluid::blocks::block_index at{n};
    ++count_.state_gathers;
    gather_by_owner(fields * n * n * n, [&](index_t b, double* o, bool pack) {
      for (int q = 0; q < fields; ++q) {
        double* u = q < 5 ? (*m_.U)[std::size_t(b)][q] : m_.mu_t[std::size_t(b)];
        for (index_t k = 0; k < n; ++k)
          for (index_t j = 0; j < n; ++j)
            for (index_t i = 0; i < n; ++i) {
              double& v = u[at(i, j, k)];
              if (pack) *o++ = v;
              else v = *o++;
            }
      }
    });
  }

  std::vector<char> would_compute(const fluid::blocks::tree& leaves, const std::vector<double>& weight) const override {
    std::vector<int> owner;
    std::vector<char> everywhere;
    std::vector<std::vector<index_t>> owned;
    assign(leaves, weight, owner, everywhere, owned);
    std::vector<char> out(everywhere.size(), 0);
    for (std::size_t b = 0; b < out.size(); ++b) out[b] = size_ == 1 || everywhere[b] || owner[b] == rank_;
    return out;
  }

  /// Asks each owner for its listed blocks (one all-to-all of the block lists), then one
  /// message per peer each way with their interiors (blocks in ascending order).
  void fetch_blocks(const std::vector<index_t>& wanted) override {
    const index_t n = m_.n, n3 = n * n * n;
    const int fields = m_.mu_t.empty() ? 5 : 6;
    lists recv(static_cast<std::size_t>(size_));
    for (index_t b : wanted) {
      require(b >= 0 && b < index_t(owner_.size()), "mpi::block_halo::fetch_blocks: no block ", b);
      if (!computes(b)) recv[std::size_t(owner_[std::size_t(b)])].push_back(cell_ref{b, 0});
    }
    for (auto& items : recv) {
      std::sort(items.begin(), items.end());
      items.erase(std::unique(items.begin(), items.end()), items.end());
    }
    const lists send = requests_to_sends(recv);
    // Values per message (int counts): blocks × fields × n³, every process's verdict shared.
    std::size_t largest = 0;
    for (const lists* l : {static_cast<const lists*>(&recv), &send})
      for (const auto& items : *l) largest = std::max(largest, items.size() * std::size_t(fields * n3));
    MPI_Allreduce(MPI_IN_PLACE, &largest, 1, MPI_UNSIGNED_LONG, MPI_MAX, comm_);
    require(largest < std::size_t(2000000000), "mpi::block_halo::fetch_blocks: ", largest,
            " values in one message, more than 2000000000 (regrid more often or use more processes)");
    // The interior cells of a block in (i, j, k) order, field by field.
    const fluid::blocks::block_index at{n};
    interior_.resize(std::size_t(n3));
    for (index_t k = 0, o = 0; k < n; ++k)
      for (index_t j = 0; j < n; ++j)
        for (index_t i = 0; i < n; ++i) interior_[std::size_t(o++)] = at(i, j, k);
    const auto before = count_;
    begin(send, recv, int(fields * n3), block_at{this, n3});
    end(recv, int(fields * n3), block_at{this, n3});
    // Counted as moved blocks, not as a stage's messages (the communication model's).
    count_.messages = before.messages;
    count_.bytes = before.bytes;
    std::int64_t got = 0;
    for (const auto& items : recv) got += std::int64_t(items.size());
    count_.fetched_blocks += got;
    count_.fetched_bytes += got * std::int64_t(fields) * std::int64_t(n3) * std::int64_t(sizeof(double));
  }

  double max(double local) override {
    double out = local;
    MPI_Allreduce(&local, &out, 1, MPI_DOUBLE, MPI_MAX, comm_);
    return out;
  }

  void gather_blocks(std::vector<double>& per_block, int width) override {
    gather_by_owner(width, [&](index_t b, double* o, bool pack) {
      for (int k = 0; k < width; ++k) {
        double& v = per_block[std::size_t(b * width + k)];
        if (pack) *o++ = v;
        else v = *o++;
      }
    });
  }

  bool everywhere(index_t b) const override { return size_ == 1 || everywhere_[std::size_t(b)] != 0; }
  int owner(index_t b) const override { return owner_[std::size_t(b)]; }

  /// MPI_Alltoall of the counts, then MPI_Irecv/MPI_Isend per non-empty pair.
  void exchange(const std::vector<std::vector<double>>& out, std::vector<std::vector<double>>& in) override {
    require(out.size() == std::size_t(size_), "mpi::block_halo::exchange: ", out.size(), " lists for ", size_,
            " processes");
    // Member buffers (no allocation per stage once sized); the requests are not reqs_, so
    // that a stage's pending exchange is never touched.
    auto& give = give_;
    auto& take = take_;
    auto& reqs = xreqs_;
    give.resize(std::size_t(size_));
    take.resize(std::size_t(size_));
    reqs.clear();
    long largest = 0;
    for (int r = 0; r < size_; ++r) {
      give[std::size_t(r)] = r == rank_ ? 0 : long(out[std::size_t(r)].size());
      largest = std::max(largest, give[std::size_t(r)]);
    }
    // The limit of one message (int counts), checked with every process's verdict, so that
    // all stop or none does.
    MPI_Allreduce(MPI_IN_PLACE, &largest, 1, MPI_LONG, MPI_MAX, comm_);
    require(largest < 2000000000L, "mpi::block_halo::exchange: a process sends ", largest,
            " values in one message, more than 2000000000");
    MPI_Alltoall(give.data(), 1, MPI_LONG, take.data(), 1, MPI_LONG, comm_);
    in.resize(std::size_t(size_));  // the lists keep their capacity
    for (int r = 0; r < size_; ++r) {
      const long k = take[std::size_t(r)];
      in[std::size_t(r)].resize(std::size_t(k));
      if (k == 0) continue;
      reqs.emplace_back();
      MPI_Irecv(in[std::size_t(r)].data(), int(k), MPI_DOUBLE, r, tag_ + 1, comm_, &reqs.back());
    }
    for (int r = 0; r < size_; ++r) {
      const long k = give[std::size_t(r)];
      if (k == 0) continue;
      reqs.emplace_back();
      MPI_Isend(out[std::size_t(r)].data(), int(k), MPI_DOUBLE, r, tag_ + 1, comm_, &reqs.back());
      count_.sparse_bytes += std::int64_t(k) * std::int64_t(sizeof(double));
    }
    MPI_Waitall(int(reqs.size()), reqs.data(), MPI_STATUSES_IGNORE);
    ++count_.sparse_exchanges;
  }

  void gather_items(const std::vector<index_t>& item_block, std::vector<double>& values, int width) override {
    require(values.size() == item_block.size() * std::size_t(width), "mpi::block_halo::gather_items: ", values.size(),
            " values for ", item_block.size(), " items of width ", width);
    counts_.assign(std::size_t(size_), 0);
    for (index_t b : item_block)
      if (!everywhere(b)) counts_[std::size_t(owner_[std::size_t(b)])] += width;
    // Items of partitioned blocks, by owner, in item order: io(rank, gathered, item values).
    auto each = [&](auto&& io) {
      at_.assign(displs_.begin(), displs_.end());
      for (std::size_t i = 0; i < item_block.size(); ++i) {
        const index_t b = item_block[i];
        if (everywhere(b)) continue;
        const int r = owner_[std::size_t(b)];
        io(r, gather_.data() + at_[std::size_t(r)], values.data() + i * std::size_t(width));
        at_[std::size_t(r)] += width;
      }
    };
    const index_t total = allgather([&] {
      each([&](int r, double* g, const double* v) {
        if (r == rank_) std::copy(v, v + width, g);
      });
    });
    each([&](int r, const double* g, double* v) {
      if (r != rank_) std::copy(g, g + width, v);
    });
    ++count_.gathers;
    count_.gathered_bytes += std::int64_t(total) * std::int64_t(sizeof(double));
  }

  int rank() const override { return rank_; }
  int size() const override { return size_; }
  fluid::blocks::halo_counters counters() const override { return count_; }
  /// The partitioned blocks each rank owns (replicated blocks are in no list).
  const std::vector<std::vector<index_t>>& owned() const noexcept { return owned_; }
  /// Cells (state) this rank sends per exchange to each rank.
  const lists& state_sends() const noexcept { return state_send_; }
  const lists& register_sends() const noexcept { return reg_send_; }
  /// Cells (state) this rank receives per exchange from each rank.
  const lists& state_receives() const noexcept { return state_recv_; }
  const lists& register_receives() const noexcept { return reg_recv_; }

 private:
  bool computes(index_t b) const noexcept { return everywhere_[std::size_t(b)] || owner_[std::size_t(b)] == rank_; }

  /// The partition of `leaves` by `weight`: replicated blocks (with replicate_finest, the
  /// finest level's), then the others' Morton order cut into one contiguous range per rank
  /// (blocks::partition). rebuild and would_compute share it, so a regrid's forecast of its
  /// new blocks is the partition it then gets.
  void assign(const fluid::blocks::tree& leaves, const std::vector<double>& weight, std::vector<int>& owner,
              std::vector<char>& everywhere, std::vector<std::vector<index_t>>& owned) const {
    const index_t nb = leaves.size();
    require(index_t(weight.size()) == nb, "mpi::block_halo: ", weight.size(), " block weights for ", nb, " blocks");
    const int finest = leaves.finest_level();
    everywhere.assign(std::size_t(nb), 0);
    if (opt_.replicate_finest)
      for (index_t b = 0; b < nb; ++b) everywhere[std::size_t(b)] = leaves.leaf(b).level == finest;
    std::vector<index_t> spread;
    std::vector<double> w;
    for (index_t b = 0; b < nb; ++b)
      if (!everywhere[std::size_t(b)]) {
        spread.push_back(b);
        w.push_back(weight[std::size_t(b)]);
      }
    const auto cut = spread.empty() ? std::vector<index_t>(std::size_t(size_) + 1, 0)
                                    : fluid::blocks::partition(w, size_);
    owner.assign(std::size_t(nb), 0);
    owned.assign(std::size_t(size_), {});
    for (int r = 0; r < size_; ++r)
      for (index_t k = cut[std::size_t(r)]; k < cut[std::size_t(r) + 1]; ++k) {
        owner[std::size_t(spread[std::size_t(k)])] = r;
        owned[std::size_t(r)].push_back(spread[std::size_t(k)]);
      }
  }

  /// What each rank asks of this one, from what this one asks of each rank (recv[r]: the
  /// items it receives from r, in the order r must send them): MPI_Alltoall of the counts,
  /// MPI_Alltoallv of the (block, cell) pairs. Collective.
  lists requests_to_sends(const lists& recv) {
    static_assert(std::is_same_v<index_t, long>, "block_halo sends cell_ref fields as MPI_LONG");
    constexpr std::size_t most = 2000000000;  // values in one MPI message (int counts)
    const auto ranks = std::size_t(size_);
    std::vector<int> ask(ranks), asked(ranks), ask_at(ranks), asked_at(ranks);
    // Counts and offsets per rank of count_of(r) values. The total is checked on every
    // process before anything moves and the verdict shared, so that a list too long for one
    // message (int counts) stops every process, not one of them.
    auto offsets = [&](auto&& count_of, std::vector<int>& count, std::vector<int>& at, const char* what) {
      std::size_t total = 0;
      for (int r = 0; r < size_; ++r) total += count_of(r);
      std::size_t largest = total;
      MPI_Allreduce(MPI_IN_PLACE, &largest, 1, MPI_UNSIGNED_LONG, MPI_MAX, comm_);
      require(largest < most, "mpi::block_halo: a process ", what, " ", largest,
              " halo values in one list message, more than ", most);
      total = 0;
      for (int r = 0; r < size_; ++r) {
        count[std::size_t(r)] = int(count_of(r));
        at[std::size_t(r)] = int(total);
        total += count_of(r);
      }
      return total;
    };
    const std::size_t out = offsets([&](int r) { return 2 * recv[std::size_t(r)].size(); }, ask, ask_at, "asks for");
    std::vector<long> sbuf;
    sbuf.reserve(out);
    for (const auto& items : recv)
      for (const cell_ref& c : items) {
        sbuf.push_back(c.block);
        sbuf.push_back(c.cell);
      }
    MPI_Alltoall(ask.data(), 1, MPI_INT, asked.data(), 1, MPI_INT, comm_);
    const std::size_t in = offsets([&](int r) { return std::size_t(asked[std::size_t(r)]); }, asked, asked_at,
                                   "is asked for");
    std::vector<long> rbuf(in);
    MPI_Alltoallv(sbuf.data(), ask.data(), ask_at.data(), MPI_LONG, rbuf.data(), asked.data(), asked_at.data(),
                  MPI_LONG, comm_);
    lists send(ranks);
    for (int r = 0; r < size_; ++r) {
      auto& items = send[std::size_t(r)];
      const auto from = std::size_t(asked_at[std::size_t(r)]), to = from + std::size_t(asked[std::size_t(r)]);
      items.reserve((to - from) / 2);
      for (std::size_t k = from; k < to; k += 2) items.push_back(cell_ref{index_t(rbuf[k]), index_t(rbuf[k + 1])});
    }
    return send;
  }

  /// MPI_Allgatherv of `per` values per partitioned block, each from its owner:
  /// io(block, buffer, pack) packs (pack true) or unpacks the block's values.
  template <class IO>
  void gather_by_owner(index_t per, IO&& io) {
    counts_.assign(std::size_t(size_), 0);
    for (int r = 0; r < size_; ++r) counts_[std::size_t(r)] = per * index_t(owned_[std::size_t(r)].size());
    allgather([&] {
      double* mine = gather_.data() + displs_[std::size_t(rank_)];
      for (index_t b : owned_[std::size_t(rank_)]) {
        io(b, mine, true);
        mine += per;
      }
    });
    for (int r = 0; r < size_; ++r) {
      if (r == rank_) continue;
      double* o = gather_.data() + displs_[std::size_t(r)];
      for (index_t b : owned_[std::size_t(r)]) {
        io(b, o, false);
        o += per;
      }
    }
  }

  /// MPI_Allgatherv into gather_ of counts_[r] values from each rank r, in rank order:
  /// sets displs_, sizes gather_, lets pack() fill this rank's part, then gathers in place.
  /// Returns the number of values.
  template <class Pack>
  index_t allgather(Pack&& pack) {
    displs_.assign(std::size_t(size_), 0);
    mpi_counts_.assign(std::size_t(size_), 0);
    mpi_displs_.assign(std::size_t(size_), 0);
    index_t total = 0;
    for (int r = 0; r < size_; ++r) {
      const index_t count = counts_[std::size_t(r)];
      require(total + count < index_t(2000000000), "mpi::block_halo: too many values for one gather message (",
              total + count, ")");
      displs_[std::size_t(r)] = total;
      mpi_displs_[std::size_t(r)] = int(total);
      mpi_counts_[std::size_t(r)] = int(count);
      total += count;
    }
    gather_.resize(std::size_t(total));
    pack();
    MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, gather_.data(), mpi_counts_.data(), mpi_displs_.data(),
                   MPI_DOUBLE, comm_);
    return total;
  }

  /// The conserved value f of a cell (the state exchange's storage).
  struct state_at {
    const block_halo* h;
    double& operator()(const cell_ref& c, int f) const { return (*h->m_.U)[std::size_t(c.block)][f][c.cell]; }
  };
  /// A face-register entry (the register exchange's storage; c.cell is the offset in it).
  struct register_at {
    const block_halo* h;
    double& operator()(const cell_ref& c, int) const { return h->m_.registers[std::size_t(c.block)][c.cell]; }
  };

  /// A whole block's interior, field by field (fetch_blocks' storage; c.block the block,
  /// value k the interior cell k % n³ of field k / n³, μ_t as the sixth).
  struct block_at {
    const block_halo* h;
    index_t n3;
    double& operator()(const cell_ref& c, int k) const {
      const auto f = std::size_t(k / n3);
      const index_t cell = h->interior_[std::size_t(k % n3)];
      return f < 5 ? (*h->m_.U)[std::size_t(c.block)][f][cell] : h->m_.mu_t[std::size_t(c.block)][cell];
    }
  };

  /// One message per peer each way: post the receives, pack and send (begin); wait and
  /// unpack (end). width values per listed item, at(item, k) the storage of value k.
  template <class At>
  void begin(const lists& send, const lists& recv, int width, At&& at) {
    sbuf_.resize(std::size_t(size_));
    rbuf_.resize(std::size_t(size_));
    reqs_.clear();
    for (int r = 0; r < size_; ++r) {
      const auto& items = recv[std::size_t(r)];
      if (items.empty()) continue;
      auto& buf = rbuf_[std::size_t(r)];
      buf.resize(items.size() * std::size_t(width));
      reqs_.emplace_back();
      MPI_Irecv(buf.data(), int(buf.size()), MPI_DOUBLE, r, tag_, comm_, &reqs_.back());
    }
    for (int r = 0; r < size_; ++r) {
      const auto& items = send[std::size_t(r)];
      if (items.empty()) continue;
      auto& buf = sbuf_[std::size_t(r)];
      buf.resize(items.size() * std::size_t(width));
      std::size_t o = 0;
      for (const auto& c : items)
        for (int k = 0; k < width; ++k) buf[o++] = at(c, k);
      reqs_.emplace_back();
      MPI_Isend(buf.data(), int(buf.size()), MPI_DOUBLE, r, tag_, comm_, &reqs_.back());
      ++count_.messages;
      count_.bytes += std::int64_t(buf.size() * sizeof(double));
    }
  }
  template <class At>
  void end(const lists& recv, int width, At&& at) {
    MPI_Waitall(int(reqs_.size()), reqs_.data(), MPI_STATUSES_IGNORE);
    reqs_.clear();
    for (int r = 0; r < size_; ++r) {
      const auto& items = recv[std::size_t(r)];
      const auto& buf = rbuf_[std::size_t(r)];
      std::size_t o = 0;
      for (const auto& c : items)
        for (int k = 0; k < width; ++k) at(c, k) = buf[o++];
    }
  }

  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  static constexpr int tag_ = 4242;
  fluid::blocks::mesh_view m_;
  options opt_;
  std::vector<int> owner_;                   ///< per block: its owner (0 for replicated blocks)
  std::vector<char> everywhere_;             ///< per block: computed by every process
  std::vector<std::vector<index_t>> owned_;  ///< per rank: its partitioned blocks
  std::vector<char> remote_reader_;          ///< per block: its ghost plan reads another process's cells
  std::vector<char> remote_corrector_;       ///< per block: its flux corrections read another process's registers
  std::vector<char> register_sender_;        ///< per block: another process reads its register
  lists state_send_, state_recv_, reg_send_, reg_recv_;
  std::vector<std::vector<double>> sbuf_, rbuf_;
  std::vector<double> gather_;
  std::vector<index_t> counts_, displs_, at_;  ///< allgather: values per rank, offsets; gather_items' cursor
  std::vector<int> mpi_counts_, mpi_displs_;
  std::vector<index_t> interior_;  ///< fetch_blocks: a block's interior cells, (i, j, k) order
  std::vector<MPI_Request> reqs_;
  std::vector<long> give_, take_;   ///< exchange: values to and from each rank
  std::vector<MPI_Request> xreqs_;  ///< exchange: its requests
  fluid::blocks::halo_counters count_;
};

}  // namespace parafsi::mpi
