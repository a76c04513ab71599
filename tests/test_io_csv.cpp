// Observers: CSV time histories and the progress line.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <parafsi/io/csv.hpp>
#include <parafsi/io/progress.hpp>

namespace fs = std::filesystem;
using namespace parafsi;

namespace {
std::vector<std::string> lines_of(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::string> v;
  for (std::string l; std::getline(in, l);) v.push_back(l);
  return v;
}
fs::path scratch(const char* name) {
  const fs::path d = fs::temp_directory_path() / "parafsi_test_io_csv";
  fs::create_directories(d);
  return d / name;
}
}  // namespace

TEST_CASE("csv_writer: header once, rows of doubles that round-trip, column count checked") {
  const fs::path p = scratch("h.csv");
  {
    io::csv_writer w(p, {"t", "x", "f"});
    w.row({0.0, 0.1, 1.0 / 3.0});
    const std::vector<double> r{1e-300, -2.5, std::numeric_limits<double>::quiet_NaN()};
    w.row(r);
    CHECK_THROWS_WITH_AS(w.row({1.0, 2.0}), doctest::Contains("2 values for 3 columns"), invalid_input);
    CHECK(w.rows() == 2);
  }
  const auto l = lines_of(p);
  REQUIRE(l.size() == 3);
  CHECK(l[0] == "t,x,f");
  double a, b, c;
  char k1, k2;
  std::istringstream(l[1]) >> a >> k1 >> b >> k2 >> c;
  CHECK(a == 0.0);
  CHECK(b == 0.1);  // 17 digits: exact round-trip
  CHECK(c == 1.0 / 3.0);
  CHECK(l[2] == "1e-300,-2.5,nan");
}

TEST_CASE("csv_writer: resume after a restart time keeps earlier rows, rejects another header") {
  const fs::path p = scratch("r.csv");
  {
    io::csv_writer w(p, {"t", "v"});
    for (int i = 0; i < 5; ++i) w.row({0.1 * i, double(i)});
  }
  io::csv_options o;
  o.resume_after = 0.2;
  {
    io::csv_writer w(p, {"t", "v"}, o);
    w.row({0.3, 30.0});
  }
  const auto l = lines_of(p);
  REQUIRE(l.size() == 5);
  CHECK(l[3] == "0.20000000000000001,2");
  CHECK(l[4] == "0.29999999999999999,30");
  CHECK_THROWS_WITH_AS(io::csv_writer(p, {"t", "w"}, o), doctest::Contains("its header is 't,v'"), invalid_input);
  CHECK_THROWS_AS(io::csv_writer(p, {"t", "a,b"}), invalid_input);
}

TEST_CASE("csv_writer: flush policies") {
  const fs::path p = scratch("f.csv");
  io::csv_options o;
  o.flush = io::flush_policy::every_n_rows;
  o.flush_rows = 3;
  io::csv_writer w(p, {"t"}, o);
  w.row({1.0});
  w.row({2.0});
  w.row({3.0});  // third row: flushed
  CHECK(lines_of(p).size() == 4);
  w.row({4.0});
  w.flush();
  CHECK(lines_of(p).size() == 5);
}

// A full disk (/dev/full accepts the open, fails every write) is an error naming the
// file, at the first flushed row, not a silent success.
TEST_CASE("csv_writer: a failed write throws naming the file") {
  if (!fs::exists("/dev/full")) return;
  CHECK_THROWS_WITH_AS(io::csv_writer("/dev/full", {"t"}).row({1.0}), doctest::Contains("write to /dev/full failed"),
                       invalid_input);
}

TEST_CASE("progress: rate-limited lines with steps/s, ETA and extra fields") {
  double wall = 100.0;
  std::ostringstream os;
  io::progress_options o;
  o.out = &os;
  o.interval = 0.5;
  o.clock = [&] { return wall; };
  io::progress bar(2.0, o);
  wall = 100.1;
  CHECK_FALSE(bar(0.0, 0));  // inside the interval: silent
  wall = 101.0;              // 1 s later: 100 steps, 0.5 simulated seconds
  CHECK(bar(0.5, 100, {{"F", 12.5}}));
  const std::string l1 = bar.last_line();
  CHECK(l1.find("t = 0.5000 s / 2 s (25.0 %)") != std::string::npos);
  CHECK(l1.find("steps 100") != std::string::npos);
  CHECK(l1.find("100 steps/s") != std::string::npos);
  CHECK(l1.find("ETA 3s") != std::string::npos);  // 1.5 s left at 0.5 sim-s/s
  CHECK(l1.find("F = 12.5") != std::string::npos);
  wall = 101.2;
  CHECK_FALSE(bar(0.6, 120));  // rate limit
  wall = 102.0;
  CHECK(bar(1.0, 300));
  CHECK(bar.last_line().find("200 steps/s") != std::string::npos);
  bar.finish(2.0, 500);
  CHECK(bar.lines() == 3);
  CHECK(os.str().find("ETA 0s") != std::string::npos);
  CHECK(io::format_duration(3725) == "1h02m");
  CHECK(io::format_duration(125) == "2m05s");
}
