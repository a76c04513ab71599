/// \file csv.hpp
/// A tiny CSV time-history writer for the user's loop (DESIGN §1).
///
///   io::csv_writer h("out/history.csv", {"t", "x", "speed"});
///   h.row({t, x, speed});                // one row of doubles per call
///
/// Format: the header line once (the column names joined by ','), then one line per
/// row, values printed with `precision` significant digits (17 by default: doubles
/// round-trip exactly), '.' as decimal point whatever the locale, "nan"/"inf" for
/// non-finite values. A row with the wrong number of values is an error naming both
/// counts. Flush policy: every row (default), every n rows, or at most every
/// `interval` wall seconds; the destructor, `flush()` and `close()` always flush, and every
/// write, flush and `close()` is checked (a full disk throws naming the file).
/// Restart: `csv_options::resume_after = t` opens an existing file with the same header,
/// keeps the rows whose first column is <= t (the rows up to the checkpoint) and
/// appends after them; a header that differs is an error naming both.
/// io/ is never included by physics headers; this one needs the standard library only.
#pragma once
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "../core/error.hpp"

namespace parafsi::io {

enum class flush_policy { every_row, every_n_rows, interval, on_close };

struct csv_options {
  int precision = 17;  ///< significant digits
  flush_policy flush = flush_policy::every_row;
  long flush_rows = 100;        ///< for every_n_rows
  double flush_interval = 1.0;  ///< wall seconds, for interval
  /// Resume an existing file: keep rows with first column <= this value and append.
  /// NaN (default): truncate and start a new file.
  double resume_after = std::numeric_limits<double>::quiet_NaN();
};

namespace detail {
/// Locale-independent shortest-enough formatting of a double.
inline void append_number(std::string& s, double v, int precision) {
  if (std::isnan(v)) {
    s += "nan";
    return;
  }
  if (std::isinf(v)) {
    s += v > 0 ? "inf" : "-inf";
    return;
  }
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", precision, v);
  for (char* p = buf; *p; ++p)
    if (*p == ',') *p = '.';  // a locale with a decimal comma must not split the column
  s += buf;
}
inline std::string join_header(const std::vector<std::string>& cols) {
  std::string h;
  for (std::size_t i = 0; i < cols.size(); ++i) h += (i ? "," : "") + cols[i];
  return h;
}
}  // namespace detail

class csv_writer {
 public:
  csv_writer(const std::filesystem::path& path, std::vector<std::string> columns, csv_options opt = {})
      : path_(path), cols_(std::move(columns)), opt_(opt) {
    require(!cols_.empty(), "io::csv_writer: no columns for ", path_.string());
    for (const auto& c : cols_)
      require(!c.empty() && c.find_first_of(",\n\r\"") == std::string::npos, "io::csv_writer: column name '", c,
              "' is empty or contains ',', a quote or a line break");
    require(opt_.precision >= 1 && opt_.precision <= 17, "io::csv_writer: precision must be in [1, 17], got ",
            opt_.precision);
    require(opt_.flush != flush_policy::every_n_rows || opt_.flush_rows >= 1,
            "io::csv_writer: flush_rows must be >= 1, got ", opt_.flush_rows);
    if (path_.has_parent_path()) std::filesystem::create_directories(path_.parent_path());
    const std::string header = detail::join_header(cols_);
    std::string kept;
    if (!std::isnan(opt_.resume_after) && std::filesystem::exists(path_)) {
      std::ifstream in(path_);
      std::string line;
      std::getline(in, line);
      if (!line.empty() && line.back() == '\r') line.pop_back();
      require(line == header, "io::csv_writer: cannot resume ", path_.string(), ": its header is '", line,
              "', this writer's is '", header, "'");
      while (std::getline(in, line)) {
        if (line.empty()) continue;
        const double first = std::strtod(line.c_str(), nullptr);
        if (first <= opt_.resume_after) kept += line + '\n';
      }
    }
    out_.open(path_, std::ios::out | std::ios::trunc);
    require(out_.good(), "io::csv_writer: cannot open ", path_.string(), " for writing");
    out_ << header << '\n' << kept;
    out_.flush();
    last_flush_ = now();
  }
  csv_writer(const csv_writer&) = delete;
  csv_writer& operator=(const csv_writer&) = delete;
  ~csv_writer() {
    if (out_.is_open()) out_.flush();
  }

  std::size_t columns() const noexcept { return cols_.size(); }
  long rows() const noexcept { return rows_; }
  const std::filesystem::path& path() const noexcept { return path_; }

  void row(std::span<const double> values) {
    require(values.size() == cols_.size(), "io::csv_writer: row ", rows_, " of ", path_.string(), " has ",
            values.size(), " values for ", cols_.size(), " columns");
    line_.clear();
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (i) line_ += ',';
      detail::append_number(line_, values[i], opt_.precision);
    }
    line_ += '\n';
    out_ << line_;
    require(out_.good(), "io::csv_writer: write to ", path_.string(), " failed (disk full?)");
    ++rows_;
    switch (opt_.flush) {
      case flush_policy::every_row: out_.flush(); break;
      case flush_policy::every_n_rows:
        if (rows_ % opt_.flush_rows == 0) out_.flush();
        break;
      case flush_policy::interval:
        if (now() - last_flush_ >= opt_.flush_interval) {
          out_.flush();
          last_flush_ = now();
        }
        break;
      case flush_policy::on_close: break;
    }
    require(out_.good(), "io::csv_writer: write to ", path_.string(), " failed (disk full?)");
  }
  void row(std::initializer_list<double> values) { row(std::span<const double>(values.begin(), values.size())); }
  void flush() {
    out_.flush();
    require(out_.good(), "io::csv_writer: write to ", path_.string(), " failed (disk full?)");
    last_flush_ = now();
  }
  /// Flush and close, checked: the file is complete only if this returns (the destructor
  /// flushes without reporting).
  void close() {
    flush();
    out_.close();
    require(!out_.fail(), "io::csv_writer: closing ", path_.string(), " failed");
  }

 private:
  static double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  }
  std::filesystem::path path_;
  std::vector<std::string> cols_;
  csv_options opt_;
  std::ofstream out_;
  std::string line_;
  long rows_ = 0;
  double last_flush_ = 0;
};

}  // namespace parafsi::io
