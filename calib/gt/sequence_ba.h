#pragma once
// The bundle adjustment of a whole sequence (doc/ground-truth.md, stage 2): keyframes chosen by
// the rig's motion, overlapping windows of consecutive keyframes, each adjusted on its own
// (window_ba.h), their results joined by the pose graph of stage 1. Each motion from one keyframe
// to the next is taken from the one window in which it lies farthest from the window's ends, with
// the covariance that window's information gives it, and spread over the scans between them
// along the odometry's path (with every scan a keyframe, the default, each motion a scan's; with
// keyframes, the odometry's motions between the window's poses are priors in it).
// The pose graph then weighs these motions against the GNSS priors as it weighed the odometry's.
// The windows are independent of each other, so the cost grows linearly with the sequence and the
// memory holds one window of scans.
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/core/scan.h"
#include "rigcal/gt/types.h"
#include "rigcal/gt/window_ba.h"
#include "rigcal/report/step.h"

namespace rigcal::gt {

struct SequenceBaConfig {
  WindowBaConfig window;  // its step_covariances is set here
  // Keyframes, the scans the windows adjust: the first scan, then each scan at which the rig has
  // moved keyframe_distance_m or turned keyframe_angle_deg since the last keyframe (by the
  // odometry's motions: the same plan in every task of a job array), or keyframe_max_gap scans
  // after it (0: no limit), and the last sweep. Windows must then overlap by one keyframe at
  // least (overlap_scans). Both 0 (the default): every
  // scan. Keyframes trade accuracy for time: at 0.3 m and 5 deg a walk's 0.13 m a sweep makes
  // every third scan a keyframe, the adjustment about twice as fast, and the ground truth's error
  // larger: the scans between keyframes are where the odometry puts them, and the keyframes
  // follow its motions where their planes leave a direction free (doc/ground-truth.md).
  double keyframe_distance_m = 0, keyframe_angle_deg = 0;
  size_t keyframe_max_gap = 10;
  bool keyframes_on() const { return keyframe_distance_m > 0 || keyframe_angle_deg > 0; }
  size_t window_scans = 20;  // keyframes a window (its poses: each one's stamp and sweep's end)
  size_t overlap_scans = 4;  // each window starts this many keyframes before the previous one ends
  // Windows adjusted at once (each on one thread; the scans of all of them held); 0: one a core.
  int parallel_windows = 0;
  // Only the windows [first_window, end_window) of the sequence's plan (a chunk of a job array,
  // doc/performance.md): the motions they own come from them, the others stay the odometry's
  // (SequenceBaResult::from_window says which); join_window_motions puts the chunks together.
  // The plan, and so each window, is the whole sequence's whatever the chunk.
  size_t first_window = 0, end_window = std::numeric_limits<size_t>::max();
};

// One window as it was adjusted (WindowBaResult's figures).
struct WindowSummary {
  size_t first_pose = 0, scans = 0;  // scans: the window's keyframes
  int rounds = 0;
  size_t patches = 0, residuals = 0;
  double rms_before_m = 0, rms_after_m = 0;
  bool covariances = false;  // false: its motions could not be weighed, the odometry's kept
  double seconds = 0;
  // With the photometric term (WindowBaResult's figures).
  size_t photometric_residuals = 0;
  double photometric_sigma_range_m = 0, photometric_sigma_intensity = 0;
};

struct SequenceBaResult {
  SequenceBaConfig config;
  // The poses chained from the windows' motions (from the initial first pose) and those motions'
  // covariances: the pose graph's input, in place of the odometry's.
  OdometryInput motions;
  std::vector<WindowSummary> windows;
  size_t motions_from_odometry = 0;  // of the windows that gave no covariance
  // Per motion: true where an adjusted window gave it.
  std::vector<bool> from_window;
  // The windows the sequence's plan has, and the motions [first_owned, end_owned) the adjusted
  // windows own (all of them without a chunk).
  size_t planned_windows = 0, first_owned = 0, end_owned = 0;
  std::vector<size_t> keyframes;  // the plan's (poses)
  size_t scans_unused = 0;        // read, but stamped at no pose of the trajectory
  double seconds = 0;
};

// `next_scan`: the scans in stamp order (lidar::ScanStream::next), each stamped as a pose of
// `T_world_lidar` (the stage-1 poses the windows start from; every pose needs its scan);
// `odometry`: the motions and covariances kept where a window gives none. Throws rigcal::Error
// when a pose has no scan or the trajectory and the odometry differ in their stamps.
SequenceBaResult sequence_ba(const std::function<std::optional<Scan>()>& next_scan,
                             const Trajectory& T_world_lidar, const OdometryInput& odometry,
                             const SequenceBaConfig& config, const report::Progress& progress = {});

// The first pose (scan) of window `window` of the plan of the sequence whose odometry is
// `T_odom_lidar` (none past the plan's end): where a chunk's scans start (what came before may
// be skipped unread).
std::optional<size_t> first_pose_of_window(const Trajectory& T_odom_lidar,
                                           const SequenceBaConfig& config, size_t window);

// The motions a chunk's windows own (first_owned..end_owned), chained from the pose of
// `T_world_lidar` (the poses the windows started from) at the first of them, with their
// covariances: what a task of a job array writes. Empty when the chunk owns none.
OdometryInput owned_motions(const SequenceBaResult& ba, const Trajectory& T_world_lidar);

// The motions of the chunks of a job array (each chunk's owned motions, SequenceBaResult with
// first_owned..end_owned, chained as poses with their step covariances; `sources` name them in
// errors) put in the sequence's place: every chunk's consecutive poses must be consecutive poses
// of `odometry` (throws rigcal::Error naming the chunk otherwise, or where two chunks give the
// same motion); the motions no chunk gives stay the odometry's (motions_from_odometry). The
// result is chained from `T_world_first` as sequence_ba's.
SequenceBaResult join_window_motions(const std::vector<OdometryInput>& chunks,
                                     const std::vector<std::string>& sources,
                                     const OdometryInput& odometry, const SE3& T_world_first);

}  // namespace rigcal::gt
