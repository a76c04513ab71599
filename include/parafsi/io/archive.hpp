/// \file archive.hpp
/// The checkpoint file format and the two archives that write and read it, in one
/// place. A stateful component describes itself once, in a static member template
///
///   template <class Archive, class Self>
///   static void serialize(Archive& ar, Self& self) {   // Self = T (load) or const T (save)
///     ar.check("cells", self.n_, "the cell count");    // signature: written, or compared
///     ar("time", self.t_);                             // state: written, or read back
///     ar.fields("conserved", self.U_);                 // every SoA field under its tag name
///     ar("frame", self.frame_);                        // a nested component: "frame.<entry>"
///   }
///
/// and the same code writes (output_archive, Self const) and reads (input_archive,
/// Self mutable), so saving, loading and io::read_checkpoint_info cannot drift apart.
/// (Self stands in for C++23's explicit object parameter: one body serves a const
/// object on save and a mutable one on load, without casts.) Physics headers do not
/// include this file: their serialize is written against the archive interface below.
///
/// Archive interface (both archives; `Archive::saving` / `Archive::loading` tell them apart):
///   ar(name, value)        a value: bool, integers and enums (i64), double, std::string,
///                          fixed-size Eigen matrices/vectors and quaternions, vectors of
///                          doubles or of integers/enums (the length must match on load),
///                          or a nested component with a static serialize (its entries
///                          are named "<name>.<entry>"); an empty class without serialize
///                          (a stateless policy) writes nothing.
///   ar.array(name, p, n)   n doubles at p (the count must match on load).
///   ar.fields(group, soa)  every field of an soa<Tags...> as "<group>.<Tag::name>", all
///                          cells including SIMD padding (the file then belongs to one
///                          SIMD width, which the length check names).
///   ar.check(name, here, what)          signature: the file's value must equal `here`,
///                          else "<what> is <file> in the file but <here> here".
///   ar.check(name, here, describe)      the same with a message describe(file, here)
///                          (empty = equal), for a better sentence than the default.
///   ar.check_digest(name, what, feed)   FNV-1a digest of what feed(put) puts (doubles,
///                          integers): set-up data too large to store (connectivity,
///                          rest lengths) compared on load, "<what> differ(s) from the file".
///   ar.fail(...)           (input only) refuse the file with a message naming the entry.
///
/// Loading reads the entries in the order the serialize code asks for them; a name or
/// kind that differs is refused naming both ("expected entry 'conserved.rho' but found
/// 'conserved.dens'"); every double read must be finite; a section that holds entries
/// nobody read is refused as well.
///
/// File format (version 2, native byte order recorded and checked):
///   "PARAFSI-CHECKPOINT\n" (19 bytes), u32 version, u32 0x01020304 (byte order),
///   u64 payload length, payload, u64 FNV-1a-64 checksum of the payload.
///   The payload is a sequence of sections, each a sequence of named entries: u8 kind,
///   u16 name length, name, then kind 'S' (section begin) / 'E' (section end) /
///   'i' (i64) / 'd' (f64) / 's' (u64 length + bytes) / 'D' (u64 count + f64 values) /
///   'I' (u64 count + i64 values) / 'B' (u64 count + bytes).
/// Version 1 had the same container but entries by position ("U0", "node_field3"); it is
/// refused with a message naming both versions (a run restarts from a checkpoint of its
/// own build). The whole file (header, length, checksum, section structure) is verified
/// before any object is changed. Writing goes to `<path>.tmp`, then a rename, so a crash
/// during a write leaves the previous checkpoint intact.
#pragma once
#include <cmath>
#include <concepts>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "../core/error.hpp"
#include "../core/simd.hpp"
#include "../core/soa.hpp"
#include "checked_file.hpp"

