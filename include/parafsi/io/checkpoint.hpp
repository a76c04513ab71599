/// \file checkpoint.hpp
/// Checkpoint/restart of the full state of fluid solvers and structure assemblies, for
/// the user's loop (DESIGN §1; io/ is never included by physics headers). A run
/// restored from a checkpoint continues bit for bit like the run that wrote it
/// (tests/test_io_checkpoint.cpp), on the same build and thread-independent kernels.
///
///   io::save_checkpoint("out/run.ckpt", solver, assembly);   // or (stepper)
///   ...
///   fluid::solver s2{same grid, bcs, policies};  structure::assembly a2{same scene};
///   io::load_checkpoint("out/run.ckpt", s2, a2);              // then continue stepping
///
/// Arguments are fluid solvers, structure assemblies, or (save only) an
/// explicit_stepper, whose fluid and structure are written. The k-th solver goes to the
/// section "fluid" (k = 0) or "fluid.k", the k-th assembly to "structure"/"structure.k";
/// a stepper also writes "stepper" (its time, steps and last substep count). Loading
/// reads the sections its arguments need and ignores the others. A stepper is restored
/// by loading its fluid and assembly first and then constructing it from them: its own
/// clock starts at the fluid's time, and the first coupling kick uses the last substep
/// length (exact when the fluid step and the substep count are unchanged across the
/// checkpoint; explicit_stepper exposes no setter for its private clock).
///
/// What is stored (everything the next step reads):
///   fluid: the conserved fields on all cells, ghosts and SIMD padding included; time;
///          step count (written, see the limitation below); box pose X, R, V, Ω; the
///          frame policy's state (translate/rigid velocities, follow_payload's axis,
///          limits, target and offset); the source arrays if enabled; the eddy
///          viscosity μ_t (used by stable_dt) and the wall distance when present.
///   structure: every node array (x, v, f, m, 1/m and the energy-ledger force parts,
///          padding included), constraint kinds and point masses, integrator settings
///          (gravity, mass damping, TSSF), the clock (time, substeps, last substep length,
///          energy tracking and ledger), per element part its per-element pressure load
///          (membranes), and every rigid body's state() (momenta at t^{n−½}, attitudes
///          at t^n and t^{n−½}, pending loads, previous step length).
///   Elements hold no other history: membranes are total-Lagrangian with the
///   velocity-proportional damping computed from the node velocities; cables are
///   elastic + velocity damping. Reference geometry, rest lengths and masses come from
///   the scene the user rebuilds; they are fingerprinted and compared on load.
///
/// File format (version 1, native byte order recorded and checked):
///   "PARAFSI-CHECKPOINT\n" (19 bytes), u32 version, u32 0x01020304 (byte order),
///   u64 payload length, payload, u64 FNV-1a-64 checksum of the payload.
///   The payload is a sequence of named entries: u8 kind, u16 name length, name, then
///   kind 'S' (section begin) / 'E' (section end) / 'i' (i64) / 'd' (f64) /
///   's' (u64 length + bytes) / 'D' (u64 count + f64 values) / 'I' (u64 count + i64)
///   / 'B' (u64 count + bytes). Each section starts with its signature (type name,
///   sizes, policy names) so that a checkpoint of another scene is refused with a
///   message naming what differs (e.g. "grid axis 0 has 16 cells in the file but 24 in
///   this solver"); a truncated or corrupted file is refused before anything is
///   changed (`checkpoint_error`, an invalid_input). A failed load leaves the targets
///   untouched only for those errors; a signature mismatch in a later section can
///   follow an earlier section's successful restore.
/// Writing goes to `path.tmp` then renames it, so a crash during a write leaves the
/// previous checkpoint intact.
///
/// Limitation (fluid/ offers no setter): fluid::solver::steps() of a restored solver
/// counts from 0 (it is only a counter; no result depends on it). The file holds the
/// original value (`checkpoint_info::fluid_steps`).
#pragma once
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "../core/error.hpp"
#include "../core/simd.hpp"
#include "../fluid/frame/fixed.hpp"
#include "../fluid/frame/follow_payload.hpp"
#include "../fluid/frame/rigid.hpp"
#include "../fluid/frame/translate.hpp"
#include "../structure/energy.hpp"
#include "../structure/nodes.hpp"
#include "../structure/rigid_body.hpp"

