// The drop's observables and summary (io/drop_summary.hpp) on synthetic histories
// with known answers; the history and summary files (io/drop_history.hpp).
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <parafsi/io/drop_history.hpp>
#include <parafsi/io/drop_summary.hpp>

namespace io = parafsi::io;
using doctest::Approx;

namespace {

/// A synthetic drop: diameter rising as 1 − e^{−t/τ} with an overshoot bump at t_mo,
/// a force pulse at t_p, speed relaxing to v_T, vertical descent unless told otherwise.
std::vector<io::drop_history_row> synthetic(double t_end, double dt, double Ds, double v_T, double tilt_deg = 0.0,
                                            double drift = 0.0, double swing_rate = 0.0) {
  std::vector<io::drop_history_row> h;
  for (int n = 0; n * dt <= t_end + 1e-12; ++n) {
    const double t = n * dt;
    io::drop_history_row r;
    r.t = t;
    r.canopy_diameter = 0.2 + (Ds - 0.2) * std::min(1.0, t / 0.5) + 0.1 * std::exp(-std::pow((t - 0.7) / 0.1, 2));
    r.open_force = 5.0 + 40.0 * std::exp(-std::pow((t - 0.45) / 0.05, 2));
    const double v = v_T + (10.0 - v_T) * std::exp(-t);
    double vx = drift, vy = 0.0;
    if (swing_rate > 0) {
      vx = drift * std::cos(swing_rate * t);
      vy = drift * std::sin(swing_rate * t);
    }
    r.vx = vx;
    r.vy = vy;
    r.vz = -v;
    r.speed = std::sqrt(vx * vx + vy * vy + v * v);
    r.canopy_phi_x = tilt_deg * (swing_rate > 0 ? std::sin(swing_rate * t) : 1.0);
    r.canopy_phi_y = 0;
    r.drag_coefficient = io::drag_coefficient(2.0 * 9.81, 1.18, r.speed, std::numbers::pi / 4);
    h.push_back(r);
  }
  return h;
}

}  // namespace

TEST_CASE("canopy diameter: 2 x mean distance of the skirt from the axis") {
  std::vector<Eigen::Vector3d> skirt;
  const int N = 8;
  const double R = 0.35;
  const Eigen::Vector3d a(1, 2, 3), axis = Eigen::Vector3d(0.3, -0.2, 1).normalized();
  const Eigen::Vector3d u = axis.unitOrthogonal(), w = axis.cross(u);
  for (int k = 0; k < N; ++k) {
    const double th = 2 * std::numbers::pi * k / N;
    skirt.push_back(a + 0.9 * axis + R * (std::cos(th) * u + std::sin(th) * w));
  }
  CHECK(io::canopy_diameter(skirt, a, a + 1.3 * axis) == Approx(2 * R).epsilon(1e-12));
  // Moving the skirt along the axis changes nothing.
  for (auto& x : skirt) x += 0.4 * axis;
  CHECK(io::canopy_diameter(skirt, a, a + 1.3 * axis) == Approx(2 * R).epsilon(1e-12));
  CHECK(io::canopy_diameter({}, a, a) == 0.0);
}

TEST_CASE("attitude angles, flight-path angle and drag coefficient") {
  const auto up = io::axis_angles({0, 0, 1});
  CHECK(up[0] == Approx(0.0));
  CHECK(up[1] == Approx(0.0));
  const double th = 0.3;
  const Eigen::Vector3d ax = Eigen::AngleAxisd(th, Eigen::Vector3d::UnitX()) * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d ay = Eigen::AngleAxisd(th, Eigen::Vector3d::UnitY()) * Eigen::Vector3d::UnitZ();
  CHECK(io::axis_angles(ax)[0] == Approx(io::deg(th)).epsilon(1e-12));
  CHECK(io::axis_angles(ax)[1] == Approx(0.0));
  CHECK(io::axis_angles(ay)[1] == Approx(io::deg(th)).epsilon(1e-12));
  CHECK(io::tilt_from_angles(io::deg(th), 0) == Approx(io::deg(th)).epsilon(1e-12));
  // A general axis: the tilt from (φx, φy) equals the angle from the vertical.
  const Eigen::Vector3d g = Eigen::Vector3d(0.2, -0.3, 0.9).normalized();
  const auto ga = io::axis_angles(g);
  CHECK(io::tilt_from_angles(ga[0], ga[1]) == Approx(io::deg(std::acos(g.z()))).epsilon(1e-12));

  CHECK(io::flight_path_angle({0, 0, -3}) == Approx(90.0));
  CHECK(io::flight_path_angle({3, 0, -3}) == Approx(45.0));
  CHECK(io::flight_path_angle({0, 2, 0}) == Approx(0.0));
  CHECK(io::flight_path_angle({0, 0, 0}, 90.0) == 90.0);

  // C_D = 2 W/(ρ v² S0): 1.9 kg at 5 m/s with S0 = π/4.
  const double W = 1.9 * 9.81, S0 = std::numbers::pi / 4;
  CHECK(io::drag_coefficient(W, 1.18, 5.0, S0) == Approx(2 * W / (1.18 * 25 * S0)).epsilon(1e-14));
  CHECK(std::isnan(io::drag_coefficient(W, 1.18, 0.1, S0)));
}