namespace parafsi::io {

/// A checkpoint that cannot be read into the given objects (message says why).
struct checkpoint_error : invalid_input {
  using invalid_input::invalid_input;
};

inline constexpr std::string_view checkpoint_magic = "PARAFSI-CHECKPOINT\n";
inline constexpr std::uint32_t checkpoint_version = 2;

namespace ckpt {

/// A structure-of-arrays container (soa, paged_soa): fields by tag, a length.
template <class S>
concept soa_like = requires(const S& s) {
  S::field_count;
  { s.size() } -> std::convertible_to<index_t>;
  { s.data(std::size_t(0)) } -> std::convertible_to<const double*>;
};

/// Allocated length of a soa field of n entries (soa::resize: padded + one pack).
inline std::size_t soa_length(index_t n) { return simd::padded(std::size_t(n)) + simd::width; }

/// FNV-1a-64, incremental.
struct fnv1a_hash {
  std::uint64_t h = 14695981039346656037ull;
  void add(const void* p, std::size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) {
      h ^= c[i];
      h *= 1099511628211ull;
    }
  }
};
inline std::uint64_t fnv1a(const unsigned char* p, std::size_t n) {
  fnv1a_hash h;
  h.add(p, n);
  return h.h;
}

/// Feeds check_digest: doubles and integers, by value.
struct digest_feed {
  fnv1a_hash& hash;
  void operator()(double v) const { hash.add(&v, sizeof v); }
  template <class I>
  requires std::is_integral_v<I>
  void operator()(I v) const {
    const auto w = static_cast<std::int64_t>(v);
    hash.add(&w, sizeof w);
  }
};

template <class T>
concept eigen_fixed = requires {
  typename T::Scalar;
  T::RowsAtCompileTime;
  T::ColsAtCompileTime;
}
&&std::is_same_v<typename T::Scalar, double> && (T::RowsAtCompileTime > 0) && (T::ColsAtCompileTime > 0);
template <class T>
concept quaternion = std::is_same_v<T, Eigen::Quaterniond>;
template <class T>
concept integer_like = (std::is_integral_v<T> || std::is_enum_v<T>)&&!std::is_same_v<T, bool>;
template <class T>
struct is_vector : std::false_type {};
template <class T, class A>
struct is_vector<std::vector<T, A>> : std::true_type {};
template <class T>
concept real_vector = is_vector<T>::value && std::is_same_v<typename T::value_type, double>;
template <class T>
concept integer_vector = is_vector<T>::value && integer_like<typename T::value_type>;

template <class T>
std::int64_t to_i64(T v) {
  if constexpr (std::is_enum_v<T>) return static_cast<std::int64_t>(static_cast<std::underlying_type_t<T>>(v));
  else return static_cast<std::int64_t>(v);
}
template <class T>
T from_i64(std::int64_t v) {
  if constexpr (std::is_enum_v<T>) return static_cast<T>(static_cast<std::underlying_type_t<T>>(v));
  else return static_cast<T>(v);
}

/// Printable form of a signature value for messages.
inline std::string show(const std::string& s) { return "'" + s + "'"; }
template <class T>
std::string show(const T& v) {
  if constexpr (std::is_same_v<T, bool>) return v ? "true" : "false";
  else if constexpr (integer_like<T>) return std::to_string(to_i64(v));
  else return parafsi::detail::concat(v);
}
template <class T>
bool same_value(const T& a, const T& b) {
  if constexpr (std::is_same_v<T, double>) return std::memcmp(&a, &b, sizeof(double)) == 0;  // bitwise
  else if constexpr (real_vector<T>)
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
  else return a == b;
}

}  // namespace ckpt

// ================================================================== output

/// Serialises named entries into a byte buffer (see the file comment).
class output_archive {
 public:
  static constexpr bool saving = true;
  static constexpr bool loading = false;

  void begin_section(std::string_view section) { head('S', section); }
  void end_section(std::string_view section) { head('E', section); }