namespace parafsi::io {

/// A checkpoint that cannot be read into the given objects (message says why).
struct checkpoint_error : invalid_input {
  using invalid_input::invalid_input;
};

inline constexpr std::string_view checkpoint_magic = "PARAFSI-CHECKPOINT\n";
inline constexpr std::uint32_t checkpoint_version = 1;

namespace ckpt {

inline std::uint64_t fnv1a(const unsigned char* p, std::size_t n) {
  std::uint64_t h = 14695981039346656037ull;
  for (std::size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
  return h;
}

/// Serialises named entries into a byte buffer.
class writer {
 public:
  std::vector<unsigned char> buf;

  void begin(std::string_view section) { head('S', section); }
  void end(std::string_view section) { head('E', section); }
  void i64(std::string_view name, std::int64_t v) { head('i', name); raw(&v, sizeof v); }
  void f64(std::string_view name, double v) { head('d', name); raw(&v, sizeof v); }
  void str(std::string_view name, std::string_view v) {
    head('s', name);
    count(v.size());
    raw(v.data(), v.size());
  }
  void f64s(std::string_view name, const double* p, std::size_t n) {
    head('D', name);
    count(n);
    raw(p, n * sizeof(double));
  }
  void f64s(std::string_view name, const std::vector<double>& v) { f64s(name, v.data(), v.size()); }
  void i64s(std::string_view name, const std::vector<std::int64_t>& v) {
    head('I', name);
    count(v.size());
    raw(v.data(), v.size() * sizeof(std::int64_t));
  }
  void bytes(std::string_view name, const std::vector<unsigned char>& v) {
    head('B', name);
    count(v.size());
    raw(v.data(), v.size());
  }
  template <int N>
  void vec(std::string_view name, const Eigen::Matrix<double, N, 1>& v) { f64s(name, v.data(), std::size_t(N)); }
  void mat3(std::string_view name, const Eigen::Matrix3d& m) { f64s(name, m.data(), 9); }
  void quat(std::string_view name, const Eigen::Quaterniond& q) { f64s(name, q.coeffs().data(), 4); }

 private:
  void raw(const void* p, std::size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    buf.insert(buf.end(), c, c + n);
  }
  void count(std::uint64_t n) { raw(&n, sizeof n); }
  void head(char kind, std::string_view name) {
    buf.push_back(static_cast<unsigned char>(kind));
    const auto len = static_cast<std::uint16_t>(name.size());
    raw(&len, sizeof len);
    raw(name.data(), name.size());
  }
};

/// Reads the entries of one section in order; every mismatch is a checkpoint_error
/// naming the file, the section and the entry.
class reader {
 public:
  reader(const std::vector<unsigned char>& b, std::size_t begin, std::size_t end, std::string where)
      : b_(b), p_(begin), end_(end), where_(std::move(where)) {}

  std::int64_t i64(std::string_view name) { expect('i', name); std::int64_t v; take(&v, sizeof v); return v; }
  double f64(std::string_view name) { expect('d', name); double v; take(&v, sizeof v); return v; }
  std::string str(std::string_view name) {
    expect('s', name);
    std::string s(count(1), '\0');
    take(s.data(), s.size());
    return s;
  }
  std::vector<double> f64s(std::string_view name) {
    expect('D', name);
    std::vector<double> v(count(sizeof(double)));
    take(v.data(), v.size() * sizeof(double));
    return v;
  }
  /// An f64 array of exactly n values into p.
  void f64s_into(std::string_view name, double* p, std::size_t n) {
    expect('D', name);
    const std::size_t m = count(sizeof(double));
    if (m != n) fail(name, " has ", m, " values in the file but ", n, " here");
    take(p, n * sizeof(double));
  }
  std::vector<std::int64_t> i64s(std::string_view name) {
    expect('I', name);
    std::vector<std::int64_t> v(count(sizeof(std::int64_t)));
    take(v.data(), v.size() * sizeof(std::int64_t));
    return v;
  }
  std::vector<unsigned char> bytes(std::string_view name) {
    expect('B', name);
    std::vector<unsigned char> v(count(1));
    take(v.data(), v.size());
    return v;
  }
  template <int N>
  Eigen::Matrix<double, N, 1> vec(std::string_view name) {
    Eigen::Matrix<double, N, 1> v;
    f64s_into(name, v.data(), std::size_t(N));
    return v;
  }
  Eigen::Matrix3d mat3(std::string_view name) {
    Eigen::Matrix3d m;
    f64s_into(name, m.data(), 9);
    return m;
  }
  Eigen::Quaterniond quat(std::string_view name) {
    Eigen::Quaterniond q;
    f64s_into(name, q.coeffs().data(), 4);
    return q;
  }

  /// Signature checks: the file's value must equal this object's.
  void same(std::string_view what, std::int64_t file, std::int64_t here) {
    if (file != here) fail(what, " is ", file, " in the file but ", here, " here");
  }
  void same(std::string_view what, const std::string& file, const std::string& here) {
    if (file != here) fail(what, " is '", file, "' in the file but '", here, "' here");
  }
  void same_value(std::string_view what, double file, double here) {
    if (std::memcmp(&file, &here, sizeof(double)) != 0) fail(what, " is ", file, " in the file but ", here, " here");
  }

  template <class... A>
  [[noreturn]] void fail(A&&... a) const {
    throw checkpoint_error(detail::concat(where_, ": ", std::forward<A>(a)...));
  }

 private:
  std::size_t count(std::size_t elem) {
    std::uint64_t n;
    take(&n, sizeof n);
    if (elem > 0 && n > (end_ - p_) / elem) fail("an entry claims ", n, " items, more than the section holds");
    return std::size_t(n);
  }
  void take(void* dst, std::size_t n) {
    if (n > end_ - p_) fail("section ends inside an entry");
    std::memcpy(dst, b_.data() + p_, n);
    p_ += n;
  }
  void expect(char kind, std::string_view name) {
    if (p_ + 3 > end_) fail("expected entry '", name, "' but the section ends");
    const char k = char(b_[p_]);
    std::uint16_t len;
    std::memcpy(&len, b_.data() + p_ + 1, sizeof len);
    if (p_ + 3 + len > end_) fail("entry name runs past the section");
    const std::string got(reinterpret_cast<const char*>(b_.data() + p_ + 3), len);
    if (got != name || k != kind)
      fail("expected entry '", name, "' (kind ", kind, ") but found '", got, "' (kind ", k,
           "): written by another version or another scene");
    p_ += 3 + std::size_t(len);
  }
  const std::vector<unsigned char>& b_;
  std::size_t p_, end_;
  std::string where_;
};

/// A whole checkpoint file, verified (magic, version, byte order, length, checksum)
/// and split into sections.
class file {
 public:
  explicit file(const std::filesystem::path& path) : path_(path.string()) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw checkpoint_error(detail::concat("checkpoint ", path_, ": cannot open the file"));
    std::vector<unsigned char> all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t m = checkpoint_magic.size();
    if (all.size() < m || std::memcmp(all.data(), checkpoint_magic.data(), m) != 0)
      fail("not a parafsi checkpoint (the file does not start with the magic string)");
    if (all.size() < m + 16) fail("truncated: ", all.size(), " bytes, shorter than the header");
    std::uint32_t version, order;
    std::uint64_t len;
    std::memcpy(&version, all.data() + m, 4);
    std::memcpy(&order, all.data() + m + 4, 4);
    std::memcpy(&len, all.data() + m + 8, 8);
    if (order != 0x01020304u) fail("written on a machine of the other byte order");
    if (version != checkpoint_version)
      fail("format version ", version, ", this library reads version ", checkpoint_version);
    const std::size_t head = m + 16;
    if (all.size() < head + 8 || len > all.size() - head - 8)
      fail("truncated: ", all.size(), " bytes, the header announces ", head + len + 8);
    if (all.size() != head + len + 8) fail("has ", all.size() - head - len - 8, " unexpected bytes after its end");
    std::uint64_t sum;
    std::memcpy(&sum, all.data() + head + len, 8);
    if (sum != fnv1a(all.data() + head, std::size_t(len))) fail("corrupted: checksum mismatch");
    data_.assign(all.begin() + std::ptrdiff_t(head), all.begin() + std::ptrdiff_t(head + len));
    index_sections();
  }

  bool has(const std::string& section) const { return sections_.count(section) > 0; }
  std::vector<std::string> names() const {
    std::vector<std::string> v;
    for (const auto& [k, r] : order_) v.push_back(r);
    return v;
  }
  reader section(const std::string& name) const {
    const auto it = sections_.find(name);
    if (it == sections_.end()) {
      std::string have;
      for (const auto& n : names()) have += (have.empty() ? "" : ", ") + n;
      fail("has no section '", name, "' (it holds: ", have.empty() ? "nothing" : have, ")");
    }
    return reader(data_, it->second.first, it->second.second, "checkpoint " + path_ + ", section '" + name + "'");
  }

  template <class... A>
  [[noreturn]] void fail(A&&... a) const {
    throw checkpoint_error(detail::concat("checkpoint ", path_, ": ", std::forward<A>(a)...));
  }

 private:
  /// Walk the entries once: every section's [begin, end) and well-formedness.
  void index_sections() {
    std::size_t p = 0;
    const std::size_t n = data_.size();
    std::string open;
    std::size_t open_at = 0;
    auto need = [&](std::size_t k) {
      if (k > n - p) fail("malformed payload at byte ", p);
    };
    while (p < n) {
      need(3);
      const char kind = char(data_[p]);
      std::uint16_t len;
      std::memcpy(&len, data_.data() + p + 1, 2);
      need(3 + std::size_t(len));
      const std::string name(reinterpret_cast<const char*>(data_.data() + p + 3), len);
      p += 3 + std::size_t(len);
      std::uint64_t cnt = 0;
      switch (kind) {
        case 'S':
          if (!open.empty()) fail("section '", name, "' opens inside section '", open, "'");
          open = name;
          open_at = p;
          break;
        case 'E':
          if (open != name) fail("section end '", name, "' does not match '", open, "'");
          sections_[name] = {open_at, p - 3 - std::size_t(len)};
          order_.emplace(order_.size(), name);
          open.clear();
          break;
        case 'i': case 'd': need(8); p += 8; break;
        case 's': case 'B': need(8); std::memcpy(&cnt, data_.data() + p, 8); p += 8; if (cnt > n - p) fail("malformed entry '", name, "'"); p += std::size_t(cnt); break;
        case 'D': case 'I': need(8); std::memcpy(&cnt, data_.data() + p, 8); p += 8; if (cnt > (n - p) / 8) fail("malformed entry '", name, "'"); p += std::size_t(cnt) * 8; break;
        default: fail("unknown entry kind ", int(kind), " at byte ", p);
      }
    }
    if (!open.empty()) fail("section '", open, "' is not closed");
  }
  std::string path_;
  std::vector<unsigned char> data_;
  std::map<std::string, std::pair<std::size_t, std::size_t>> sections_;
  std::map<std::size_t, std::string> order_;
};

inline void write_file(const std::filesystem::path& path, const writer& w) {
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::filesystem::path tmp = path;
  tmp += ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    require(out.good(), "io::save_checkpoint: cannot open ", tmp.string(), " for writing");
    const std::uint32_t version = checkpoint_version, order = 0x01020304u;
    const std::uint64_t len = w.buf.size(), sum = fnv1a(w.buf.data(), w.buf.size());
    out.write(checkpoint_magic.data(), std::streamsize(checkpoint_magic.size()));
    out.write(reinterpret_cast<const char*>(&version), 4);
    out.write(reinterpret_cast<const char*>(&order), 4);
    out.write(reinterpret_cast<const char*>(&len), 8);
    out.write(reinterpret_cast<const char*>(w.buf.data()), std::streamsize(w.buf.size()));
    out.write(reinterpret_cast<const char*>(&sum), 8);
    out.flush();
    require(out.good(), "io::save_checkpoint: writing ", tmp.string(), " failed (disk full?)");
  }
  std::filesystem::rename(tmp, path);
}

// ------------------------------------------------------------------ concepts
template <class T>
concept fluid_solver = requires(const T& s) {
  s.grid();
  s.pose();
  s.conserved_storage();
  s.frame();
  T::has_eddy_viscosity;
};
template <class T>
concept structure_assembly = requires(const T& a) {
  a.node_set();
  a.previous_step();
  T::part_count;
};
template <class T>
concept coupled_stepper = requires(const T& s) {
  T::has_fluid;
  T::has_structure;
  s.last_substeps();
};

/// Allocated length of a soa field of n entries (soa::resize: padded + one pack).
inline std::size_t soa_length(index_t n) { return simd::padded(std::size_t(n)) + simd::width; }

// ------------------------------------------------------------------ frames
inline void save_frame(writer&, const frame::fixed&) {}
inline void load_frame(reader&, frame::fixed&) {}
inline void save_frame(writer& w, const frame::translate& f) { w.vec<3>("frame.velocity", f.velocity); }
inline void load_frame(reader& r, frame::translate& f) { f.velocity = r.vec<3>("frame.velocity"); }
inline void save_frame(writer& w, const frame::rigid& f) {
  w.vec<3>("frame.velocity", f.velocity);
  w.vec<3>("frame.angular_velocity", f.angular_velocity);
}
inline void load_frame(reader& r, frame::rigid& f) {
  f.velocity = r.vec<3>("frame.velocity");
  f.angular_velocity = r.vec<3>("frame.angular_velocity");
}
inline void save_frame(writer& w, const frame::follow_payload& f) {
  w.vec<3>("frame.axis", f.axis);
  w.f64("frame.min_speed", f.min_speed);
  w.f64("frame.max_rate", f.max_rate);
  w.i64("frame.turn", f.turn ? 1 : 0);
  w.vec<3>("frame.target_position", f.target_position);
  w.vec<3>("frame.target_velocity", f.target_velocity);
  w.vec<3>("frame.offset", f.offset);
}
inline void load_frame(reader& r, frame::follow_payload& f) {
  f.axis = r.vec<3>("frame.axis");
  f.min_speed = r.f64("frame.min_speed");
  f.max_rate = r.f64("frame.max_rate");
  f.turn = r.i64("frame.turn") != 0;
  f.target_position = r.vec<3>("frame.target_position");
  f.target_velocity = r.vec<3>("frame.target_velocity");
  f.offset = r.vec<3>("frame.offset");
}
/// Other frame policies: stateless (empty) ones need nothing; stateful ones provide
/// `save_checkpoint(ckpt::writer&) const` and `load_checkpoint(ckpt::reader&)`.
template <class F>
  requires(!std::is_same_v<F, frame::fixed> && !std::is_same_v<F, frame::translate> &&
           !std::is_same_v<F, frame::rigid> && !std::is_same_v<F, frame::follow_payload>)
void save_frame(writer& w, const F& f) {
  if constexpr (requires { f.save_checkpoint(w); }) f.save_checkpoint(w);
  else static_assert(std::is_empty_v<F>, "io::checkpoint: this frame policy holds state; give it "
                                         "save_checkpoint(ckpt::writer&) const and load_checkpoint(ckpt::reader&)");
}
template <class F>
  requires(!std::is_same_v<F, frame::fixed> && !std::is_same_v<F, frame::translate> &&
           !std::is_same_v<F, frame::rigid> && !std::is_same_v<F, frame::follow_payload>)
void load_frame(reader& r, F& f) {
  if constexpr (requires { f.load_checkpoint(r); }) f.load_checkpoint(r);
}

// ------------------------------------------------------------------ fluid
template <class Solver>
void save_fluid(writer& w, const std::string& name, const Solver& s) {
  const auto& g = s.grid();
  const index_t N = g.total_cells();
  const std::size_t L = soa_length(N);
  w.begin(name);
  w.str("type", s.name());
  w.i64("ghosts", Solver::ng);
  for (int d = 0; d < 3; ++d) w.f64s("grid.axis" + std::to_string(d), g.axis_of(d).faces);
  w.i64("total_cells", N);
  w.i64("field_length", std::int64_t(L));
  w.f64("gas.gamma", s.gas().gamma);
  w.f64("gas.R", s.gas().R);
  w.f64("time", s.time());
  w.i64("steps", s.steps());
  w.vec<3>("pose.X", s.pose().X);
  w.mat3("pose.R", s.pose().R);
  w.vec<3>("pose.V", s.pose().V);
  w.vec<3>("pose.Omega", s.pose().Omega);
  save_frame(w, s.frame());
  const auto& U = s.conserved_storage();
  for (std::size_t f = 0; f < Solver::cons_storage::field_count; ++f)
    w.f64s("U" + std::to_string(f), U.data(f), L);
  w.i64("sources", s.has_sources() ? 1 : 0);
  if (s.has_sources()) {
    // The source accessors are non-const; reading through them changes nothing.
    auto& m = const_cast<Solver&>(s);
    for (int c = 0; c < 4; ++c) w.f64s("source" + std::to_string(c), m.source(c), L);
    w.f64s("source_mass", m.source_mass(), L);
  }
  if constexpr (Solver::has_eddy_viscosity) {
    w.f64s("mu_t", s.eddy_viscosity(), L);
    if constexpr (Solver::needs_wall_distance) w.f64s("wall_distance", const_cast<Solver&>(s).wall_distance(), L);
  }
  w.end(name);
}

template <class Solver>
void load_fluid(const file& f, const std::string& name, Solver& s) {
  reader r = f.section(name);
  const auto& g = s.grid();
  // Signature first: nothing is changed unless the whole signature matches.
  r.same("the solver type", r.str("type"), s.name());
  r.same("the number of ghost layers", r.i64("ghosts"), Solver::ng);
  for (int d = 0; d < 3; ++d) {
    const auto faces = r.f64s("grid.axis" + std::to_string(d));
    const auto& mine = g.axis_of(d).faces;
    if (faces.size() != mine.size())
      r.fail("grid axis ", d, " has ", index_t(faces.size()) - 1, " cells in the file but ", index_t(mine.size()) - 1,
             " in this solver");
    for (std::size_t i = 0; i < faces.size(); ++i)
      if (faces[i] != mine[i])
        r.fail("grid axis ", d, " face ", i, " is at ", faces[i], " in the file but ", mine[i], " in this solver");
  }
  const index_t N = g.total_cells();
  const std::size_t L = soa_length(N);
  r.same("the cell count incl. ghosts", r.i64("total_cells"), N);
  r.same("the field length (cells + SIMD padding; another SIMD width?)", r.i64("field_length"), std::int64_t(L));
  r.same_value("gas gamma", r.f64("gas.gamma"), s.gas().gamma);
  r.same_value("gas constant R", r.f64("gas.R"), s.gas().R);
  // State: read into temporaries, then commit.
  const double t = r.f64("time");
  const long fluid_steps = long(r.i64("steps"));
  frame::pose pose;
  pose.X = r.vec<3>("pose.X");
  pose.R = r.mat3("pose.R");
  pose.V = r.vec<3>("pose.V");
  pose.Omega = r.vec<3>("pose.Omega");
  auto fr = s.frame();
  load_frame(r, fr);
  std::vector<std::vector<double>> U(Solver::cons_storage::field_count, std::vector<double>(L));
  for (std::size_t q = 0; q < U.size(); ++q) r.f64s_into("U" + std::to_string(q), U[q].data(), L);
  const bool src = r.i64("sources") != 0;
  std::vector<std::vector<double>> S;
  if (src) {
    for (int c = 0; c < 4; ++c) S.push_back(r.f64s("source" + std::to_string(c)));
    S.push_back(r.f64s("source_mass"));
    for (const auto& v : S)
      if (v.size() != L) r.fail("a source array has ", v.size(), " values, expected ", L);
  }
  std::vector<double> mut, wd;
  if constexpr (Solver::has_eddy_viscosity) {
    mut.resize(L);
    r.f64s_into("mu_t", mut.data(), L);
    if constexpr (Solver::needs_wall_distance) {
      wd.resize(L);
      r.f64s_into("wall_distance", wd.data(), L);
    }
  }
  // Commit.
  s.set_time(t);
  s.set_steps(fluid_steps);
  s.pose() = pose;
  s.frame() = fr;
  auto& st = s.conserved_storage();
  for (std::size_t q = 0; q < U.size(); ++q) std::memcpy(st.data(q), U[q].data(), L * sizeof(double));
  if (src) {
    s.enable_sources();
    for (int c = 0; c < 4; ++c) std::memcpy(s.source(c), S[std::size_t(c)].data(), L * sizeof(double));
    std::memcpy(s.source_mass(), S[4].data(), L * sizeof(double));
  } else if (s.has_sources()) {
    for (int c = 0; c < 4; ++c) std::fill(s.source(c), s.source(c) + L, 0.0);
    std::fill(s.source_mass(), s.source_mass() + L, 0.0);
  }
  if constexpr (Solver::has_eddy_viscosity) {
    // fluid::solver exposes μ_t read-only; the storage belongs to the (non-const)
    // solver, so writing through it is defined. stable_dt() reads it.
    std::memcpy(const_cast<double*>(s.eddy_viscosity()), mut.data(), L * sizeof(double));
    if constexpr (Solver::needs_wall_distance) std::memcpy(s.wall_distance(), wd.data(), L * sizeof(double));
  }
}

// ------------------------------------------------------------------ structure
template <class Assembly, class F>
void for_each_part(Assembly& a, F&& f) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (f(std::integral_constant<std::size_t, I>{}, a.template part<I>()), ...);
  }(std::make_index_sequence<std::remove_cvref_t<Assembly>::part_count>{});
}

