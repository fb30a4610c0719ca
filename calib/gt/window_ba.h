#pragma once
// The geometric LiDAR bundle adjustment of one window of scans (doc/ground-truth.md, stage 2):
// the scans' points, placed by their poses, split into planar patches (plane_patches.h); every
// pose then moved to bring its points onto the patches' planes (point-to-plane, robust loss,
// Ceres), the map and its patches rebuilt from the new poses, and again, a few rounds. Each round
// lowers the same cost, the sum of the squared distances of the points to their planes (the
// planes refitted to the points are its minimum over the planes; the solve its descent over the
// poses). The first pose is held: the result is the window's shape, its place comes from the
// pose graph.
#include <Eigen/Core>
#include <vector>

#include "rigcal/core/se3.h"
#include "rigcal/gt/plane_patches.h"

namespace rigcal::gt {

struct WindowBaConfig {
  double voxel_size_m = 0.2;  // each scan's points downsampled to the first one of each voxel
  PatchConfig patches;
  // Of each patch, the points of a scan that contributes at least `min_points_per_scan`, at most
  // `max_points_per_scan` of them (evenly spread over its list); patches seen by one scan only
  // are left out (they fix nothing).
  size_t min_points_per_scan = 3, max_points_per_scan = 10;
  double point_sigma_m = 0.01;  // the points' noise along a normal (the range noise)
  double huber_sigmas = 3.0;    // Huber scale of the point-to-plane residual, in point sigmas
  int rounds = 6;               // map rebuilt and solved again, at most
  int max_iterations = 15;      // of each round's solve
  // Rounds stop when no pose moved more than this (m, and the same in rad over 10 m).
  double converged_m = 1e-4;
};

struct WindowBaResult {
  std::vector<SE3> T_world_lidar;  // the first one as given
  int rounds = 0;
  size_t patches = 0, residuals = 0;  // of the last round
  // The points' distances to their planes (m), over the residuals of the first and the last
  // round: the map's crispness before and after.
  double rms_before_m = 0, rms_after_m = 0;
};

// `points_lidar[k]`: scan k's points in its own frame at its stamp (deskewed); `T_world_lidar`:
// the initial poses, one a scan.
WindowBaResult window_ba(const std::vector<std::vector<Eigen::Vector3d>>& points_lidar,
                         const std::vector<SE3>& T_world_lidar, const WindowBaConfig& config);

}  // namespace rigcal::gt
