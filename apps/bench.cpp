// rigcal bench: scores estimated trajectories against ground truth (doc/bench.md).
#include <fmt/format.h>

#include <filesystem>
#include <memory>

#include "cli.h"
#include "rigcal/bench/evaluate.h"
#include "rigcal/bench/leaderboard.h"
#include "rigcal/bench/report.h"
#include "rigcal/core/error.h"
#include "rigcal/io/files.h"
#include "rigcal/io/trajectory_io.h"

namespace rigcal::cli {
namespace {

struct Options {
  std::string gt, est, format = "auto", gt_format, est_format, gt_times, est_times;
  std::string align, association, convention = "rigcal", report;
  size_t align_first = 0;
  double delta = 1;
  std::string delta_unit = "f";
  bool all_pairs = false;
  double max_diff = 0.01, max_gap = 0.5;
  std::string duplicates;
  // Leaderboard.
  std::string gt_dir, est_dir, methods;
  double ate_max = 10.0, rpe_max = 10.0;
};

io::TrajectoryReadOptions read_options(const Options& o, const std::string& format,
                                       const std::string& times) {
  io::TrajectoryReadOptions r;
  r.format = io::trajectory_format_from_string(format.empty() ? o.format : format);
  r.kitti_times = times;
  // The VBR evaluator reads every line, equal stamps included; the others refuse them by default.
  r.duplicates = io::duplicates_from_string(
      o.duplicates.empty() ? (o.convention == "vbr" ? "keep" : "error") : o.duplicates);
  return r;
}

bench::EvalOptions eval_options(const Options& o) {
  bench::EvalOptions e;
  e.convention = bench::convention_from_string(o.convention);
  if (!o.align.empty()) e.alignment = bench::alignment_from_string(o.align);
  if (!o.association.empty()) e.association = bench::association_from_string(o.association);
  e.align_first_n = o.align_first;
  e.max_diff = Time::from_seconds(o.max_diff);
  e.max_gap = Time::from_seconds(o.max_gap);
  e.delta = o.delta;
  if (o.delta_unit == "f" || o.delta_unit == "frames")
    e.delta_unit = bench::DeltaUnit::frames;
  else if (o.delta_unit == "m" || o.delta_unit == "meters")
    e.delta_unit = bench::DeltaUnit::meters;
  else
    throw Error(
        fmt::format("--delta-unit: expected f (frames) or m (metres), got '{}'", o.delta_unit));
  e.all_pairs = o.all_pairs;
  e.keep_segments = !o.report.empty();
  return e;
}

void print_stats(std::string_view label, const bench::Stats& s) {
  fmt::print(
      "  {:<16} rmse {:>10.6f}  mean {:>10.6f}  median {:>10.6f}  std {:>10.6f}  min {:>10.6f}  "
      "max {:>10.6f}\n",
      label, s.rmse, s.mean, s.median, s.std, s.min, s.max);
}

void run_pair(const Options& o) {
  io::TrajectoryFile gt = io::read_trajectory(o.gt, read_options(o, o.gt_format, o.gt_times));
  io::TrajectoryFile est = io::read_trajectory(o.est, read_options(o, o.est_format, o.est_times));
  const bench::EvalOptions options = eval_options(o);
  const bench::EvalResult r = [&] {
    try {
      return bench::evaluate(std::move(gt.trajectory), std::move(est.trajectory), options);
    } catch (const Error& e) {
      throw Error(fmt::format("{} against {}: {}", o.est, o.gt, e.what()));
    }
  }();

  fmt::print("rigcal bench, convention {}\n", bench::to_string(r.convention));
  fmt::print("  ground truth {} ({} poses, {}{})\n", o.gt, r.n_gt, io::to_string(gt.format),
             gt.duplicate_stamps ? fmt::format(", {} duplicate stamps", gt.duplicate_stamps) : "");
  fmt::print(
      "  estimate     {} ({} poses, {}{})\n", o.est, r.n_est, io::to_string(est.format),
      est.duplicate_stamps ? fmt::format(", {} duplicate stamps", est.duplicate_stamps) : "");
  fmt::print("  {} pose pairs ({}), alignment {}{}, GT path {:.3f} m\n", r.n_pairs,
             bench::to_string(r.association), bench::to_string(r.alignment.method),
             r.alignment.method == bench::Alignment::sim3
                 ? fmt::format(" (scale {:.9f})", r.alignment.scale)
                 : "",
             r.gt_length);
  fmt::print("ATE\n");
  print_stats("translation [m]", r.ate_trans);
  print_stats("rotation [deg]", r.ate_rot_deg);
  if (r.vbr_ate_trans) {
    fmt::print("  VBR's \"ATE\" (sqrt of mean error, not an RMSE): {:.6g} m, {:.6g} deg\n",
               *r.vbr_ate_trans, *r.vbr_ate_rot);
  }
  fmt::print("RPE\n");
  for (const bench::RpeResult& rpe : r.rpe) {
    if (rpe.kind == "delta") {
      fmt::print("  {} ({} pairs)\n", rpe.definition, rpe.trans.n);
      print_stats("translation [m]", rpe.trans);
      print_stats("rotation [deg]", rpe.rot_deg);
    } else if (rpe.drift.n_segments == 0) {
      fmt::print("  {}: no segment fits in the trajectory\n", rpe.definition);
    } else {
      fmt::print(
          "  {}\n    translation {:.6f} %, rotation {:.6g} deg/m ({:.6g} rad/m), {} segments\n",
          rpe.definition, rpe.drift.trans_pct, rpe.drift.rot_deg_per_m,
          rpe.drift.rot_deg_per_m * M_PI / 180.0, rpe.drift.n_segments);
    }
  }
  for (const std::string& n : r.notes) fmt::print("note: {}\n", n);
  if (!o.report.empty()) {
    bench::write_bench_report(r, o.report, {{"gt", o.gt}, {"est", o.est}});
    fmt::print("report: {}/bench.json and plots\n", o.report);
  }
}

void run_leaderboard(const Options& o) {
  if (o.est_dir.empty()) throw Error("--gt-dir needs --est-dir");
  bench::LeaderboardInput in;
  in.ate_max = o.ate_max;
  in.rpe_max = o.rpe_max;
  const bench::EvalOptions options = eval_options(o);
  in = bench::load_leaderboard_input(o.gt_dir, o.est_dir, o.methods, read_options(o, "", ""), in);
  const bench::Leaderboard board = bench::build_leaderboard(
      in, options, [](std::string_view msg) { fmt::print(stderr, "{}\n", msg); });
  fmt::print("{}", bench::leaderboard_markdown(board));
  if (!o.report.empty()) {
    bench::write_leaderboard_report(board, o.report);
    fmt::print("report: {}/leaderboard.{{md,csv,json}} and cumulative curves\n", o.report);
  }
  if (bench::scored_entries(board) == 0) {
    fmt::print(stderr,
               "rigcal: error: no run could be scored (every estimate missing or failed)\n");
    throw Exit{2};
  }
}

}  // namespace

void add_bench(CLI::App& app) {
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "bench",
      "Score estimated trajectories against ground truth: ATE (after alignment) and RPE.\n"
      "One pair: --gt GT --est EST. A leaderboard: --gt-dir G --est-dir E [--methods A,B]\n"
      "(files G/<seq>_gt.txt and E/<method>/<seq>_es.txt, or E/<seq>_es.txt for one method).\n"
      "Conventions: rigcal (correct, default), evo, kitti (devkit), vbr (official evaluator).\n"
      "Every figure is defined in doc/bench.md.");
  cmd->add_option("--gt", o->gt, "ground-truth trajectory");
  cmd->add_option("--est", o->est, "estimated trajectory");
  cmd->add_option("--format", o->format, "auto | tum | kitti | euroc (both files)")
      ->capture_default_str();
  cmd->add_option("--gt-format", o->gt_format, "format of the ground truth only");
  cmd->add_option("--est-format", o->est_format, "format of the estimate only");
  cmd->add_option("--gt-times", o->gt_times, "KITTI times file of the ground truth");
  cmd->add_option("--est-times", o->est_times, "KITTI times file of the estimate");
  cmd->add_option("--convention", o->convention, "rigcal | evo | kitti | vbr")
      ->capture_default_str();
  cmd->add_option(
      "--align", o->align,
      "se3 | sim3 | yaw | origin | none (default: se3 for rigcal and vbr, none for evo and kitti)");
  cmd->add_option("--align-first", o->align_first,
                  "align on the first N matched poses only (0: all)");
  cmd->add_option("--association", o->association,
                  "interpolate | nearest | one_to_one | index (default: the convention's)");
  cmd->add_option("--max-diff", o->max_diff, "nearest / one_to_one: largest stamp difference, s")
      ->check(finite_number(false))
      ->capture_default_str();
  cmd->add_option("--max-gap", o->max_gap, "interpolate: longest GT interval bridged, s")
      ->check(finite_number(true))
      ->capture_default_str();
  cmd->add_option("--delta", o->delta, "RPE delta of the evo-style pairs")
      ->check(finite_number(true))
      ->capture_default_str();
  cmd->add_option("--delta-unit", o->delta_unit, "f (frames) | m (metres of the estimate's path)")
      ->capture_default_str();
  cmd->add_flag("--all-pairs", o->all_pairs,
                "evo's --all_pairs: every start, not consecutive pairs");
  cmd->add_option(
      "--duplicate-stamps", o->duplicates,
      "poses with equal stamps: error | drop (keep the first) | keep (default: keep for\n"
      "the vbr convention, as its evaluator does; error otherwise)");
  cmd->add_option("--report", o->report, "folder for bench.json (every figure) and SVG plots");
  cmd->add_option("--gt-dir", o->gt_dir, "leaderboard: folder of <seq>_gt.txt");
  cmd->add_option("--est-dir", o->est_dir, "leaderboard: folder of <method>/<seq>_es.txt");
  cmd->add_option("--methods", o->methods, "leaderboard: comma-separated method folders");
  cmd->add_option("--ate-max", o->ate_max, "leaderboard: ATE threshold for the rank, m")
      ->check(finite_number(true))
      ->capture_default_str();
  cmd->add_option("--rpe-max", o->rpe_max, "leaderboard: RPE threshold for the rank, %")
      ->check(finite_number(true))
      ->capture_default_str();
  cmd->callback([o] {
    if (!o->gt_dir.empty()) return run_leaderboard(*o);
    if (o->gt.empty() || o->est.empty())
      throw Error("give --gt and --est (or --gt-dir and --est-dir)");
    run_pair(*o);
  });
}

}  // namespace rigcal::cli