/// Fingerprint of an element part's set-up: connectivity and reference data.
template <class P>
std::uint64_t part_fingerprint(const P& p) {
  std::vector<unsigned char> b;
  auto put = [&](const void* q, std::size_t n) {
    const auto* c = static_cast<const unsigned char*>(q);
    b.insert(b.end(), c, c + n);
  };
  if constexpr (requires { p.element(index_t(0)); }) {
    for (index_t e = 0; e < p.size(); ++e) {
      const auto el = p.element(e);
      for (auto n : el) { const std::int64_t v = n; put(&v, 8); }
      if constexpr (requires { p.rest_length(e); }) { const double v = p.rest_length(e); put(&v, 8); }
      if constexpr (requires { p.reference_area(e); }) { const double v = p.reference_area(e); put(&v, 8); }
    }
  }
  return fnv1a(b.data(), b.size());
}

inline void save_body(writer& w, const std::string& k, const structure::rigid_body_state& s) {
  w.f64(k + ".mass", s.mass);
  w.mat3(k + ".inertia", s.inertia);
  w.vec<3>(k + ".com_body", s.com_body);
  w.vec<3>(k + ".x_com", s.x_com);
  w.quat(k + ".q", s.q);
  w.quat(k + ".q_half", s.q_half);
  w.vec<3>(k + ".p", s.p);
  w.vec<3>(k + ".l", s.l);
  w.vec<3>(k + ".omega_body", s.omega_body);
  w.vec<3>(k + ".force_com", s.force_com);
  w.vec<3>(k + ".force_points", s.force_points);
  w.vec<3>(k + ".moment_origin", s.moment_origin);
  w.f64(k + ".dt_prev", s.dt_prev);
  w.f64(k + ".time", s.time);
  w.i64(k + ".steps", s.steps);
}
inline structure::rigid_body_state load_body(reader& r, const std::string& k) {
  structure::rigid_body_state s;
  s.mass = r.f64(k + ".mass");
  s.inertia = r.mat3(k + ".inertia");
  s.com_body = r.vec<3>(k + ".com_body");
  s.x_com = r.vec<3>(k + ".x_com");
  s.q = r.quat(k + ".q");
  s.q_half = r.quat(k + ".q_half");
  s.p = r.vec<3>(k + ".p");
  s.l = r.vec<3>(k + ".l");
  s.omega_body = r.vec<3>(k + ".omega_body");
  s.force_com = r.vec<3>(k + ".force_com");
  s.force_points = r.vec<3>(k + ".force_points");
  s.moment_origin = r.vec<3>(k + ".moment_origin");
  s.dt_prev = r.f64(k + ".dt_prev");
  s.time = r.f64(k + ".time");
  s.steps = r.i64(k + ".steps");
  return s;
}

