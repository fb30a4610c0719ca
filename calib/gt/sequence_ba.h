#pragma once
// The bundle adjustment of a whole sequence (doc/ground-truth.md, stage 2): overlapping windows of
// consecutive scans, each adjusted on its own (window_ba.h), their results joined by the pose
// graph of stage 1. Each motion between consecutive scans is taken from the one window in which
// it lies farthest from the window's ends, with the covariance that window's information gives
// it; the pose graph then weighs these motions against the GNSS priors as it weighed the
// odometry's. The windows are independent of each other, so the cost grows linearly with the
// sequence and the memory holds one window of scans.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/core/scan.h"
#include "rigcal/gt/types.h"
#include "rigcal/gt/window_ba.h"
#include "rigcal/report/step.h"

namespace rigcal::gt {

struct SequenceBaConfig {
  WindowBaConfig window;     // its step_covariances is set here
  size_t window_scans = 20;  // scans a window (its knots: one more, the next scan's pose)
  size_t overlap_scans = 4;  // each window starts this many scans before the previous one ends
  // Windows adjusted at once (each on one thread; the scans of all of them held); 0: one a core.
  int parallel_windows = 0;
};

// One window as it was adjusted (WindowBaResult's figures).
struct WindowSummary {
  size_t first_pose = 0, scans = 0;
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
  size_t scans_unused = 0;           // read, but stamped at no pose of the trajectory
  double seconds = 0;
};

// `next_scan`: the scans in stamp order (lidar::ScanStream::next), each stamped as a pose of
// `T_world_lidar` (the stage-1 poses the windows start from; every pose needs its scan);
// `odometry`: the motions and covariances kept where a window gives none. Throws rigcal::Error
// when a pose has no scan or the trajectory and the odometry differ in their stamps.
SequenceBaResult sequence_ba(const std::function<std::optional<Scan>()>& next_scan,
                             const Trajectory& T_world_lidar, const OdometryInput& odometry,
                             const SequenceBaConfig& config, const report::Progress& progress = {});

}  // namespace rigcal::gt
