#pragma once
// The geometric LiDAR bundle adjustment of one window of scans (doc/ground-truth.md, stage 2):
// the scans' points, placed by their poses, split into planar patches (plane_patches.h); every
// pose then moved to bring its points onto the patches' planes (point-to-plane, robust loss,
// Ceres), the map and its patches rebuilt from the new poses, and again, a few rounds. Each round
// lowers the same cost, the sum of the squared distances of the points to their planes (the
// planes refitted to the points are its minimum over the planes; the solve its descent over the
// poses). The first pose is held: the result is the window's shape, its place comes from the
// pose graph.
//
// The sensor moves during a sweep: the poses are knots, one at each scan's stamp and one at the
// end of each sweep the next scan does not start, and a point measured a fraction f of the way from
// its scan's stamp to the next knot is placed by the interpolation of the two knots
// (sweep_point_to_plane_error.h). The sweeps are deskewed by the adjustment itself, with the motion
// it estimates, and each sweep's motion is its own (not the constant motion of the odometry's
// deskew).
#include <Eigen/Core>
#include <vector>

#include "rigcal/core/scan.h"
#include "rigcal/core/se3.h"
#include "rigcal/core/time.h"
#include "rigcal/gt/plane_patches.h"
#include "rigcal/gt/types.h"

namespace rigcal::gt {

// The photometric term (photometric_error.h), solved after the geometric rounds together with the
// last round's geometric residuals: each scan's points against the spherical images of the
// scans before it. Off by default: on the simulated walks and drives it changes the ground
// truth by less than its error (doc/ground-truth.md, the figures).
struct PhotometricConfig {
  bool enabled = false;
  int reference_scans = 2;   // each scan's points against the images of this many before it
  size_t max_points = 1500;  // of a scan against one image, evenly spread over those usable
  // A point is used where its pixel's 4 x 4 neighbourhood (what the bicubic interpolation reads)
  // holds ranges all within this fraction of its range (no edge, no empty pixel) and its range
  // there within `max_range_error_m` of its own (not occluded, not another surface).
  double max_range_spread = 0.1;
  double max_range_error_m = 0.3;
  double huber_sigmas = 3.0;  // on each point's residual, in the residuals' own sigmas
  // Each residual over its sigma, times its weight. The intensity's is low: a surface's intensity
  // changes with the angle it is seen at, from one scan to the next by more than its noise, and
  // weighed by its noise alone (1.8 units on the simulator's walk) it pulls the knots 2 cm off
  // the truth (doc/ground-truth.md). MD-SLAM weighs intensity 0.2 against range 0.9.
  double range_weight = 1.0, intensity_weight = 0.2;
  int iterations = 10;
};

struct WindowBaConfig {
  double voxel_size_m = 0.2;  // each scan's points downsampled to the first one of each voxel
  double min_range_m = 0.5, max_range_m = 120.0;  // of the points kept
  // Points placed by their time between two knots; false: every point at its scan's knot (scans
  // already deskewed).
  bool sweep_motion = true;
  // Knots a sweep (with sweep_motion): 1, the scans' stamps only; 2, one more halfway through
  // each sweep (the motion bent once a sweep: a walk's bob and sway are not straight over 0.1 s).
  int knots_per_sweep = 2;
  PatchConfig patches;
  // Of each patch, the points of a scan that contributes at least `min_points_per_scan`, at most
  // `max_points_per_scan` of them (evenly spread over its list); patches seen by one scan only
  // are left out (they fix nothing).
  size_t min_points_per_scan = 3, max_points_per_scan = 5;
  double point_sigma_m = 0.01;  // the points' noise along a normal (the range noise)
  double huber_sigmas = 3.0;    // Huber scale of the point-to-plane residual, in point sigmas
  int rounds = 4;               // map rebuilt and solved again, at most
  int max_iterations = 15;      // of the first round's solve
  // Of each later round's: it starts near its optimum (the association changes little), and
  // the solver otherwise spends up to max_iterations on millimetres (the demo's walk: the same
  // ground truth, 28 % less time).
  int later_iterations = 4;
  // Rounds stop when no pose moved more than this (m, and the same in rad over 10 m).
  double converged_m = 1e-4;
  // The covariance of each motion from a scan's pose to the next scan's
  // (WindowBaResult::step_covariance).
  bool step_covariances = false;
  int threads = 0;  // of the solver; 0: one a core
  PhotometricConfig photometric;
};

struct WindowBaResult {
  std::vector<SE3> T_world_lidar;  // the poses (knots at the given stamps), the first one as given
  int rounds = 0;
  size_t patches = 0, residuals = 0;  // of the last round
  // The points' distances to their planes (m), over the residuals of the first and the last
  // round: the map's crispness before and after.
  double rms_before_m = 0, rms_after_m = 0;
  // With step_covariances: the motion from scan k's pose to scan k + 1's, and from the last
  // scan's to the last pose (one a scan; with consecutive scans, one a pair of consecutive
  // poses), in the odometry's convention (types.h: rotation first, the motion perturbed on the
  // left, in the first pose's frame), from the last round's information with the planes
  // marginalized, scaled up by the residuals' variance over point_sigma_m^2 when that is larger
  // than 1. Empty when the information is singular (a knot no point depends on, a scene without
  // planes enough).
  std::vector<Matrix6d> step_covariance;
  // With the photometric term: its residuals, and their noise as measured before its solve
  // (1.4826 median absolute deviations), by which each is weighed.
  size_t photometric_residuals = 0;
  double photometric_sigma_range_m = 0, photometric_sigma_intensity = 0;
};

// A motion between two consecutive poses of a window measured by another sensor, with its
// covariance (types.h's convention): the odometry's, where the window leaves scans out
// (keyframes). Across a gap each side sees its knot through half a sweep's points only (a
// sweep's end knot holds the points of its last half, the next keyframe's first knot those of
// its first half), and a keyframe's own sweep, whose end no next scan's points hold, can stretch
// along whatever its planes leave free.
struct MotionPrior {
  size_t pose = 0;  // the motion from this pose to the next
  SE3 T_pose_next;
  Matrix6d covariance = Matrix6d::Identity();
};

// `scans`: in time order, each point in the sensor frame at its own time (Scan::point_times false,
// or sweep_motion false: at the scan's stamp); `stamps` and `T_world_lidar`: the window's poses
// (the initial knots), in time order: each scan's stamp and the end of its sweep (the next scan's
// stamp in the recording). Consecutive scans share the pose between them; where the window leaves
// scans out (keyframes, sequence_ba.h) a sweep's end is a pose of its own, and the motion across
// the gap to the next scan is what the two sweeps' points on common planes make of it. A knot no
// point depends on comes back as given. `priors`: motions between consecutive poses measured
// elsewhere (MotionPrior), in the solve and in the step covariances. Throws rigcal::Error when a
// scan has no pose at its stamp or none after it, or a pose is neither a scan's stamp nor a sweep's
// end.
WindowBaResult window_ba(const std::vector<Scan>& scans, const std::vector<Time>& stamps,
                         const std::vector<SE3>& T_world_lidar, const WindowBaConfig& config,
                         const std::vector<MotionPrior>& priors = {});

// Consecutive scans: the poses at the scans' stamps and at `end` (the end of the last sweep: the
// next scan's stamp).
WindowBaResult window_ba(const std::vector<Scan>& scans, const std::vector<SE3>& T_world_lidar,
                         Time end, const WindowBaConfig& config);

}  // namespace rigcal::gt
