#pragma once
// T_camera_lidar from the board's plane seen by both sensors in several poses (issue 8;
// doc/lidar-camera.md). A plane n_l . x = d_l in the LiDAR frame is, in the camera frame,
// (R n_l) . x = d_l + (R n_l) . t; the camera sees n_c . x = d_c. So R takes the LiDAR normals to
// the camera's (Kabsch), and n_c . t = d_c - d_l (least squares): at least 3 boards whose normals
// span space. Then Ceres over SE(3) on the per-board residuals (2 normal angles, 1 distance),
// each whitened by the two planes' covariances (the camera's from the corner noise, the LiDAR's
// from its points' scatter), with a Huber loss.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/core/se3.h"
#include "rigcal/lidar_camera/board_camera.h"
#include "rigcal/lidar_camera/board_lidar.h"

namespace rigcal::lidar_camera {

struct BoardPair {
  Plane camera, lidar;
  std::vector<Eigen::Vector3d> lidar_points;  // for the point-to-plane RMS
};

struct Observability {
  // Singular values (descending) of the stacked camera normals, and the direction (camera frame)
  // of the smallest: the translation along it rests on the least tilt between the boards.
  Eigen::Vector3d singular_values = Eigen::Vector3d::Zero();
  Eigen::Vector3d weak_direction = Eigen::Vector3d::UnitZ();
  double condition = 0;  // first over third singular value
  bool enough = false;   // >= 3 boards and condition <= max_condition
  std::string reason;    // when not enough
};

Observability observability(const std::vector<BoardPair>& pairs, double max_condition = 20.0);

struct PairResidual {
  double normal_angle_deg = 0, distance_m = 0;  // camera plane vs the LiDAR plane carried over
  double point_rms_m = 0;                       // the LiDAR board points against the camera plane
  double chi2 = 0;                              // whitened squared residual (3 dof)
  bool outlier = false;                         // chi2 beyond 16.27 (99.9 % of chi-square(3))
};

struct Solution {
  SE3 T_camera_lidar;
  SE3 closed_form;
  // 6 x 6: rotation (left tangent, rad) then translation (m); scaled by the residuals' level when
  // it exceeds 1.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Vector3d rotation_sigma_deg = Eigen::Vector3d::Zero(),
                  translation_sigma_m = Eigen::Vector3d::Zero();
  std::vector<PairResidual> residuals;
  double noise_scale = 1;  // RMS of the whitened residuals (1 when the covariances are right)
  Observability observability;
};

// Throws rigcal::Error when the boards do not determine the extrinsic (observability().reason).
Solution solve(const std::vector<BoardPair>& pairs, double huber = 3.0);

// A warning when more than a third of the solved pairs are outliers (the solution then rests on
// the rest, which a person should look at); empty otherwise.
std::vector<std::string> outlier_warnings(const Solution& solution);

// The residuals of the boards under a given extrinsic (another tool's, an old calibration's):
// how well it makes the two sensors' planes agree.
std::vector<PairResidual> residuals_at(const std::vector<BoardPair>& pairs,
                                       const SE3& T_camera_lidar);

// One image + scan pair as the pipeline sees it: the camera's board (from the corners) and the
// scan's points (LiDAR frame).
struct PairInput {
  std::optional<CameraBoard> camera;  // nullopt: no full board detected in the image
  std::vector<Eigen::Vector3d> scan;
};

struct PairOutcome {
  bool used = false;
  std::string note;  // what was found, or why the pair was dropped
  LidarBoard lidar;
};

struct Calibration {
  Solution solution;
  std::vector<PairOutcome> pairs;
};

// The whole step: the board found in every scan (first without a prior, unless `prior_T_camera_
// lidar` is given); when some scans hold several board-sized pieces, a first solve on the
// unambiguous pairs predicts where the board is (the camera's board carried into the LiDAR
// frame) and those scans are searched again; then the final solve. Throws rigcal::Error when
// fewer than 3 usable pairs remain or they do not determine the extrinsic.
Calibration calibrate(const std::vector<PairInput>& pairs, const BoardSearch& search,
                      const std::optional<SE3>& prior_T_camera_lidar = std::nullopt);

}  // namespace rigcal::lidar_camera