  template <class T>
  void operator()(std::string_view name, const T& v) {
    using U = std::remove_cvref_t<T>;
    if constexpr (std::is_same_v<U, double>) {
      head('d', full(name));
      raw(&v, sizeof v);
    } else if constexpr (std::is_same_v<U, bool> || ckpt::integer_like<U>) {
      head('i', full(name));
      const std::int64_t w = ckpt::to_i64(v);
      raw(&w, sizeof w);
    } else if constexpr (std::is_same_v<U, std::string>) {
      head('s', full(name));
      count(v.size());
      raw(v.data(), v.size());
    } else if constexpr (ckpt::eigen_fixed<U>) {
      array(name, v.data(), std::size_t(v.size()));
    } else if constexpr (ckpt::quaternion<U>) {
      array(name, v.coeffs().data(), 4);
    } else if constexpr (ckpt::real_vector<U>) {
      array(name, v.data(), v.size());
    } else if constexpr (ckpt::integer_vector<U>) {
      head('I', full(name));
      count(v.size());
      for (const auto& x : v) {
        const std::int64_t w = ckpt::to_i64(x);
        raw(&w, sizeof w);
      }
    } else if constexpr (requires(output_archive & a, const U& u) { U::serialize(a, u); }) {
      const std::size_t keep = prefix_.size();
      prefix_.append(name).push_back('.');
      U::serialize(*this, v);
      prefix_.resize(keep);
    } else {
      static_assert(std::is_empty_v<U>,
                    "io::output_archive: this type holds state but has no "
                    "`template <class Archive, class Self> static void serialize(Archive&, Self&)`");
    }
  }
  void operator()(std::string_view name, const char* v) { (*this)(name, std::string(v)); }

  void array(std::string_view name, const double* p, std::size_t n) {
    head('D', full(name));
    count(n);
    raw(p, n * sizeof(double));
  }
  template <template <class...> class Soa, class... Tags>
  requires ckpt::soa_like<Soa<Tags...>>
  void fields(std::string_view group, const Soa<Tags...>& s) {
    const std::size_t L = ckpt::soa_length(s.size());
    (array(std::string(group) + "." + Tags::name, s.template get<Tags>(), L), ...);
  }

  template <class T, class Describe>
  void check(std::string_view name, const T& here, Describe&&) {
    (*this)(name, here);
  }
  template <class F>
  void check_digest(std::string_view name, std::string_view, F&& feed) {
    ckpt::fnv1a_hash h;
    feed(ckpt::digest_feed{h});
    (*this)(name, static_cast<std::int64_t>(h.h));
  }

  const std::vector<unsigned char>& bytes() const noexcept { return buf_; }

 private:
  std::string full(std::string_view name) const { return prefix_ + std::string(name); }
  void raw(const void* p, std::size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    buf_.insert(buf_.end(), c, c + n);
  }
  void count(std::uint64_t n) { raw(&n, sizeof n); }
  void head(char kind, std::string_view name) {
    require(name.size() < 65536, "io::output_archive: entry name longer than 65535 bytes");
    buf_.push_back(static_cast<unsigned char>(kind));
    const auto len = static_cast<std::uint16_t>(name.size());
    raw(&len, sizeof len);
    raw(name.data(), name.size());
  }
  std::vector<unsigned char> buf_;
  std::string prefix_;
};

// ================================================================== input

/// Reads the entries of one section in order into the objects (see the file comment);
/// every mismatch is a checkpoint_error naming the file, the section and the entry.
class input_archive {
 public:
  static constexpr bool saving = false;
  static constexpr bool loading = true;

  input_archive(const std::vector<unsigned char>& b, std::size_t begin, std::size_t end, std::string where)
      : b_(b), begin_(begin), p_(begin), end_(end), where_(std::move(where)) {}