template <class Assembly>
void save_structure(writer& w, const std::string& name, const Assembly& a) {
  const auto& nd = a.node_set();
  require(!nd.needs_finalize(), "io::save_checkpoint: the assembly is not finalized (call finalize() or step first)");
  const index_t N = nd.size();
  const std::size_t L = soa_length(N);
  w.begin(name);
  w.str("type", Assembly::name());
  w.i64("nodes", N);
  w.i64("field_length", std::int64_t(L));
  w.f64("time", a.time());
  for_each_part(a, [&](auto I, const auto& p) {
    const std::string k = "part" + std::to_string(decltype(I)::value);
    w.str(k + ".name", p.name());
    if constexpr (requires { p.element(index_t(0)); }) {
      w.i64(k + ".elements", p.size());
      w.i64(k + ".fingerprint", std::int64_t(part_fingerprint(p)));
    }
  });
  // Constraints and point masses.
  std::vector<unsigned char> kinds(std::size_t(N), 0);
  std::vector<double> pm(static_cast<std::size_t>(N));
  for (index_t i = 0; i < N; ++i) {
    kinds[std::size_t(i)] = static_cast<unsigned char>(nd.kind(i));
    pm[std::size_t(i)] = nd.point_mass(i);
  }
  w.bytes("constraints", kinds);
  w.f64s("point_masses", pm);
  // Integrator and clock.
  auto& cd = const_cast<Assembly&>(a).integrator();  // settings read only
  w.vec<3>("gravity", cd.gravity);
  w.f64("mass_damping", cd.mass_damping);
  w.f64("tssf", cd.tssf);
  w.i64("steps", a.steps());
  w.f64("previous_step", a.previous_step());
  w.i64("track_energy", a.tracking_energy() ? 1 : 0);
  const auto& e = a.energy();
  w.f64s("ledger", std::vector<double>{e.kinetic, e.strain, e.damping, e.external});
  // Node arrays.
  const auto& s = nd.data();
  for (std::size_t f = 0; f < structure::nodes::storage::field_count; ++f)
    w.f64s("node_field" + std::to_string(f), s.data(f), L);
  // Element loads and bodies.
  for_each_part(a, [&](auto I, const auto& p) {
    const std::string k = "part" + std::to_string(decltype(I)::value);
    using P = std::remove_cvref_t<decltype(p)>;
    if constexpr (requires(P& q) { q.pressure(); }) {
      w.f64s(k + ".pressure", const_cast<P&>(p).pressure(), std::size_t(p.size()));
    }
    if constexpr (requires { p.body().state(); }) save_body(w, k + ".body", p.body().state());
  });
  w.end(name);
}

