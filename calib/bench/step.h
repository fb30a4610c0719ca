#pragma once
// The benchmark as one step (doc/bench.md): one estimate against its ground truth, or a
// leaderboard of methods over sequences, from files, with the report written where asked. The
// command line only parses options into BenchOptions and prints the lines returned.
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rigcal/bench/compare.h"
#include "rigcal/bench/evaluate.h"
#include "rigcal/bench/leaderboard.h"
#include "rigcal/io/trajectory_io.h"

namespace rigcal::bench {

struct BenchOptions {
  // --est: one estimate (est), or several against one ground truth (ests, est unused).
  std::vector<std::string> ests;
  std::string gt, est, format = "auto", gt_format, est_format, gt_times, est_times;
  std::string align, association, convention = "rigcal", report;
  size_t align_first = 0;
  double delta = 1;
  std::string delta_unit = "f";
  bool all_pairs = false;
  double delta_tol = 0.1;                // evo's --delta_tol
  bool pairs_from_reference = false;     // evo's --pairs_from_reference
  double t_offset = 0;                   // evo's --t_offset, s
  std::optional<double> t_start, t_end;  // evo's --t_start / --t_end, s
  double max_diff = 0.01, max_gap = 0.5;
  std::string duplicates;
  std::string plot_mode = "auto";  // --plot-mode
  bool per_pose = false;           // --per-pose: the rows as CSV beside bench.json
  // Leaderboard.
  std::string gt_dir, est_dir, methods;
  double ate_max = 10.0, rpe_max = 10.0;
};

// The reader's options for one file: `format` and `times` override the shared ones when given; the
// duplicate-stamp policy is the convention's default (keep for vbr, error otherwise) unless set.
io::TrajectoryReadOptions read_options(const BenchOptions& o, const std::string& format,
                                       const std::string& times);
// Throws rigcal::Error naming the option on an unknown value.
EvalOptions eval_options(const BenchOptions& o);

struct PairRun {
  io::TrajectoryFile gt, est;  // as read (their trajectories moved into the evaluation)
  EvalResult result;
};
// Reads o.gt and o.est, scores them, writes the report when o.report is set. Throws
// rigcal::Error naming both files when they cannot be scored.
PairRun score_pair(const BenchOptions& o);
// The figures as the command prints them, one line each.
std::vector<std::string> pair_summary(const BenchOptions& o, const PairRun& run);

// Several estimates (o.ests) against o.gt, each scored as score_pair scores one; with o.report,
// each one's report in REPORT/<name>/ (the estimate file's stem) and, in REPORT, the comparison
// (write_compare_report's files) and the overlay plots (trajectories.svg, ate.svg).
struct SeveralRun {
  std::vector<NamedResult> named;  // each estimate's name and summary (bench.json)
  std::vector<PairRun> runs;
  std::vector<std::string> report_files;  // written in REPORT (each estimate's not listed)
};
SeveralRun score_several(const BenchOptions& o);
// Each estimate's lines as pair_summary prints them, then the comparison table.
std::vector<std::string> several_summary(const BenchOptions& o, const SeveralRun& run);

// `rigcal bench compare RESULT...`: the saved results (bench.json files or folders holding one)
// read, named by their folders; with `report`, the comparison written there.
struct Compared {
  std::vector<NamedResult> results;
  std::vector<std::string> report_files;  // the names of the files written in `report`
};
Compared compare_results(const std::vector<std::string>& paths, const std::string& report);

// What `rigcal bench compare` prints: the table, and the files written to `report`.
std::vector<std::string> compare_summary(const Compared& compared, const std::string& report);

// `rigcal bench` for its options: one pair (o.ests of one), several estimates, or the leaderboard
// (o.gt_dir); each line to print goes to `print`, each leaderboard failure to `tell` as it
// happens. Throws rigcal::Error when the options name no job, or, after the leaderboard's table,
// when no run of it could be scored.
void run_bench(BenchOptions o, const std::function<void(std::string_view)>& print,
               const std::function<void(std::string_view)>& tell);

// Loads the leaderboard's folders, scores every run (`tell` receives a line per failure) and
// writes the report when o.report is set.
Leaderboard score_leaderboard(const BenchOptions& o,
                              const std::function<void(std::string_view)>& tell);

}  // namespace rigcal::bench
