#pragma once
// Trajectory metrics: association, alignment, ATE and RPE (doc/bench.md). Plain functions on
// rigcal::Trajectory; conventions of other tools (evo, KITTI devkit, VBR evaluator) are selected
// in calib/bench/evaluate.h.
#include <functional>
#include <span>
#include <vector>

#include "rigcal/core/memory.h"
#include "rigcal/core/trajectory.h"

namespace rigcal::bench {

// ---- statistics -------------------------------------------------------------------------------
struct Stats {
  size_t n = 0;
  double rmse = 0, mean = 0, median = 0, std = 0, min = 0, max = 0, sse = 0;  // std: population
};
// By value: give it an rvalue to let the median reorder the values in place (millions of
// segment errors are not copied).
Stats statistics(std::vector<double> values);
Stats statistics_in_place(std::span<double> values);  // reorders them (the median)

// The shape of a set of errors, for box plots and histograms (evo_res's): quartiles by linear
// interpolation between order statistics (numpy's percentile), whiskers at the furthest values
// within 1.5 interquartile ranges of the box (matplotlib's), and a histogram over [min, max] of
// Freedman-Diaconis bins (2 IQR / n^(1/3) wide), at most 50 (sqrt(n) when the IQR is 0). O(n).
struct Distribution {
  size_t n = 0;
  double q1 = 0, median = 0, q3 = 0, whisker_low = 0, whisker_high = 0;
  double bin_low = 0, bin_width = 0;  // bin k covers [bin_low + k w, bin_low + (k + 1) w)
  std::vector<size_t> counts;         // the last bin includes the maximum
};
Distribution distribution(std::vector<double> values);

// ---- association --------------------------------------------------------------------------------
struct Matches {
  std::vector<size_t> gt, est;  // pairs: gt[k] with est[k]
};
// For every stamp of `a`, the nearest stamp of `b` within max_diff (ties: the earlier). O(N log M).
// Several stamps of `a` may take the same stamp of `b` (evo's rule). Returned as (a, b) pairs.
std::vector<std::pair<size_t, size_t>> nearest_stamps(const std::vector<Time>& a,
                                                      const std::vector<Time>& b, Time max_diff);
// evo: the shorter trajectory's stamps each take their nearest in the longer one (the estimate's
// when both have as many), in exact arithmetic; among equal stamps, the first.
Matches associate_evo(const Trajectory& gt, const Trajectory& est, Time max_diff);

// evo's association in evo's own arithmetic (evo.core.sync.matching_time_indices): stamps as the
// float64 seconds evo reads, and for each stamp of `a` the first stamp of `b` whose float64
// |difference| is smallest (numpy's argmin: among equal differences the first in file order),
// kept when that difference is <= max_diff. Both non-decreasing. Returned as (a, b) pairs.
std::vector<std::pair<size_t, size_t>> nearest_seconds(const std::vector<double>& a,
                                                       const std::vector<double>& b,
                                                       double max_diff);
// The float64 seconds evo reads: the decimal seconds correctly rounded (TUM: the text through
// float()), or integer nanoseconds read as float64 then divided by 1e9 (EuRoC).
std::vector<double> evo_seconds(const std::vector<Time>& stamps, bool read_as_ns);
// est_offset (evo's --t_offset) is added to the longer one's seconds, negated for the ground truth.
Matches associate_evo_seconds(std::vector<double> gt_seconds, std::vector<double> est_seconds,
                              double max_diff, double est_offset = 0.0);
// One-to-one (TUM associate.py): all pairs within max_diff, taken greedily by increasing |dt|.
Matches associate_one_to_one(const Trajectory& gt, const Trajectory& est, Time max_diff);
// By index, for files without stamps: the first min(N, M) poses.
Matches associate_by_index(const Trajectory& gt, const Trajectory& est);
// The ground truth interpolated (slerp + linear) at each estimate stamp that falls inside a GT
// interval no longer than max_gap; returns the matched estimate indices and the GT poses there.
struct Interpolated {
  std::vector<size_t> est;
  std::vector<SE3> T_world_gt;
};
// (rigcal::interpolate, core/trajectory.h, between the two GT poses.)
Interpolated interpolate_gt(const Trajectory& gt, const Trajectory& est, Time max_gap);

// ---- alignment ----------------------------------------------------------------------------------
enum class Alignment { se3, sim3, yaw, origin, none };
Alignment alignment_from_string(std::string_view name);  // se3|sim3|yaw|origin|none
std::string_view to_string(Alignment alignment);

struct AlignmentResult {
  Alignment method = Alignment::none;
  SE3 T_gt_est;        // maps estimate world coordinates into the GT world frame
  double scale = 1.0;  // applied to estimate positions before T_gt_est (sim3 only)
  size_t n_used = 0;
};
// p_gt ~ scale * R * p_est + t over the first n poses (0: all). Umeyama for se3/sim3, yaw about z
// with translation for yaw (4-DoF, gravity-aligned frames), first poses for origin. Throws
// rigcal::Error on degenerate input (fewer than 3 poses, all positions on a line).
AlignmentResult align(const std::vector<SE3>& T_world_gt, const std::vector<SE3>& T_world_est,
                      Alignment method, size_t n_first = 0);
// The estimate pose in the GT world: T_gt_est * (scaled estimate pose).
SE3 apply(const AlignmentResult& alignment, const SE3& T_world_est);

// ---- errors -------------------------------------------------------------------------------------
struct PoseErrors {
  std::vector<double> trans;    // m
  std::vector<double> rot_deg;  // deg
};
// ATE: E_i = inv(gt_i) * est_i for aligned, associated poses.
PoseErrors absolute_errors(const std::vector<SE3>& T_world_gt, const std::vector<SE3>& T_world_est);

// One relative-error segment: poses first..last, GT path length between them.
struct Segment {
  size_t first = 0, last = 0;
  double length = 0;   // m (the nominal length for KITTI/VBR kinds, the GT distance for deltas)
  double trans = 0;    // m (|t(E)|)
  double rot_deg = 0;  // deg (angle(E))
};
// Segments of fixed lengths, KITTI-style: starts every `step` frames; a segment ends at the first
// pose whose GT distance from the start exceeds the length. E = inv(dP_est) * dP_gt.
// length_segment_errors keeps their errors only (16 bytes a segment: millions for every-frame
// starts), start by start and each start's lengths in order, computed in parallel; with
// `segments`, every segment too. The sums of trans / length and rot_deg / length are added in
// that order.
struct SegmentErrors {
  UninitialisedVector<double> trans, rot_deg;  // m, deg
  double trans_per_length = 0, rot_deg_per_length = 0;
};
SegmentErrors length_segment_errors(const std::vector<SE3>& T_world_gt,
                                    const std::vector<SE3>& T_world_est,
                                    const std::vector<double>& lengths, size_t step,
                                    std::vector<Segment>* segments = nullptr);
std::vector<Segment> length_segments(const std::vector<SE3>& T_world_gt,
                                     const std::vector<SE3>& T_world_est,
                                     const std::vector<double>& lengths, size_t step);
// evo's RPE pairs (evo.core.filters, 1.36.5), chosen on the poses given (the estimate's by
// default, the reference's with evo's --pairs_from_reference):
//   frames, consecutive: (0, d), (d, 2d), ...; all pairs: (i, i + d) for every i.
//   metres, consecutive: the poses where the path since the previous one reaches d;
//   metres, all pairs: for each i, the first j > i whose path length from i is nearest d
//   (numpy's argmin), kept when within d * rel_tol of d.
//   degrees / radians, consecutive: the poses where the sum of the angles between consecutive
//   rotations since the previous one reaches d; all pairs: every (i, j > i) whose relative
//   rotation's angle is within d * rel_tol of d (quadratic in the poses, as in evo).
enum class DeltaUnit { frames, meters, degrees, radians };
DeltaUnit delta_unit_from_string(std::string_view name);  // f | m | d | r (evo's letters)
std::string_view to_string(DeltaUnit unit);               // frames | m | deg | rad
std::vector<std::pair<size_t, size_t>> evo_delta_pairs(const std::vector<SE3>& T_world_body,
                                                       double delta, DeltaUnit unit, bool all_pairs,
                                                       double rel_tol = 0.1);
// E = inv(dQ) * dP for each pair (the inverse of the KITTI form; same norms); `length` is the GT
// path between the two poses.
std::vector<Segment> delta_errors(const std::vector<SE3>& T_world_gt,
                                  const std::vector<SE3>& T_world_est,
                                  const std::vector<std::pair<size_t, size_t>>& pairs);
// Consecutive frame pairs: delta_errors(gt, est, evo_delta_pairs(est, delta, frames, false)).
std::vector<Segment> frame_deltas(const std::vector<SE3>& T_world_gt,
                                  const std::vector<SE3>& T_world_est, size_t delta);

// Pooled drift of segments: mean of trans/length (as % with 100) and rot/length (deg/m).
struct Drift {
  size_t n_segments = 0;
  double trans_pct = 0, rot_deg_per_m = 0;
};
Drift pooled_drift(const std::vector<Segment>& segments);

std::vector<double> cumulative_distances(const std::vector<SE3>& T_world_body);

}  // namespace rigcal::bench
