// rigcal bench: scores estimated trajectories against ground truth (doc/bench.md).
#include <fmt/format.h>

#include <memory>

#include "cli.h"
#include "rigcal/bench/step.h"

namespace rigcal::cli {

void add_bench(CLI::App& app) {
  auto o = std::make_shared<bench::BenchOptions>();
  CLI::App* cmd = app.add_subcommand(
      "bench",
      "Score estimated trajectories against ground truth: ATE (after alignment) and RPE.\n"
      "One pair: --gt GT --est EST. A leaderboard: --gt-dir G --est-dir E [--methods A,B]\n"
      "(files G/<seq>_gt.txt and E/<method>/<seq>_es.txt, or E/<seq>_es.txt for one method).\n"
      "Conventions: rigcal (correct, default), evo, kitti (devkit), vbr (official evaluator).\n"
      "Every figure is defined in doc/bench.md.");
  cmd->add_option("--gt", o->gt, "ground-truth trajectory");
  cmd->add_option("--est", o->ests,
                  "estimated trajectory; repeat it to score several against one ground truth\n"
                  "(a table of all, each one's report in REPORT/<file stem>/, and plots of all)");
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
                  "align on the first N matched poses only (0: all)")
      ->check(whole_count("a count of poses (0: all)"));
  cmd->add_option("--association", o->association,
                  "interpolate | nearest | one_to_one | index (default: the convention's)");
  cmd->add_option("--max-diff", o->max_diff, "nearest / one_to_one: largest stamp difference, s")
      ->check(seconds_within(0))
      ->capture_default_str();
  cmd->add_option("--max-gap", o->max_gap, "interpolate: longest GT interval bridged, s")
      ->check(seconds_within(1e-9))
      ->capture_default_str();
  cmd->add_option("--delta", o->delta, "RPE delta of the evo-style pairs")
      ->check(finite_number(true))
      ->capture_default_str();
  cmd->add_option("--delta-unit", o->delta_unit,
                  "f (frames) | m (metres of path) | d (degrees) | r (radians of rotation)")
      ->capture_default_str();
  cmd->add_flag("--all-pairs,--all_pairs", o->all_pairs,
                "evo's --all_pairs: every start, not consecutive pairs");
  cmd->add_option("--delta-tol,--delta_tol", o->delta_tol,
                  "all pairs in m, d or r: a pair's delta within delta * (1 +- TOL)")
      ->check(finite_number(true))
      ->capture_default_str();
  cmd->add_flag("--pairs-from-reference,--pairs_from_reference", o->pairs_from_reference,
                "RPE pairs chosen on the ground truth's path or rotation, not the estimate's");
  cmd->add_option("--t-offset,--t_offset", o->t_offset,
                  "seconds added to the estimate's stamps before association")
      ->check(seconds_within(-1e9));
  cmd->add_option("--t-start,--t_start", o->t_start,
                  "only ground-truth poses stamped at or after this time, s (the file's clock)")
      ->check(seconds_within(-1e10, 1e10));
  cmd->add_option("--t-end,--t_end", o->t_end,
                  "only ground-truth poses stamped at or before this time, s")
      ->check(seconds_within(-1e10, 1e10));
  cmd->add_option(
      "--duplicate-stamps", o->duplicates,
      "poses with equal stamps: error | drop (keep the first) | keep (default: keep for\n"
      "the evo and vbr conventions, as those tools do; error otherwise)");
  cmd->add_option("--report", o->report,
                  "folder for bench.json (every figure, a few kB) and the plots trajectory.svg,\n"
                  "ate.svg, rpe.svg");
  cmd->add_option("--plot-mode", o->plot_mode,
                  "plane of the trajectory plot: auto (the two axes of largest spread) | xy | xz "
                  "| yz")
      ->capture_default_str();
  cmd->add_flag("--per-pose", o->per_pose,
                "with --report: also per_pose.csv (each matched pose: positions, ATE) and\n"
                "segments_<kind>.csv (each RPE segment); large for long trajectories");
  cmd->add_option("--gt-dir", o->gt_dir, "leaderboard: folder of <seq>_gt.txt");
  cmd->add_option("--est-dir", o->est_dir, "leaderboard: folder of <method>/<seq>_es.txt");
  cmd->add_option("--methods", o->methods, "leaderboard: comma-separated method folders");
  cmd->add_option("--ate-max", o->ate_max, "leaderboard: ATE threshold for the rank, m")
      ->check(finite_number(true))
      ->capture_default_str();
  cmd->add_option("--rpe-max", o->rpe_max, "leaderboard: RPE threshold for the rank, %")
      ->check(finite_number(true))
      ->capture_default_str();
  auto compared = std::make_shared<std::vector<std::string>>();
  auto compare_report = std::make_shared<std::string>();
  CLI::App* compare = cmd->add_subcommand(
      "compare",
      "Compare saved results (evo_res's job): a table of their figures (ATE statistics, each\n"
      "RPE kind) and evo_res's plots. RESULT: a bench.json, or the --report folder holding\n"
      "one; a result is named by its folder.");
  compare->add_option("results", *compared, "RESULT...")->required();
  compare->add_option(
      "--report", *compare_report,
      "folder for compare.md, .csv, .json and evo_res's plots: the ATE's and the delta\n"
      "RPE's statistics as bars; box plots and histograms where the results\n"
      "hold their distribution (bench --report writes it)");
  auto print = [](std::string_view line) { fmt::print("{}\n", line); };
  compare->callback([compared, compare_report, print] {
    for (const std::string& line : bench::compare_summary(
             bench::compare_results(*compared, *compare_report), *compare_report))
      print(line);
  });
  cmd->callback([o, compare, print] {
    if (compare->parsed()) return;
    bench::run_bench(*o, print, [](std::string_view msg) { fmt::print(stderr, "{}\n", msg); });
  });
}

}  // namespace rigcal::cli