TEST_CASE("summary of a vertical synthetic drop") {
  const auto h = synthetic(6.0, 0.005, 0.7, 5.0);
  const auto s = io::summarize(h, "mat544");
  // Steady diameter = 0.7 (the bump has decayed long before the last 2 s).
  CHECK(s.steady_diameter == Approx(0.7).epsilon(1e-9));
  // D reaches 0.7 at t = 0.5 but the overshoot bump (0.1 e^{-((t-0.7)/0.1)^2}) adds
  // e^{-4}·0.1 = 1.8e-3 there, so the crossing is a little earlier.
  CHECK(s.t_f > 0.47);
  CHECK(s.t_f <= 0.5 + 1e-12);
  CHECK(s.t_mo == Approx(0.7).epsilon(1e-9));
  CHECK(s.t_p == Approx(0.45).epsilon(1e-9));
  CHECK(s.F_p == Approx(45.0).epsilon(1e-9));
  // Mean speed over [4, 6] of 5 + 5 e^{-t}: 5 + 5 (e^{-4} − e^{-6})/2 (trapezoid rule error ~1e-6).
  CHECK(s.v_terminal == Approx(5 + 2.5 * (std::exp(-4.0) - std::exp(-6.0))).epsilon(1e-4));
  CHECK(s.cd_terminal == Approx(2 * 2 * 9.81 / (1.18 * 25 * std::numbers::pi / 4)).epsilon(0.02));
  CHECK(s.attitude_amplitude == Approx(0.0));
  CHECK(s.descent_mode == "vertical");
  CHECK(s.csv_row().rfind("mat544,", 0) == 0);
}

TEST_CASE("descent modes: gliding (steady drift and tilt) and coning (turning drift)") {
  // Steady tilt 15° and 1.5 m/s horizontal drift one way: gliding.
  const auto g = io::summarize(synthetic(6.0, 0.005, 0.7, 5.0, 15.0, 1.5), "x");
  CHECK(g.attitude_amplitude == Approx(15.0).epsilon(1e-9));
  CHECK(g.drift_speed == Approx(1.5).epsilon(1e-9));
  CHECK(g.descent_mode == "gliding");
  // Tilt swinging ±15° and the drift direction turning at 3 rad/s: coning.
  const auto c = io::summarize(synthetic(6.0, 0.005, 0.7, 5.0, 15.0, 1.5, 3.0), "x");
  CHECK(c.attitude_amplitude == Approx(15.0).epsilon(1e-3));
  CHECK(c.horizontal_speed == Approx(1.5).epsilon(1e-9));
  CHECK(c.drift_speed < 0.3);
  CHECK(c.descent_mode == "coning");
  // The rule itself.
  CHECK(io::classify_descent(5.0, 0.0, 0.2, 5.0) == "vertical");
  CHECK(io::classify_descent(5.0, 0.9, 1.0, 5.0) == "gliding");
  CHECK(io::classify_descent(12.0, 0.1, 1.0, 5.0) == "coning");
  CHECK(io::classify_descent(12.0, 0.0, 0.0, 5.0) == "coning");
}

TEST_CASE("history rows round-trip and the headers are the contract's") {
  CHECK(std::string(io::drop_history_header) ==
        "t,x,y,z,vx,vy,vz,speed,canopy_diameter,open_force,payload_phi_x,payload_phi_y,canopy_phi_x,canopy_phi_y,"
        "flight_path_angle,drag_coefficient");
  CHECK(std::string(io::drop_summary_header) ==
        "fabric,t_f,t_mo,t_p,F_p,v_terminal,cd_terminal,attitude_amplitude,descent_mode");
  io::drop_history_row r;
  r.t = 1.5;
  r.open_force = 12.5;
  r.drag_coefficient = 0.8;
  const auto back = io::drop_history_row::from(r.values());
  CHECK(back.t == 1.5);
  CHECK(back.open_force == 12.5);
  CHECK(back.drag_coefficient == 0.8);
  // Empty and short histories.
  const auto e = io::summarize(std::span<const io::drop_history_row>{}, "none");
  CHECK(std::isnan(e.t_f));
  const auto s = io::summarize(synthetic(1.0, 0.01, 0.7, 5.0), "short");
  CHECK(std::isfinite(s.v_terminal));
}

