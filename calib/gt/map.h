#pragma once
// The ground truth's map (doc/ground-truth.md, "The map and the markers"): every scan's points
// placed by the ground-truth trajectory, each point at its own time (the motion between the
// poses of consecutive scans taken as constant), voxel-filtered to one point a voxel (the
// centroid of its points, with their mean intensity) for the PLY output; and, at full
// resolution, the points bright enough to be retro-reflective survey markers.
#include <Eigen/Core>
#include <functional>
#include <optional>
#include <vector>

#include "rigcal/core/scan.h"
#include "rigcal/core/trajectory.h"
#include "rigcal/report/step.h"

namespace rigcal::gt {

struct MapConfig {
  double voxel_size_m = 0.1;
  double min_range_m = 0.5, max_range_m = 60.0;
  // A point is bright (a marker's candidate) at this intensity or above; 0: `bright_factor`
  // times the median intensity of the first scan (a retro-reflective sheet returns tens of
  // times what a diffuse surface does; Ouster's calibrated reflectivity puts the two above and
  // below 100).
  double bright_intensity = 0.0;
  double bright_factor = 10.0;
};

struct LidarMap {
  double voxel_size_m = 0;
  std::vector<Eigen::Vector3d> points;  // the voxels' centroids, the trajectory's frame
  std::vector<float> intensity;         // their points' mean
  std::vector<Eigen::Vector3d> bright;  // every bright point, not filtered
  double bright_intensity = 0;          // the threshold used
  size_t scans = 0, scan_points = 0;
  size_t scans_unused = 0;  // stamped at no pose of the trajectory
};

// `next_scan`: the scans in stamp order (lidar::ScanStream::next); `T_world_lidar`: a pose at
// each scan's stamp (the ground truth). Throws rigcal::Error when the trajectory has fewer than 2
// poses.
LidarMap build_map(const std::function<std::optional<Scan>()>& next_scan,
                   const Trajectory& T_world_lidar, const MapConfig& config,
                   const report::Progress& progress = {});

}  // namespace rigcal::gt