  template <class T>
  void operator()(std::string_view name, T& v) {
    static_assert(!std::is_const_v<T>, "io::input_archive: cannot read into a const object");
    if constexpr (std::is_same_v<T, double>) {
      expect('d', name);
      take(&v, sizeof v);
      finite(name, &v, 1);
    } else if constexpr (std::is_same_v<T, bool> || ckpt::integer_like<T>) {
      expect('i', name);
      std::int64_t w;
      take(&w, sizeof w);
      if constexpr (std::is_same_v<T, bool>) {
        if (w != 0 && w != 1) fail("entry '", full(name), "' holds ", w, " where a flag (0 or 1) is expected");
        v = (w != 0);
      } else {
        v = ckpt::from_i64<T>(w);
      }
    } else if constexpr (std::is_same_v<T, std::string>) {
      expect('s', name);
      v.assign(count(1), '\0');
      take(v.data(), v.size());
    } else if constexpr (ckpt::eigen_fixed<T>) {
      array(name, v.data(), std::size_t(v.size()));
    } else if constexpr (ckpt::quaternion<T>) {
      array(name, v.coeffs().data(), 4);
    } else if constexpr (ckpt::real_vector<T>) {
      array(name, v.data(), v.size());
    } else if constexpr (ckpt::integer_vector<T>) {
      expect('I', name);
      const std::size_t n = count(sizeof(std::int64_t));
      if (n != v.size()) fail("entry '", full(name), "' has ", n, " values in the file but ", v.size(), " here");
      for (auto& x : v) {
        std::int64_t w;
        take(&w, sizeof w);
        x = ckpt::from_i64<typename T::value_type>(w);
      }
    } else if constexpr (requires(input_archive & a, T & u) { T::serialize(a, u); }) {
      const std::size_t keep = prefix_.size();
      prefix_.append(name).push_back('.');
      T::serialize(*this, v);
      prefix_.resize(keep);
    } else {
      static_assert(std::is_empty_v<T>,
                    "io::input_archive: this type holds state but has no "
                    "`template <class Archive, class Self> static void serialize(Archive&, Self&)`");
    }
  }

  void array(std::string_view name, double* p, std::size_t n) {
    expect('D', name);
    const std::size_t m = count(sizeof(double));
    if (m != n) fail("entry '", full(name), "' has ", m, " values in the file but ", n, " here");
    take(p, n * sizeof(double));
    finite(name, p, n);
  }
  template <template <class...> class Soa, class... Tags>
  requires ckpt::soa_like<Soa<Tags...>>
  void fields(std::string_view group, Soa<Tags...>& s) {
    const std::size_t L = ckpt::soa_length(s.size());
    (array(std::string(group) + "." + Tags::name, s.template get<Tags>(), L), ...);
  }

  /// Signature: the file's value must equal `here`; `describe(file, here)` returns the
  /// message for a difference, or a string naming what it is ("the node count").
  template <class T, class Describe>
  void check(std::string_view name, const T& here, Describe&& describe) {
    using U = std::remove_cvref_t<T>;
    U file = read_any<U>(name);
    if constexpr (std::is_invocable_r_v<std::string, Describe, const U&, const U&>) {
      const std::string why = describe(file, here);
      if (!why.empty()) fail(why);
    } else if constexpr (ckpt::is_vector<U>::value) {
      if (!ckpt::same_value(file, static_cast<const U&>(here)))
        fail(describe, " differs (", file.size(), " values in the file, ", here.size(), " here)");
    } else {
      if (!ckpt::same_value(file, static_cast<const U&>(here)))
        fail(describe, " is ", ckpt::show(file), " in the file but ", ckpt::show(static_cast<const U&>(here)), " here");
    }
  }
  template <class F>
  void check_digest(std::string_view name, std::string_view what, F&& feed) {
    ckpt::fnv1a_hash h;
    feed(ckpt::digest_feed{h});
    std::int64_t file;
    (*this)(name, file);
    if (file != static_cast<std::int64_t>(h.h)) fail(what, " differ from the file (another scene?)");
  }

  /// Every entry read: anything left was written by code this build does not have.
  void finish() const {
    if (p_ < end_) fail("holds entries this build does not read, from '", peek_name(), "' on");
  }

  /// The value of a scalar entry by name, anywhere in the section (for
  /// read_checkpoint_info); nullopt if the section has no such entry.
  std::optional<double> find_real(std::string_view name) const { return find<double>('d', name); }
  std::optional<std::int64_t> find_int(std::string_view name) const { return find<std::int64_t>('i', name); }

  template <class... A>
  [[noreturn]] void fail(A&&... a) const {
    throw checkpoint_error(parafsi::detail::concat(where_, ": ", std::forward<A>(a)...));
  }