template <class Assembly>
void load_structure(const file& f, const std::string& name, Assembly& a) {
  reader r = f.section(name);
  auto& nd = a.node_set();
  const index_t N = nd.size();
  r.same("the assembly type", r.str("type"), Assembly::name());
  r.same("the node count", r.i64("nodes"), N);
  const std::size_t L = soa_length(N);
  r.same("the node field length (SIMD padding; another SIMD width?)", r.i64("field_length"), std::int64_t(L));
  const double t = r.f64("time");
  for_each_part(a, [&](auto I, const auto& p) {
    const std::string k = "part" + std::to_string(decltype(I)::value);
    r.same(k + " (" + p.name() + ")", r.str(k + ".name"), std::string(p.name()));
    if constexpr (requires { p.element(index_t(0)); }) {
      r.same(k + " (" + p.name() + ") element count", r.i64(k + ".elements"), p.size());
      (void)r.i64(k + ".fingerprint");  // compared after finalize, below
    }
  });
  const auto kinds = r.bytes("constraints");
  const auto pm = r.f64s("point_masses");
  if (index_t(kinds.size()) != N || index_t(pm.size()) != N) r.fail("constraint/point-mass lists do not match ", N, " nodes");
  const Eigen::Vector3d gravity = r.vec<3>("gravity");
  const double damping = r.f64("mass_damping"), tssf = r.f64("tssf");
  const long steps = long(r.i64("steps"));
  const double prev = r.f64("previous_step");
  const bool track = r.i64("track_energy") != 0;
  const auto led = r.f64s("ledger");
  if (led.size() != 4) r.fail("energy ledger has ", led.size(), " values, expected 4");
  std::vector<std::vector<double>> fields(structure::nodes::storage::field_count, std::vector<double>(L));
  for (std::size_t q = 0; q < fields.size(); ++q) r.f64s_into("node_field" + std::to_string(q), fields[q].data(), L);
  // Constraint kinds and point masses as in the file (they may change during a run).
  for (index_t i = 0; i < N; ++i) {
    const auto k = static_cast<structure::constraint>(kinds[std::size_t(i)]);
    if (nd.point_mass(i) != pm[std::size_t(i)]) nd.set_point_mass(i, pm[std::size_t(i)]);
    if (nd.kind(i) == k) continue;
    switch (k) {
      case structure::constraint::free: nd.release(i); break;
      case structure::constraint::pinned: nd.pin(i); break;
      case structure::constraint::prescribed: nd.prescribe_velocity(i, Eigen::Vector3d::Zero()); break;
      case structure::constraint::attached: nd.mark_attached(i); break;
      default: r.fail("node ", i, " has an unknown constraint kind ", int(kinds[std::size_t(i)]));
    }
  }
  if (nd.needs_finalize()) a.finalize();  // masses, scatter maps, reference geometry, attached masses
  // Set-up fingerprints (after finalize: reference data and rest lengths exist).
  {
    reader r2 = f.section(name);
    (void)r2.str("type"); (void)r2.i64("nodes"); (void)r2.i64("field_length"); (void)r2.f64("time");
    for_each_part(a, [&](auto I, const auto& p) {
      const std::string k = "part" + std::to_string(decltype(I)::value);
      (void)r2.str(k + ".name");
      if constexpr (requires { p.element(index_t(0)); }) {
        (void)r2.i64(k + ".elements");
        if (std::uint64_t(r2.i64(k + ".fingerprint")) != part_fingerprint(p))
          r2.fail(k, " (", p.name(), "): connectivity, rest lengths or reference areas differ from the file "
                  "(another scene?)");
      }
    });
  }
  // Element loads and bodies (read before committing the nodes).
  std::vector<std::pair<std::size_t, std::vector<double>>> pressures;
  std::vector<structure::rigid_body_state> bodies;
  for_each_part(a, [&](auto I, auto& p) {
    const std::string k = "part" + std::to_string(decltype(I)::value);
    if constexpr (requires { p.pressure(); }) {
      auto v = r.f64s(k + ".pressure");
      if (index_t(v.size()) != p.size()) r.fail(k, ".pressure has ", v.size(), " values for ", p.size(), " elements");
      pressures.emplace_back(decltype(I)::value, std::move(v));
    }
    if constexpr (requires { p.body().state(); }) bodies.push_back(load_body(r, k + ".body"));
  });
  // Commit.
  auto& s = nd.data();
  for (std::size_t q = 0; q < fields.size(); ++q) std::memcpy(s.data(q), fields[q].data(), L * sizeof(double));
  std::size_t ip = 0, ib = 0;
  for_each_part(a, [&](auto I, auto& p) {
    if constexpr (requires { p.pressure(); }) {
      if (ip < pressures.size() && pressures[ip].first == decltype(I)::value) {
        std::memcpy(p.pressure(), pressures[ip].second.data(), pressures[ip].second.size() * sizeof(double));
        ++ip;
      }
    }
    if constexpr (requires { p.body().set_state(bodies[0]); }) p.body().set_state(bodies[ib++]);
  });
  a.integrator().gravity = gravity;
  a.integrator().mass_damping = damping;
  a.integrator().tssf = tssf;
  a.restore_clock(t, steps, prev, track, structure::energy_ledger{led[0], led[1], led[2], led[3]});
}

}  // namespace ckpt

