#pragma once
// The board found in a LiDAR scan without clicks (issue 8; doc/lidar-camera.md): planes by
// RANSAC, split into connected pieces, and the piece whose minimum-area rectangle matches the
// physical board's size; then the plane refitted on its points.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/lidar_camera/board_camera.h"

namespace rigcal::lidar_camera {

struct BoardSearch {
  double board_width_m = 0, board_height_m = 0;  // the physical board (the outline)
  double min_range_m = 0.5, max_range_m = 8.0;
  double plane_threshold_m = 0.03;  // RANSAC inlier distance
  double cell_m = 0.1;              // connectivity: points in neighbouring cells join
  // A piece matches when each side of its rectangle is within [size - short_m, size + long_m]:
  // LiDAR rings sample the board's edges late (up to one ring gap short); the 2 cm raster and a
  // stub of the stand can add a few centimetres.
  double short_m = 0.12, long_m = 0.10;
  int min_points = 30;
  int max_planes = 15;
  uint64_t seed = 1;
  // Where the board is expected (LiDAR frame), e.g. from a prior extrinsic and the camera's board:
  // among matching pieces the nearest wins, and a piece farther than this is not taken.
  std::optional<Eigen::Vector3d> expected_centre;
  double max_centre_distance_m = 0.5;
  // A box in the LiDAR frame (min, max): only points inside are searched (`--roi`).
  std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> roi;
};

struct LidarBoard {
  bool found = false;
  std::string reason;  // why not found, or how many candidates there were
  Plane plane;         // refitted on the points; covariance from their scatter
  std::vector<Eigen::Vector3d> points;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double width_m = 0, height_m = 0;  // the rectangle found
  double plane_rms_m = 0;
  int candidates = 0;  // planar pieces of the board's size
};

LidarBoard find_board(const std::vector<Eigen::Vector3d>& points, const BoardSearch& search);

// Least-squares plane of points (centroid, smallest principal direction), d >= 0, with the
// covariance of (tangent angles, d) from the residual scatter.
Plane fit_plane(const std::vector<Eigen::Vector3d>& points);

// The plane of LiDAR points whose noise is along their rays from the sensor's origin: Gauss-Newton
// on the range each point would need to lie on the plane, (d - n.x) / (n.x/|x|), from the
// orthogonal fit. The orthogonal fit is biased by such noise towards the rays' direction (a board
// seen at 45 deg with 1 cm range noise tilts by about sigma^2 sin cos / in-plane variance: 0.3 deg
// for an A3 board); this one is not. Covariance from the range residuals. `rms`: of the range
// residuals.
Plane fit_plane_along_rays(const std::vector<Eigen::Vector3d>& points, double* rms = nullptr);

}  // namespace rigcal::lidar_camera
