/// \file drop_history.hpp
/// The parachute drop's history as files: the observer that computes one
/// `drop_history_row` from the drop assembly (definitions of the columns:
/// io/drop_summary.hpp), `history.csv` and `summary.csv` written through checked files
/// (io/checked_file.hpp: a failed open, write, flush or close throws `write_error` naming
/// the file and the system's reason), and the history read back on a restart.
///
///   io::drop_observer observe(scene);                          // model::drop_scene
///   io::drop_history_writer hist(dir / "history.csv");         // header written
///   io::drop_history_filter filt(io::gaussian_lowpass(10.0, 0.005));  // open_force_filtered
///   rows.push_back(observe(s.time(), s.structure()));
///   for (const auto& r : filt.complete(rows)) hist.append(r);  // the rows whose window is complete
///   hist.flush();
///   for (const auto& r : filt.finish(rows)) hist.append(r);    // at the end: the last H rows
///   hist.close();
///   io::write_drop_summary(dir / "summary.csv", io::summarize(rows, fabric, options));
///   auto kept = io::read_drop_history(dir / "history.csv", t_restart);  // rows with t <= t_restart
///
/// Observer: payload mass centre and velocity from the payload body; canopy diameter from
/// the skirt nodes and the canopy axis, confluence → vent centre (the vent-centre node, or
/// the mean of the vent nodes for a canopy without one); open force = tension of the
/// riser's last segment (the one at the payload), clipped at 0; payload and canopy axis
/// angles; flight-path angle (the scene's at rest); C_D with the total weight
/// `scene.total_mass() · g` and S0 = π D0²/4. A non-finite structure node is a
/// `numerical_failure` naming the node and the time.
///
/// Writing: a row goes to the file once its open_force_filtered is known, H rows (the
/// filter's half-window, 11 rows = 55 ms at the defaults) after its own time; the last H
/// rows at the end of the run. A run killed by a signal leaves history.csv without its
/// last H rows (a run stopped by an error writes them, with the end-of-run edge rule).
///
/// Reading (restart): the header must be `drop_history_header`; the 16-column header of
/// the earlier format (`drop_history_header_16`, without open_force_filtered) is refused
/// naming both; every complete line must hold 17 numbers (`nan` allowed); a bad number is an error naming the file, the
/// line, the column and the text. A last line without its line break (a run killed while writing it) is ignored; a
/// missing file gives no rows. io/ is never included by physics headers.
#pragma once
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "../model/drop_scene.hpp"
#include "../structure/from_drop_scene.hpp"
#include "checked_file.hpp"
#include "drop_summary.hpp"

namespace parafsi::io {

/// Computes the history row of a drop assembly built from `scene` (rules in the file comment).
class drop_observer {
 public:
  explicit drop_observer(const model::drop_scene& scene)
      : skirt_(scene.canopy.skirt),
        vent_(scene.canopy.vent),
        vent_centre_(scene.canopy.vent_centre),
        confluence_(scene.suspension.confluence),
        riser_last_(index_t(scene.cable(model::cable_kind::riser).segments.size()) - 1),
        weight_(scene.total_mass() * scene.params.gravity),
        air_density_(scene.params.air_density),
        nominal_area_(scene.params.nominal_area()),
        release_flight_path_(scene.params.flight_path_angle),
        skirt_x_(scene.canopy.skirt.size()) {
    require(!skirt_.empty(), "io::drop_observer: the canopy has no skirt nodes");
    require(vent_centre_ >= 0 || !vent_.empty(), "io::drop_observer: the canopy has no vent nodes");
  }

  /// The vent centre: the vent-centre node, or the mean of the vent nodes.
  Eigen::Vector3d vent_point(const structure::nodes& nd) const {
    if (vent_centre_ >= 0) return nd.position(vent_centre_);
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (index_t i : vent_) c += nd.position(i);
    return c / double(vent_.size());
  }

  /// The row at time t of the assembly `a`.
  drop_history_row operator()(double t, const structure::drop_assembly& a) {
    const auto& nd = a.node_set();
    const auto& body = structure::payload(a).body();
    drop_history_row r;
    r.t = t;
    const Eigen::Vector3d x = body.mass_centre(), v = body.mass_centre_velocity();
    r.x = x.x();
    r.y = x.y();
    r.z = x.z();
    r.vx = v.x();
    r.vy = v.y();
    r.vz = v.z();
    r.speed = v.norm();
    for (std::size_t k = 0; k < skirt_x_.size(); ++k) skirt_x_[k] = nd.position(skirt_[k]);
    const Eigen::Vector3d conf = nd.position(confluence_), vent = vent_point(nd);
    r.canopy_diameter = canopy_diameter(skirt_x_, conf, vent);
    r.open_force = std::max(0.0, structure::riser(a).tension(nd, riser_last_));
    const auto pa = axis_angles(body.rotation() * Eigen::Vector3d::UnitZ());
    const auto ca = axis_angles((vent - conf).normalized());
    r.payload_phi_x = pa[0];
    r.payload_phi_y = pa[1];
    r.canopy_phi_x = ca[0];
    r.canopy_phi_y = ca[1];
    r.flight_path_angle = flight_path_angle(v, release_flight_path_);
    r.drag_coefficient = drag_coefficient(weight_, air_density_, r.speed, nominal_area_);
    for (index_t i = 0; i < nd.size(); ++i)
      if (!nd.position(i).allFinite())
        throw numerical_failure(parafsi::detail::concat("parachute_drop: structure node ", i,
                                                        " has a non-finite position at t = ", t, " s"),
                                long(i), t);
    return r;
  }

