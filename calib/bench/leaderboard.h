#pragma once
// Many sequences x many methods: per-sequence errors, cumulative curves and the VBR rank
// (sum over sequences of max(0, threshold - error), the area under the cumulative curve up to the
// threshold). A missing or failed sequence counts as failed: infinite error, zero to the rank.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/bench/evaluate.h"

namespace rigcal::bench {

struct LeaderboardInput {
  std::vector<std::string> sequences;
  std::vector<Trajectory> ground_truths;  // one per sequence
  std::vector<std::string> methods;
  // estimates[m][s]: the estimate, or why there is none ("missing file", a read error).
  std::vector<std::vector<std::optional<Trajectory>>> estimates;
  std::vector<std::vector<std::string>> problems;
  double ate_max = 10.0;  // m
  double rpe_max = 10.0;  // %
};

struct Entry {
  bool ok = false;
  std::string problem;  // why it failed
  double ate = 0;       // m: ATE RMSE (vbr: the evaluator's sqrt-of-mean figure)
  double rpe_pct = 0;   // %: RPE translation (rigcal/vbr: VBR lengths; kitti: KITTI lengths)
  double rpe_rot = 0;   // deg/m
};

struct MethodRow {
  std::string method;
  std::vector<Entry> entries;         // per sequence
  double ate_rank = 0, rpe_rank = 0;  // sum of max(0, threshold - error)
  size_t n_failed = 0;
};

struct Leaderboard {
  Convention convention = Convention::rigcal;
  std::vector<std::string> sequences;
  std::vector<MethodRow> rows;  // best RPE rank first
  double ate_max = 10.0, rpe_max = 10.0;
  std::string ate_definition, rpe_definition;
};

// How many entries of the board were scored (not missing, not failed).
size_t scored_entries(const Leaderboard& board);

// progress: one line per evaluated pair, for the command line.
Leaderboard build_leaderboard(const LeaderboardInput& input, const EvalOptions& options,
                              const std::function<void(std::string_view)>& progress = {});

// sum over errors of max(0, threshold - error); failed (infinite) errors add nothing.
double rank_score(const std::vector<double>& errors, double threshold);
// The fraction of errors <= x, at `samples` thresholds evenly from 0 to max_error.
std::vector<std::pair<double, double>> cumulative_curve(const std::vector<double>& errors,
                                                        double max_error, size_t samples = 201);

}  // namespace rigcal::bench