// ------------------------------------------------------------------ history files
// io/drop_history.hpp: history.csv and summary.csv through checked files, read back on a
// restart. Known answers: the rows written are read back bit for bit (shortest round-trip
// text); the reader keeps exactly the rows with t <= t_max; a bad number is named with
// its file, line and column; a write to a full device is an error naming the file.
TEST_CASE("history.csv: written through a checked file, read back bit for bit") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "parafsi_drop_history_io";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto rows = synthetic(0.1, 0.005, 0.7, 5.0, 3.0, 0.2);
  REQUIRE(rows.size() == 21);
  {
    io::drop_history_writer w(dir / "history.csv");
    for (const auto& r : rows) w.write(r);
    w.close();
  }
  const auto back = io::read_drop_history(dir / "history.csv", 0.05 + 1e-12);
  REQUIRE(back.size() == 11);  // t = 0, 0.005, ..., 0.05
  std::size_t differing = 0;
  for (std::size_t i = 0; i < back.size(); ++i) {
    const auto a = rows[i].values(), b = back[i].values();
    for (std::size_t k = 0; k < a.size(); ++k)
      if (!(a[k] == b[k] || (std::isnan(a[k]) && std::isnan(b[k])))) ++differing;
  }
  CHECK(differing == 0);
  CHECK(io::read_drop_history(dir / "missing.csv", 1.0).empty());

  // A last line cut short by a killed run is ignored; complete lines are kept.
  {
    std::ifstream in(dir / "history.csv");
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream os(dir / "cut.csv");
    os << text.substr(0, text.size() - 7);  // the last row without its end
  }
  CHECK(io::read_drop_history(dir / "cut.csv", 1.0).size() == 20);

  // A bad number: file, line, column and text named (line 4 = the row of t = 0.01 s).
  auto corrupt = [&](const char* name, int line_no, const std::string& replacement) {
    std::ifstream in(dir / "history.csv");
    std::ofstream os(dir / name);
    std::string line;
    for (int n = 1; std::getline(in, line); ++n) os << (n == line_no ? replacement : line) << '\n';
  };
  std::string row4;
  {
    std::ifstream in(dir / "history.csv");
    for (int n = 1; n <= 4; ++n) std::getline(in, row4);
  }
  const std::size_t z0 = row4.find(',', row4.find(',', row4.find(',') + 1) + 1) + 1, z1 = row4.find(',', z0);
  corrupt("bad.csv", 4, row4.substr(0, z0) + "1.2.3" + row4.substr(z1));
  CHECK_THROWS_WITH_AS(io::read_drop_history(dir / "bad.csv", 1.0),
                       doctest::Contains("bad.csv' line 4, column 4 (z): '1.2.3' is not a number"),
                       parafsi::invalid_input);
  corrupt("short.csv", 4, "0.01,1,2");
  CHECK_THROWS_WITH_AS(io::read_drop_history(dir / "short.csv", 1.0),
                       doctest::Contains("short.csv' line 4: 3 columns, expected 16"), parafsi::invalid_input);
  corrupt("header.csv", 1, "t,x,y");
  CHECK_THROWS_WITH_AS(io::read_drop_history(dir / "header.csv", 1.0), doctest::Contains("header.csv' line 1: header"),
                       parafsi::invalid_input);

  // summary.csv: the header and one row.
  io::write_drop_summary(dir / "summary.csv", io::summarize(rows, "mat544"));
  {
    std::ifstream in(dir / "summary.csv");
    std::string h, r, extra;
    std::getline(in, h);
    std::getline(in, r);
    CHECK(h == io::drop_summary_header);
    CHECK(r.rfind("mat544,", 0) == 0);
    CHECK(!std::getline(in, extra));
  }
  fs::remove_all(dir);
}

TEST_CASE("checked files: a failed open or write is an error naming the file and the reason") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "parafsi_checked_file";
  fs::remove_all(dir);
  fs::create_directories(dir / "history.csv");  // a directory where the file should be
  const std::string open_msg = "cannot open '" + (dir / "history.csv").string() + "': Is a directory";
  CHECK_THROWS_WITH_AS(io::drop_history_writer(dir / "history.csv"), doctest::Contains(open_msg.c_str()),
                       io::write_error);
  CHECK_THROWS_WITH_AS(io::write_drop_summary(dir / "no" / "such" / "summary.csv", io::drop_summary{}),
                       doctest::Contains("No such file or directory"), io::write_error);
  if (fs::exists("/dev/full")) {
    // /dev/full accepts the open and fails every write with ENOSPC: the row's flush fails.
    io::drop_history_writer w("/dev/full");
    CHECK_THROWS_WITH_AS(w.write(io::drop_history_row{}), doctest::Contains("cannot write '/dev/full': No space left"),
                         io::write_error);
    CHECK_THROWS_WITH_AS(io::write_drop_summary("/dev/full", io::drop_summary{}),
                         doctest::Contains("cannot write '/dev/full'"), io::write_error);
  }
  fs::remove_all(dir);
}
