// drop_readout: the read-out of a drop computed again from its history.csv, without
// rerunning it (after a change of the read-out's definitions or options).
//
//   drop_readout --history DIR/history.csv [--fabric NAME] [--window S] [--force-cutoff HZ]
//                [--history-every S] [--fixed-window] --out summary.csv
//
// Reads the history (io::read_drop_history: the 17-column format of parachute_drop and
// drop_guide), summarizes it with io::summarize (definitions in io/drop_summary.hpp and
// docs/validation.md §2) and writes the summary row to --out (summary.csv's columns) and
// the read-out behind it to stderr. With the options parachute_drop used, the row equals
// its summary.csv; `--fixed-window` takes the terminal means over the last --window
// seconds instead of whole swing periods (the rule before 2026-12).
#include "example_common.hpp"

#include <parafsi/io/drop_history.hpp>

#include <filesystem>

namespace io = parafsi::io;

int main(int argc, char** argv) {
  CLI::App app{"The summary of a drop recomputed from its history.csv"};
  std::string history, fabric, out;
  io::summary_options so;
  bool fixed = false;
  app.add_option("--history", history, "the drop's history.csv")->required()->check(CLI::ExistingFile);
  app.add_option("--fabric", fabric, "fabric name for the summary row (default: the history's directory name)");
  app.add_option("--window", so.window, "seconds of the steady diameter and (at least) of the terminal means")
      ->check(examples::finite)
      ->check(CLI::Range(0.05, 1e3))
      ->capture_default_str();
  app.add_option("--force-cutoff", so.force_cutoff, "cut-off (Hz, -3 dB) of the riser-force filter")
      ->check(examples::finite)
      ->check(CLI::Range(0.5, 1e4))
      ->capture_default_str();
  app.add_option("--history-every", so.sample_interval,
                 "row interval the filter assumes (s; 0: the history's mean interval)")
      ->check(examples::finite)
      ->check(CLI::Range(0.0, 10.0))
      ->capture_default_str();
  app.add_flag("--fixed-window", fixed, "terminal means over the last --window seconds, not whole swing periods");
  examples::add_out_option(app, out);
  int rc = 0;
  if (!examples::parse(app, argc, argv, rc)) return rc;
  return examples::guarded("drop_readout", [&]() -> int {
    so.whole_periods = !fixed;
    const auto rows = io::read_drop_history(history, std::numeric_limits<double>::infinity());
    if (rows.empty()) throw std::invalid_argument("the history '" + history + "' has no rows");
    if (fabric.empty()) fabric = std::filesystem::absolute(history).parent_path().filename().string();
    const auto s = io::summarize(rows, fabric, so);
    io::write_drop_summary(out, s);
    std::fputs(io::summary_report(s, so.force_cutoff, "drop_readout: ").c_str(), stderr);
    std::printf("%s\n", s.csv_row().c_str());
    return 0;
  });
}