// ================================================================== public API

/// Write every argument (fluid solvers, assemblies, explicit_steppers) to `path`.
template <class... Parts>
void save_checkpoint(const std::filesystem::path& path, const Parts&... parts) {
  static_assert(sizeof...(Parts) > 0, "io::save_checkpoint: give at least one solver, assembly or stepper");
  ckpt::writer w;
  int nf = 0, ns = 0;
  auto fname = [](int k) { return k == 0 ? std::string("fluid") : "fluid." + std::to_string(k); };
  auto sname = [](int k) { return k == 0 ? std::string("structure") : "structure." + std::to_string(k); };
  auto one = [&](const auto& p) {
    using P = std::remove_cvref_t<decltype(p)>;
    if constexpr (ckpt::coupled_stepper<P>) {
      if constexpr (P::has_fluid) ckpt::save_fluid(w, fname(nf++), p.fluid());
      if constexpr (P::has_structure) ckpt::save_structure(w, sname(ns++), p.structure());
      w.begin("stepper");
      w.f64("time", p.time());
      w.i64("steps", p.steps());
      w.i64("last_substeps", p.last_substeps());
      w.f64("previous_substep", p.previous_substep());
      w.str("coupling", p.coupling().name());
      // Penalty coupling: the accumulated penetration of every coupling point is state
      // the next step reads.
      if constexpr (requires { p.coupling().penetration(index_t(0)); p.coupling().points().size(); }) {
        std::vector<double> d(p.coupling().points().size());
        for (std::size_t c = 0; c < d.size(); ++c) d[c] = p.coupling().penetration(index_t(c));
        w.f64s("penalty.penetration", d);
      }
      w.end("stepper");
    } else if constexpr (ckpt::fluid_solver<P>) {
      ckpt::save_fluid(w, fname(nf++), p);
    } else if constexpr (ckpt::structure_assembly<P>) {
      ckpt::save_structure(w, sname(ns++), p);
    } else {
      static_assert(sizeof(P) == 0, "io::save_checkpoint: argument is not a fluid solver, assembly or stepper");
    }
  };
  (one(parts), ...);
  ckpt::write_file(path, w);
}