 private:
  std::vector<index_t> skirt_, vent_;
  index_t vent_centre_, confluence_, riser_last_;
  double weight_, air_density_, nominal_area_, release_flight_path_;
  std::vector<Eigen::Vector3d> skirt_x_;
};

/// history.csv: the header on opening, then one row per `write`, each flushed so that a
/// failure shows at once and the file holds every row written when a run is killed.
class drop_history_writer {
 public:
  explicit drop_history_writer(const std::filesystem::path& path) : f_(path) {
    line_ = drop_history_header;
    line_ += '\n';
    f_.write(line_);
  }
  const std::filesystem::path& path() const noexcept { return f_.path(); }
  /// One row, not flushed (for rows carried over on a restart).
  void append(const drop_history_row& r) {
    line_.clear();
    append_history_row(line_, r);
    f_.write(line_);
  }
  /// One row, flushed.
  void write(const drop_history_row& r) {
    append(r);
    f_.flush();
  }
  void flush() { f_.flush(); }
  void close() { f_.close(); }

 private:
  checked_file f_;
  std::string line_;
};

/// summary.csv: `drop_summary_header` and the summary's row, checked.
inline void write_drop_summary(const std::filesystem::path& path, const drop_summary& s) {
  write_text_file(path, std::string(drop_summary_header) + '\n' + s.csv_row() + '\n');
}

/// The rows of history text `text` (history.csv's format; `source` names it in messages)
/// with t <= t_max, in order (rules in the file comment).
inline std::vector<drop_history_row> parse_drop_history(std::string_view text, const std::string& source,
                                                        double t_max) {
  std::vector<drop_history_row> rows;
  static constexpr std::array<const char*, drop_history_row::columns> names{"t",
                                                                            "x",
                                                                            "y",
                                                                            "z",
                                                                            "vx",
                                                                            "vy",
                                                                            "vz",
                                                                            "speed",
                                                                            "canopy_diameter",
                                                                            "open_force",
                                                                            "payload_phi_x",
                                                                            "payload_phi_y",
                                                                            "canopy_phi_x",
                                                                            "canopy_phi_y",
                                                                            "flight_path_angle",
                                                                            "drag_coefficient",
                                                                            "open_force_filtered"};
  std::size_t pos = 0;
  long line_no = 0;
  while (pos < text.size()) {
    const std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) break;  // a line cut short by a killed run
    std::string_view line(text.data() + pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line_no == 1) {
      require(line != drop_history_header_16, "io::read_drop_history: '", source, "' line 1: header '", line,
              "' is the 16-column drop history of an earlier version, without open_force_filtered; this version "
              "reads '",
              drop_history_header, "' (rerun the drop, or restart from a checkpoint written by this version)");
      require(line == drop_history_header, "io::read_drop_history: '", source, "' line 1: header '", line,
              "' is not the drop history's ('", drop_history_header, "')");
      continue;
    }
    if (line.empty()) continue;
    std::array<double, drop_history_row::columns> v{};
    std::size_t k = 0, start = 0;
    while (true) {
      const std::size_t comma = line.find(',', start);
      const std::string_view item = line.substr(start, comma == std::string_view::npos ? line.npos : comma - start);
      require(k < v.size(), "io::read_drop_history: '", source, "' line ", line_no, ": more than ", v.size(),
              " columns");
      double x = 0;
      const auto res = std::from_chars(item.data(), item.data() + item.size(), x);
      require(!item.empty() && res.ec == std::errc{} && res.ptr == item.data() + item.size(),
              "io::read_drop_history: '", source, "' line ", line_no, ", column ", k + 1, " (", names[k], "): '", item,
              "' is not a number");
      v[k++] = x;
      if (comma == std::string_view::npos) break;
      start = comma + 1;
    }
    require(k == v.size(), "io::read_drop_history: '", source, "' line ", line_no, ": ", k, " columns, expected ",
            v.size());
    if (v[0] <= t_max) rows.push_back(drop_history_row::from(v));
  }
  return rows;
}

/// The rows of the history file `path` with t <= t_max, in file order (rules in the file
/// comment); no file: no rows.
inline std::vector<drop_history_row> read_drop_history(const std::filesystem::path& path, double t_max) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  require(!in.bad(), "io::read_drop_history: cannot read '", path.string(), "'");
  return parse_drop_history(text, path.string(), t_max);
}

/// The history rows of a run up to a checkpoint, stored in the checkpoint's section
/// "history" (history.csv's text, exact: shortest round-trip numbers), so a restart into
/// another directory carries them and its summary covers the whole run.
///   io::drop_history_record rec{rows};  io::save_checkpoint(path, sig, stepper, rec);
struct drop_history_record {
  static constexpr const char* checkpoint_section = "history";
  std::vector<drop_history_row> rows;

  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& self) {
    std::string text;
    if constexpr (Archive::saving) {
      text = std::string(drop_history_header) + '\n';
      for (const auto& r : self.rows) append_history_row(text, r);
    }
    ar("rows", text);
    if constexpr (Archive::loading)
      self.rows = parse_drop_history(text, "checkpoint section 'history'", std::numeric_limits<double>::infinity());
  }
};

}  // namespace parafsi::io
