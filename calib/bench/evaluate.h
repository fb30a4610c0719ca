#pragma once
// One estimate against one ground truth, under a named convention (doc/bench.md):
//   rigcal  the correct form (default): GT interpolated at the estimate's stamps, SE(3) alignment,
//           ATE as true RMSE/mean/median/std/min/max, RPE over KITTI lengths, VBR lengths and
//           frame deltas, in double, rotations re-orthonormalised, accurate small angles.
//   evo     evo 1.x: nearest stamp of the longer trajectory within max_diff, alignment only when
//           asked, APE and consecutive-pair RPE as evo_ape/evo_rpe compute them.
//   kitti   the KITTI odometry devkit in double: pairs by index, no alignment, segments of
//           100..800 m every 10 frames, general 4x4 inverses, acos-of-trace angles, pooled means.
//   vbr     the official VBR evaluator (vbr_benchmark.cpp), in float as it computes: nearest stamp
//           with no threshold, Umeyama SE(3), "ATE" = sqrt(mean |e|) (not an RMSE), RPE over
//           1..55 % of the GT length with every frame a start.
#include <optional>
#include <string>
#include <vector>

#include "rigcal/bench/metrics.h"

namespace rigcal::bench {

enum class Convention { rigcal, evo, kitti, vbr };
Convention convention_from_string(std::string_view name);
std::string_view to_string(Convention convention);

enum class Association { interpolate, nearest, one_to_one, index };
Association association_from_string(std::string_view name);
std::string_view to_string(Association association);

struct EvalOptions {
  Convention convention = Convention::rigcal;
  std::optional<Association> association;     // default: the convention's
  std::optional<Alignment> alignment;         // default: the convention's
  size_t align_first_n = 0;                   // 0: all matched poses
  Time max_diff = Time::from_ns(10'000'000);  // nearest / one-to-one: 10 ms (evo's default)
  Time max_gap = Time::from_ns(500'000'000);  // interpolate: longest GT interval bridged, 0.5 s
  double delta = 1;                           // evo-style RPE delta ...
  DeltaUnit delta_unit = DeltaUnit::frames;   // ... in frames, metres, degrees or radians
  bool all_pairs = false;                     // evo's --all_pairs
  double delta_tol = 0.1;                     // evo's --delta_tol: relative, all pairs in m/deg/rad
  bool pairs_from_reference = false;          // evo's --pairs_from_reference: pairs on the GT
  // evo's --t_offset: seconds added to the estimate's stamps before association (under the evo
  // convention in evo's arithmetic: to the longer trajectory's float64 seconds, negated for the
  // ground truth).
  double t_offset = 0;
  // evo's --t_start / --t_end: only ground-truth poses whose stamps (as float64 seconds) are
  // within [t_start, t_end] are associated; the estimate is not cropped.
  std::optional<double> t_start, t_end;
  // Per matched pose (stamps, positions, ATE errors) and the delta kind's pairs: the report's
  // plots, a few tens of MB for a million poses.
  bool keep_per_pose = false;
  // Every RPE kind's segment rows (--per-pose): VBR's every-frame starts give 9 a pose.
  bool keep_segments = false;
  // evo compares the float64 seconds it reads: decimal seconds, or integer nanoseconds (EuRoC)
  // read as a float64 and divided by 1e9. True when the file gave nanoseconds.
  bool gt_stamps_ns = false, est_stamps_ns = false;
};

struct RpeResult {
  std::string kind;               // "kitti", "vbr", "delta"
  std::string definition;         // in words
  Drift drift;                    // pooled trans/length (%) and rot/length (deg/m)
  Stats trans, rot_deg;           // of the raw segment errors (m, deg)
  std::vector<Segment> segments;  // with keep_segments (the delta kind's: keep_per_pose)
};

struct EvalResult {
  Convention convention = Convention::rigcal;
  Association association = Association::interpolate;
  size_t n_gt = 0, n_est = 0, n_pairs = 0;
  double gt_length = 0;  // m, along the matched GT poses
  AlignmentResult alignment;
  Stats ate_trans, ate_rot_deg;  // m, deg
  // vbr: the evaluator's printed "ATE", sqrt(mean |e|) in m and sqrt(mean angle) in deg.
  std::optional<double> vbr_ate_trans, vbr_ate_rot;
  std::vector<RpeResult> rpe;
  std::vector<std::string> notes;  // what was computed, in words
  // Per matched pose, with keep_per_pose: stamps, GT and aligned estimate positions, ATE errors.
  // has_stamps: false when paired by index without stamps (the stamps are then pose indices).
  bool has_stamps = true;
  std::vector<Time> stamps;
  std::vector<Eigen::Vector3d> p_gt, p_est_aligned;
  std::vector<double> ate_trans_errors, ate_rot_errors_deg;
};

// Throws rigcal::Error when the two do not overlap (no matched pairs) or alignment is degenerate.
// Takes the trajectories by value: move them in to keep the peak memory of long ones low.
// Per-pose data for plots (stamps, positions, ATE errors) is kept only with
// options.keep_per_pose, segments only with options.keep_segments.
EvalResult evaluate(Trajectory gt, Trajectory est, const EvalOptions& options = {});

const RpeResult* find_rpe(const EvalResult& result, std::string_view kind);

// VBR's segment lengths, fractions of the GT path length.
inline constexpr double kVbrFractions[] = {0.01, 0.02, 0.03, 0.05, 0.08, 0.13, 0.21, 0.34, 0.55};
// KITTI's segment lengths, m.
inline constexpr double kKittiLengths[] = {100, 200, 300, 400, 500, 600, 700, 800};

}  // namespace rigcal::bench