/// Restore every argument (fluid solvers, assemblies; built like the run that wrote
/// the file) from `path`. Throws checkpoint_error naming the file, the section and what
/// differs.
template <class... Parts>
void load_checkpoint(const std::filesystem::path& path, Parts&... parts) {
  static_assert(sizeof...(Parts) > 0, "io::load_checkpoint: give at least one solver or assembly");
  const ckpt::file f(path);
  int nf = 0, ns = 0;
  auto fname = [](int k) { return k == 0 ? std::string("fluid") : "fluid." + std::to_string(k); };
  auto sname = [](int k) { return k == 0 ? std::string("structure") : "structure." + std::to_string(k); };
  auto one = [&](auto& p) {
    using P = std::remove_cvref_t<decltype(p)>;
    if constexpr (ckpt::coupled_stepper<P>) {
      if constexpr (P::has_fluid) ckpt::load_fluid(f, fname(nf++), p.fluid());
      if constexpr (P::has_structure) ckpt::load_structure(f, sname(ns++), p.structure());
      auto r = f.section("stepper");
      const double t = r.f64("time");
      const long steps = long(r.i64("steps"));
      const long last_m = long(r.i64("last_substeps"));
      const double prev = r.f64("previous_substep");
      const std::string cname = r.str("coupling");
      if (cname != p.coupling().name())
        throw checkpoint_error(path.string() + ": section 'stepper': coupling '" + cname +
                               "' in the file but '" + p.coupling().name() + "' in this stepper");
      if constexpr (requires { p.coupling().set_penetration(index_t(0), 0.0); p.coupling().points().size(); }) {
        const auto d = r.f64s("penalty.penetration");
        if (d.size() != p.coupling().points().size())
          throw checkpoint_error(path.string() + ": section 'stepper': " + std::to_string(d.size()) +
                                 " penalty coupling points in the file but " +
                                 std::to_string(p.coupling().points().size()) + " in this stepper");
        for (std::size_t c = 0; c < d.size(); ++c) p.coupling().set_penetration(index_t(c), d[c]);
      }
      p.restore_clock(t, steps, prev, last_m);
    } else if constexpr (ckpt::fluid_solver<P>) {
      ckpt::load_fluid(f, fname(nf++), p);
    } else if constexpr (ckpt::structure_assembly<P>) {
      ckpt::load_structure(f, sname(ns++), p);
    } else {
      static_assert(sizeof(P) == 0, "io::load_checkpoint: argument is not a fluid solver or assembly");
    }
  };
  (one(parts), ...);
}

