#include "rigcal/bench/step.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <filesystem>
#include <future>

#include "rigcal/bench/report.h"
#include "rigcal/core/error.h"

namespace rigcal::bench {
namespace fs = std::filesystem;
namespace {

std::string stats_line(std::string_view label, const Stats& s) {
  return fmt::format(
      "  {:<16} rmse {:>10.6f}  mean {:>10.6f}  median {:>10.6f}  std {:>10.6f}  min {:>10.6f}  "
      "max {:>10.6f}",
      label, s.rmse, s.mean, s.median, s.std, s.min, s.max);
}

// A table's text as one printed line (print adds the newline).
std::string without_final_newline(std::string text) {
  if (!text.empty() && text.back() == '\n') text.pop_back();
  return text;
}

}  // namespace

io::TrajectoryReadOptions read_options(const BenchOptions& o, const std::string& format,
                                       const std::string& times) {
  io::TrajectoryReadOptions r;
  r.format = io::trajectory_format_from_string(format.empty() ? o.format : format);
  r.kitti_times = times;
  // evo and the VBR evaluator read every line, equal stamps included; the others refuse them by
  // default.
  const bool peer_keeps = o.convention == "vbr" || o.convention == "evo";
  r.duplicates = io::duplicates_from_string(o.duplicates.empty() ? (peer_keeps ? "keep" : "error")
                                                                 : o.duplicates);
  return r;
}

EvalOptions eval_options(const BenchOptions& o) {
  EvalOptions e;
  e.convention = convention_from_string(o.convention);
  if (!o.align.empty()) e.alignment = alignment_from_string(o.align);
  if (!o.association.empty()) e.association = association_from_string(o.association);
  e.align_first_n = o.align_first;
  e.max_diff = Time::from_seconds(o.max_diff);
  e.max_gap = Time::from_seconds(o.max_gap);
  e.delta = o.delta;
  try {
    e.delta_unit = delta_unit_from_string(o.delta_unit);
  } catch (const Error& err) {
    throw Error(fmt::format("--delta-unit: {}", err.what()));
  }
  e.all_pairs = o.all_pairs;
  e.delta_tol = o.delta_tol;
  e.pairs_from_reference = o.pairs_from_reference;
  e.t_offset = o.t_offset;
  e.t_start = o.t_start;
  e.t_end = o.t_end;
  e.keep_per_pose = !o.report.empty();
  e.keep_segments = !o.report.empty() && o.per_pose;
  if (o.per_pose && o.report.empty()) throw Error("--per-pose writes beside --report DIR: give it");
  return e;
}

namespace {

// run.result from run.gt and run.est as read (their trajectories moved into the evaluation).
void evaluate_read(const BenchOptions& o, const EvalOptions& options, const std::string& est,
                   PairRun& run) {
  EvalOptions with_formats = options;
  with_formats.gt_stamps_ns = run.gt.format == io::TrajectoryFormat::euroc;
  with_formats.est_stamps_ns = run.est.format == io::TrajectoryFormat::euroc;
  try {
    run.result =
        evaluate(std::move(run.gt.trajectory), std::move(run.est.trajectory), with_formats);
  } catch (const Error& e) {
    throw Error(fmt::format("{} against {}: {}", est, o.gt, e.what()));
  }
}

}  // namespace

PairRun score_pair(const BenchOptions& o) {
  const EvalOptions options = eval_options(o);
  PairRun run;
  // The two files at once, one a core (reading a million poses takes about a third of a second).
  auto est = std::async(std::launch::async, [&] {
    return io::read_trajectory(o.est, read_options(o, o.est_format, o.est_times));
  });
  run.gt = io::read_trajectory(o.gt, read_options(o, o.gt_format, o.gt_times));
  run.est = est.get();
  evaluate_read(o, options, o.est, run);
  if (!o.report.empty()) {
    write_bench_report(run.result, o.report, {{"gt", o.gt}, {"est", o.est}},
                       {plot_mode_from_string(o.plot_mode), o.per_pose});
  }
  return run;
}

std::vector<std::string> pair_summary(const BenchOptions& o, const PairRun& run) {
  const EvalResult& r = run.result;
  auto duplicates = [](const io::TrajectoryFile& f) {
    return f.duplicate_stamps ? fmt::format(", {} duplicate stamps", f.duplicate_stamps)
                              : std::string();
  };
  std::vector<std::string> out;
  out.push_back(fmt::format("rigcal bench, convention {}", to_string(r.convention)));
  out.push_back(fmt::format("  ground truth {} ({} poses, {}{})", o.gt, r.n_gt,
                            io::to_string(run.gt.format), duplicates(run.gt)));
  out.push_back(fmt::format("  estimate     {} ({} poses, {}{})", o.est, r.n_est,
                            io::to_string(run.est.format), duplicates(run.est)));
  out.push_back(fmt::format("  {} pose pairs ({}), alignment {}{}, GT path {:.3f} m", r.n_pairs,
                            to_string(r.association), to_string(r.alignment.method),
                            r.alignment.method == Alignment::sim3
                                ? fmt::format(" (scale {:.9f})", r.alignment.scale)
                                : "",
                            r.gt_length));
  out.push_back("ATE");
  out.push_back(stats_line("translation [m]", r.ate_trans));
  out.push_back(stats_line("rotation [deg]", r.ate_rot_deg));
  if (r.vbr_ate_trans) {
    out.push_back(
        fmt::format("  VBR's \"ATE\" (sqrt of mean error, not an RMSE): {:.6g} m, {:.6g} deg",
                    *r.vbr_ate_trans, *r.vbr_ate_rot));
  }
  out.push_back("RPE");
  for (const RpeResult& rpe : r.rpe) {
    if (rpe.kind == "delta") {
      out.push_back(fmt::format("  {} ({} pairs)", rpe.definition, rpe.trans.n));
      out.push_back(stats_line("translation [m]", rpe.trans));
      out.push_back(stats_line("rotation [deg]", rpe.rot_deg));
    } else if (rpe.drift.n_segments == 0) {
      out.push_back(fmt::format("  {}: no segment fits in the trajectory", rpe.definition));
    } else {
      out.push_back(fmt::format(
          "  {}\n    translation {:.6f} %, rotation {:.6g} deg/m ({:.6g} rad/m), {} segments",
          rpe.definition, rpe.drift.trans_pct, rpe.drift.rot_deg_per_m,
          rpe.drift.rot_deg_per_m * M_PI / 180.0, rpe.drift.n_segments));
    }
  }
  for (const std::string& n : r.notes) out.push_back(fmt::format("note: {}", n));
  if (!o.report.empty()) {
    out.push_back(fmt::format("report: {}/bench.json, trajectory.svg, ate.svg, rpe.svg{}", o.report,
                              o.per_pose ? ", per_pose.csv, segments_<kind>.csv" : ""));
  }
  return out;
}

SeveralRun score_several(const BenchOptions& o) {
  SeveralRun out;
  const EvalOptions options = eval_options(o);
  const io::TrajectoryFile gt = io::read_trajectory(o.gt, read_options(o, o.gt_format, o.gt_times));
  for (const std::string& est : o.ests) {
    PairRun run;
    run.gt = gt;
    run.est = io::read_trajectory(est, read_options(o, o.est_format, o.est_times));
    evaluate_read(o, options, est, run);
    out.named.push_back(
        {fs::path(est).stem().string(), bench_json(run.result, {{"gt", o.gt}, {"est", est}})});
    out.runs.push_back(std::move(run));
  }
  make_names_unique(out.named);
  if (!o.report.empty()) {
    const fs::path dir = o.report;
    std::vector<const EvalResult*> results;
    std::vector<std::string> names;
    for (size_t k = 0; k < out.runs.size(); ++k) {
      write_bench_report(out.runs[k].result, dir / out.named[k].name,
                         {{"gt", o.gt}, {"est", o.ests[k]}},
                         {plot_mode_from_string(o.plot_mode), o.per_pose});
      results.push_back(&out.runs[k].result);
      names.push_back(out.named[k].name);
    }
    out.report_files = write_compare_report(out.named, dir);
    write_overlay_plots(results, names, dir, plot_mode_from_string(o.plot_mode));
    out.report_files.insert(out.report_files.end(), {"trajectories.svg", "ate.svg"});
  }
  return out;
}

std::vector<std::string> several_summary(const BenchOptions& o, const SeveralRun& run) {
  std::vector<std::string> out;
  for (size_t k = 0; k < run.runs.size(); ++k) {
    BenchOptions one = o;
    one.est = o.ests[k];
    one.report.clear();
    out.push_back(fmt::format("== {}", run.named[k].name));
    for (std::string& line : pair_summary(one, run.runs[k])) out.push_back(std::move(line));
  }
  out.push_back("");
  out.push_back(compare_markdown(run.named));
  if (!o.report.empty()) {
    out.push_back(fmt::format("report: {0}: {1}; each estimate's in {0}/<name>/", o.report,
                              fmt::join(run.report_files, ", ")));
  }
  return out;
}

Compared compare_results(const std::vector<std::string>& paths, const std::string& report) {
  if (paths.empty()) throw Error("give the results to compare: bench.json files or their folders");
  Compared out;
  for (const std::string& p : paths) out.results.push_back(read_result(p));
  make_names_unique(out.results);
  if (!report.empty()) out.report_files = write_compare_report(out.results, report);
  return out;
}

std::vector<std::string> compare_summary(const Compared& compared, const std::string& report) {
  std::vector<std::string> out = {without_final_newline(compare_markdown(compared.results))};
  if (!report.empty())
    out.push_back(fmt::format("report: {}: {}", report, fmt::join(compared.report_files, ", ")));
  return out;
}

void run_bench(BenchOptions o, const std::function<void(std::string_view)>& print,
               const std::function<void(std::string_view)>& tell) {
  if (!o.gt_dir.empty()) {
    const Leaderboard board = score_leaderboard(o, tell);
    print(without_final_newline(leaderboard_markdown(board)));
    if (!o.report.empty())
      print(fmt::format("report: {}/leaderboard.{{md,csv,json}} and cumulative curves", o.report));
    if (scored_entries(board) == 0)
      throw Error("no run could be scored (every estimate missing or failed)");
    return;
  }
  if (o.gt.empty() || o.ests.empty())
    throw Error("give --gt and --est (or --gt-dir and --est-dir)");
  if (o.ests.size() > 1) {
    for (const std::string& line : several_summary(o, score_several(o))) print(line);
    return;
  }
  o.est = o.ests.front();
  for (const std::string& line : pair_summary(o, score_pair(o))) print(line);
}

Leaderboard score_leaderboard(const BenchOptions& o,
                              const std::function<void(std::string_view)>& tell) {
  if (o.est_dir.empty()) throw Error("--gt-dir needs --est-dir");
  const EvalOptions options = eval_options(o);
  LeaderboardInput in;
  in.ate_max = o.ate_max;
  in.rpe_max = o.rpe_max;
  in = load_leaderboard_input(o.gt_dir, o.est_dir, o.methods, read_options(o, "", ""), in);
  const Leaderboard board = build_leaderboard(in, options, tell);
  if (!o.report.empty()) write_leaderboard_report(board, o.report);
  return board;
}

}  // namespace rigcal::bench
