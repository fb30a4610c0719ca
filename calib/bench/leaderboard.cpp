#include "rigcal/bench/leaderboard.h"

#include <fmt/format.h>

#include <algorithm>
#include <limits>

#include "rigcal/core/error.h"

namespace rigcal::bench {

double rank_score(const std::vector<double>& errors, double threshold) {
  double rank = 0.0;
  for (double e : errors) rank += std::max(0.0, threshold - e);
  return rank;
}

std::vector<std::pair<double, double>> cumulative_curve(const std::vector<double>& errors,
                                                        double max_error, size_t samples) {
  std::vector<std::pair<double, double>> curve;
  if (errors.empty() || samples < 2) return curve;
  for (size_t k = 0; k < samples; ++k) {
    const double x = max_error * static_cast<double>(k) / static_cast<double>(samples - 1);
    const size_t below =
        std::count_if(errors.begin(), errors.end(), [x](double e) { return e <= x; });
    curve.emplace_back(x, static_cast<double>(below) / static_cast<double>(errors.size()));
  }
  return curve;
}

Leaderboard build_leaderboard(const LeaderboardInput& in, const EvalOptions& options,
                              const std::function<void(std::string_view)>& progress) {
  if (options.convention == Convention::evo) {
    throw Error(
        "a leaderboard needs a sequence-level drift in %: use --convention rigcal, vbr or kitti");
  }
  Leaderboard board;
  board.convention = options.convention;
  board.sequences = in.sequences;
  board.ate_max = in.ate_max;
  board.rpe_max = in.rpe_max;
  board.ate_definition = options.convention == Convention::vbr
                             ? "VBR evaluator's ATE: sqrt(mean |e|) after SE(3) alignment, m"
                             : "ATE RMSE after alignment, m";
  const std::string rpe_kind = options.convention == Convention::kitti ? "kitti" : "vbr";
  board.rpe_definition = rpe_kind == "kitti" ? "RPE translation over 100..800 m segments, %"
                                             : "RPE translation over 1..55 % of the GT length, %";
  constexpr double kFailed = std::numeric_limits<double>::infinity();
  for (size_t m = 0; m < in.methods.size(); ++m) {
    MethodRow row;
    row.method = in.methods[m];
    std::vector<double> ates, rpes;
    for (size_t s = 0; s < in.sequences.size(); ++s) {
      Entry e;
      if (!in.estimates[m][s]) {
        e.problem = in.problems[m][s];
      } else {
        try {
          const EvalResult r = evaluate(in.ground_truths[s], *in.estimates[m][s], options);
          const RpeResult* rpe = find_rpe(r, rpe_kind);
          e.ate = r.vbr_ate_trans.value_or(r.ate_trans.rmse);
          if (rpe == nullptr || rpe->drift.n_segments == 0) {
            e.problem = "the trajectory is too short for any RPE segment";
          } else {
            e.rpe_pct = rpe->drift.trans_pct;
            e.rpe_rot = rpe->drift.rot_deg_per_m;
            e.ok = true;
          }
        } catch (const Error& err) {
          e.problem = err.what();
        }
      }
      if (progress) {
        progress(e.ok ? fmt::format("{} / {}: ATE {:.4f} m, RPE {:.4f} %", row.method,
                                    in.sequences[s], e.ate, e.rpe_pct)
                      : fmt::format("{} / {}: failed: {}", row.method, in.sequences[s], e.problem));
      }
      if (!e.ok) ++row.n_failed;
      ates.push_back(e.ok ? e.ate : kFailed);
      rpes.push_back(e.ok ? e.rpe_pct : kFailed);
      row.entries.push_back(e);
    }
    row.ate_rank = rank_score(ates, in.ate_max);
    row.rpe_rank = rank_score(rpes, in.rpe_max);
    board.rows.push_back(row);
  }
  std::stable_sort(board.rows.begin(), board.rows.end(),
                   [](const MethodRow& a, const MethodRow& b) { return a.rpe_rank > b.rpe_rank; });
  return board;
}

size_t scored_entries(const Leaderboard& board) {
  size_t n = 0;
  for (const MethodRow& row : board.rows)
    for (const Entry& e : row.entries) n += e.ok;
  return n;
}

}  // namespace rigcal::bench