/// What a checkpoint holds, without restoring anything.
struct checkpoint_info {
  std::vector<std::string> sections;
  double time = 0;        ///< the stepper's, else the fluid's, else the structure's time
  long fluid_steps = -1;  ///< fluid::solver::steps() when written (-1: no fluid)
  long steps = -1;        ///< the stepper's steps (-1: no stepper section)
};
inline checkpoint_info read_checkpoint_info(const std::filesystem::path& path) {
  const ckpt::file f(path);
  checkpoint_info info;
  info.sections = f.names();
  if (f.has("structure")) {
    auto r = f.section("structure");
    (void)r.str("type");
    (void)r.i64("nodes");
    (void)r.i64("field_length");
    info.time = r.f64("time");
  }
  if (f.has("fluid")) {
    auto r = f.section("fluid");
    (void)r.str("type");
    (void)r.i64("ghosts");
    for (int d = 0; d < 3; ++d) (void)r.f64s("grid.axis" + std::to_string(d));
    (void)r.i64("total_cells");
    (void)r.i64("field_length");
    (void)r.f64("gas.gamma");
    (void)r.f64("gas.R");
    info.time = r.f64("time");
    info.fluid_steps = long(r.i64("steps"));
  }
  if (f.has("stepper")) {
    auto r = f.section("stepper");
    info.time = r.f64("time");
    info.steps = long(r.i64("steps"));
  }
  return info;
}

}  // namespace parafsi::io
