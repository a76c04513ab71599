/// \file checked_file.hpp
/// A text file written with every step checked: opening, each write, each flush and the
/// close. A failure (a missing or read-only directory, a path that is a directory, a full
/// disk, /dev/full) throws `io::write_error` naming the file and the system's reason, so a
/// program that writes its results through it cannot report success without them.
///
///   io::checked_file f("out/summary.csv");     // created or truncated
///   f.write("a,b\n1,2\n");
///   f.close();                                  // flushes; throws if anything failed
///
/// Writes go through C stdio (a buffered FILE*): a write may only fail at the next flush
/// or at close, which is why `close()` must be called; the destructor closes a file that
/// was not closed (after an exception elsewhere) without reporting.
/// `sync()` asks the system to put the bytes on the disk (POSIX fsync; a no-op where
/// <unistd.h> is missing), and `write_file_atomic` writes `<path>.tmp`, syncs it and renames
/// it over `path`, so a reader (or a restart after a power cut) sees the old file or the
/// new one, never a torn one.
/// io/ is never included by physics headers; this one needs the standard library only
/// (and <unistd.h> where the system has it).
#pragma once
#include <cerrno>
#include <concepts>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>

#include "../core/error.hpp"

#if __has_include(<unistd.h>)
#include <unistd.h>
#define PARAFSI_HAVE_FSYNC 1
#endif

namespace parafsi::io {

/// A file could not be written (open, write, flush or close failed).
struct write_error : error {
  using error::error;
};

class checked_file {
 public:
  /// Open `path` for writing (created, or truncated if it exists).
  explicit checked_file(std::filesystem::path path) : path_(std::move(path)) {
    errno = 0;
    f_ = std::fopen(path_.c_str(), "wb");
    if (!f_) fail("cannot open", errno);
  }
  checked_file(const checked_file&) = delete;
  checked_file& operator=(const checked_file&) = delete;
  ~checked_file() {
    if (f_) std::fclose(f_);
  }

  const std::filesystem::path& path() const noexcept { return path_; }

  void write(std::string_view s) {
    require_open();
    errno = 0;
    if (!s.empty() && std::fwrite(s.data(), 1, s.size(), f_) != s.size()) fail("cannot write", errno);
  }
  /// Hand the buffered text to the system (so a failure shows now, not at close).
  void flush() {
    require_open();
    errno = 0;
    if (std::fflush(f_) != 0) fail("cannot write", errno);
  }
  /// Flush, then ask the system to write the file's data to the disk (fsync) before
  /// returning: used before the rename of an atomic write.
  void sync() {
    flush();
#ifdef PARAFSI_HAVE_FSYNC
    errno = 0;
    if (::fsync(::fileno(f_)) != 0) fail("cannot sync", errno);
#endif
  }
  /// Flush and close; the file is complete only if this returns.
  void close() {
    require_open();
    errno = 0;
    const bool flushed = std::fflush(f_) == 0;
    const int err = errno;
    const bool closed = std::fclose(f_) == 0;
    f_ = nullptr;
    if (!flushed) fail("cannot write", err);
    if (!closed) fail("cannot close", errno);
  }

 private:
  void require_open() const {
    if (!f_) throw write_error("io::checked_file: '" + path_.string() + "' is already closed");
  }
  [[noreturn]] void fail(const char* what, int err) {
    if (f_) {
      std::fclose(f_);
      f_ = nullptr;
    }
    std::string msg = std::string(what) + " '" + path_.string() + "'";
    if (err != 0) msg += std::string(": ") + std::strerror(err);
    throw write_error(msg);
  }

  std::filesystem::path path_;
  std::FILE* f_ = nullptr;
};

/// Write `text` to `path` as one checked file (created or truncated).
inline void write_text_file(const std::filesystem::path& path, std::string_view text) {
  checked_file f(path);
  f.write(text);
  f.close();
}

/// Write a file atomically: `write(f)` fills `<path>.tmp` through the checked file `f`, which
/// is then synced to disk and renamed over `path` (the parent directory is created if
/// missing). A reader, or a restart after a crash or power cut, sees the old file or the new
/// one, never a torn one; any failure throws io::write_error naming the file.
template <class Write>
requires std::invocable<Write&, checked_file&>
void write_file_atomic(const std::filesystem::path& path, Write&& write) {
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::filesystem::path tmp = path;
  tmp += ".tmp";
  {
    checked_file f(tmp);
    write(f);
    f.sync();
    f.close();
  }
  std::filesystem::rename(tmp, path);
}

/// Write `text` to `path` atomically (see above).
inline void write_file_atomic(const std::filesystem::path& path, std::string_view text) {
  write_file_atomic(path, [text](checked_file& f) { f.write(text); });
}

}  // namespace parafsi::io