 private:
  std::string full(std::string_view name) const { return prefix_ + std::string(name); }
  template <class U>
  U read_any(std::string_view name) {
    if constexpr (std::is_same_v<U, double> || std::is_same_v<U, bool> || ckpt::integer_like<U> ||
                  std::is_same_v<U, std::string>) {
      U v{};
      (*this)(name, v);
      return v;
    } else if constexpr (ckpt::real_vector<U>) {
      expect('D', name);
      U v(count(sizeof(double)));
      take(v.data(), v.size() * sizeof(double));
      return v;
    } else {
      static_assert(sizeof(U) == 0, "io::input_archive::check: signatures are scalars, strings or vectors of doubles");
    }
  }
  void finite(std::string_view name, const double* p, std::size_t n) const {
    for (std::size_t i = 0; i < n; ++i)
      if (!std::isfinite(p[i]))
        fail("entry '", full(name), "' holds a non-finite value (", p[i],
             n > 1 ? parafsi::detail::concat(" at index ", i) : "", ")");
  }
  std::size_t count(std::size_t elem) {
    std::uint64_t n;
    take(&n, sizeof n);
    if (elem > 0 && n > (end_ - p_) / elem) fail("an entry claims ", n, " items, more than the section holds");
    return std::size_t(n);
  }
  void take(void* dst, std::size_t n) {
    if (n > end_ - p_) fail("section ends inside an entry");
    if (n > 0) std::memcpy(dst, b_.data() + p_, n);
    p_ += n;
  }
  std::string peek_name() const {
    std::uint16_t len;
    std::memcpy(&len, b_.data() + p_ + 1, sizeof len);
    return std::string(reinterpret_cast<const char*>(b_.data() + p_ + 3), len);
  }
  void expect(char kind, std::string_view name) {
    const std::string want = full(name);
    if (p_ + 3 > end_) fail("expected entry '", want, "' but the section ends");
    const char k = char(b_[p_]);
    std::uint16_t len;
    std::memcpy(&len, b_.data() + p_ + 1, sizeof len);
    if (p_ + 3 + len > end_) fail("entry name runs past the section");
    const std::string got = peek_name();
    if (got != want)
      fail("expected entry '", want, "' but found '", got, "' (written by another version or another scene)");
    if (k != kind) fail("entry '", want, "' is of kind '", k, "' in the file, expected '", kind, "'");
    p_ += 3 + std::size_t(len);
  }
  /// Linear scan over the (verified) section.
  template <class T>
  std::optional<T> find(char kind, std::string_view name) const {
    std::size_t p = begin_;
    while (p + 3 <= end_) {
      const char k = char(b_[p]);
      std::uint16_t len;
      std::memcpy(&len, b_.data() + p + 1, sizeof len);
      const std::string_view got(reinterpret_cast<const char*>(b_.data() + p + 3), len);
      p += 3 + std::size_t(len);
      if (k == kind && got == name) {
        T v;
        std::memcpy(&v, b_.data() + p, sizeof v);
        return v;
      }
      std::uint64_t cnt = 0;
      switch (k) {
        case 'i':
        case 'd': p += 8; break;
        case 's':
        case 'B':
          std::memcpy(&cnt, b_.data() + p, 8);
          p += 8 + std::size_t(cnt);
          break;
        case 'D':
        case 'I':
          std::memcpy(&cnt, b_.data() + p, 8);
          p += 8 + 8 * std::size_t(cnt);
          break;
        default: return std::nullopt;
      }
    }
    return std::nullopt;
  }
  const std::vector<unsigned char>& b_;
  std::size_t begin_, p_, end_;
  std::string where_;
  std::string prefix_;
};

// ================================================================== file

/// A whole checkpoint file, verified (magic, version, byte order, length, checksum,
/// section structure) and split into sections.
class checkpoint_file {
 public:
  explicit checkpoint_file(const std::filesystem::path& path) : path_(path.string()) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw checkpoint_error(parafsi::detail::concat("checkpoint ", path_, ": cannot open the file"));
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
    if (version == 1)
      fail("checkpoint format version 1 (entries by position); this build reads version ", checkpoint_version,
           " (entries by name): rerun from the start with this build, or finish the run with the build that "
           "wrote the file");
    if (version != checkpoint_version)
      fail("checkpoint format version ", version, "; this build reads version ", checkpoint_version);
    const std::size_t head = m + 16;
    if (all.size() < head + 8 || len > all.size() - head - 8)
      fail("truncated: ", all.size(), " bytes, the header announces ", head + len + 8);
    if (all.size() != head + len + 8) fail("has ", all.size() - head - len - 8, " unexpected bytes after its end");
    std::uint64_t sum;
    std::memcpy(&sum, all.data() + head + len, 8);
    if (sum != ckpt::fnv1a(all.data() + head, std::size_t(len))) fail("corrupted: checksum mismatch");
    data_.assign(all.begin() + std::ptrdiff_t(head), all.begin() + std::ptrdiff_t(head + len));
    index_sections();
  }

  bool has(const std::string& section) const { return sections_.count(section) > 0; }
  /// Section names in file order.
  const std::vector<std::string>& names() const noexcept { return order_; }
  input_archive section(const std::string& name) const {
    const auto it = sections_.find(name);
    if (it == sections_.end()) {
      std::string have;
      for (const auto& n : order_) have += (have.empty() ? "" : ", ") + n;
      fail("has no section '", name, "' (it holds: ", have.empty() ? "nothing" : have, ")");
    }
    return input_archive(data_, it->second.first, it->second.second,
                         "checkpoint " + path_ + ", section '" + name + "'");
  }
  const std::string& path() const noexcept { return path_; }

  template <class... A>
  [[noreturn]] void fail(A&&... a) const {
    throw checkpoint_error(parafsi::detail::concat("checkpoint ", path_, ": ", std::forward<A>(a)...));
  }

 private:
  /// Walk the entries once: every section's [begin, end) and well-formedness.
  void index_sections() {
    std::size_t p = 0, open_at = 0;
    const std::size_t n = data_.size();
    std::string open;
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
      if (open.empty() && kind != 'S') fail("entry '", name, "' outside a section");
      std::uint64_t cnt = 0;
      switch (kind) {
        case 'S':
          if (!open.empty()) fail("section '", name, "' opens inside section '", open, "'");
          if (sections_.count(name)) fail("section '", name, "' appears twice");
          open = name;
          open_at = p;
          break;
        case 'E':
          if (open != name) fail("section end '", name, "' does not match '", open, "'");
          sections_[name] = {open_at, p - 3 - std::size_t(len)};
          order_.push_back(name);
          open.clear();
          break;
        case 'i':
        case 'd':
          need(8);
          p += 8;
          break;
        case 's':
        case 'B':
          need(8);
          std::memcpy(&cnt, data_.data() + p, 8);
          p += 8;
          if (cnt > n - p) fail("malformed entry '", name, "'");
          p += std::size_t(cnt);
          break;
        case 'D':
        case 'I':
          need(8);
          std::memcpy(&cnt, data_.data() + p, 8);
          p += 8;
          if (cnt > (n - p) / 8) fail("malformed entry '", name, "'");
          p += std::size_t(cnt) * 8;
          break;
        default: fail("unknown entry kind ", int(kind), " at byte ", p);
      }
    }
    if (!open.empty()) fail("section '", open, "' is not closed");
  }
  std::string path_;
  std::vector<unsigned char> data_;
  std::map<std::string, std::pair<std::size_t, std::size_t>> sections_;
  std::vector<std::string> order_;
};

/// Write the archive's payload to `path` atomically: `<path>.tmp`, synced to disk, then a
/// rename (io::write_file_atomic); a failed open, write, sync or close names the file.
inline void write_checkpoint_file(const std::filesystem::path& path, const output_archive& ar) {
  const auto& buf = ar.bytes();
  const std::uint32_t version = checkpoint_version, order = 0x01020304u;
  const std::uint64_t len = buf.size(), sum = ckpt::fnv1a(buf.data(), buf.size());
  write_file_atomic(path, [&](checked_file& f) {
    const auto put = [&f](const void* p, std::size_t n) { f.write({static_cast<const char*>(p), n}); };
    put(checkpoint_magic.data(), checkpoint_magic.size());
    put(&version, 4);
    put(&order, 4);
    put(&len, 8);
    put(buf.data(), buf.size());
    put(&sum, 8);
  });
}

}  // namespace parafsi::io
