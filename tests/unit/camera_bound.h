#pragma once
// The Cramér–Rao bound of a camera calibration, computed for the tests by a code path of its own:
// at the TRUE parameters, the Jacobian of every inlier corner's projection by central differences
// through OpenCV's projection (cv::projectPoints for radtan, cv::fisheye::projectPoints for
// equidistant; not rigcal's lens code, not Ceres), dense normal equations, and the corner noise
// measured against truth (observed minus the true projection), not estimated from the residuals.
// Shared by tests/unit/test_camera.cpp and tests/long/test_camera_long.cpp.
#include <string>
#include <vector>

#include "rigcal/camera/calibrate.h"
#include "rigcal/core/se3.h"
#include "rigcal/rig/rig.h"

namespace rigcal::camera {

struct CramerRaoBound {
  // The parameters of interest, in the layout of CalibrationResult::covariance's leading block:
  // [fx fy cx cy k...] of each camera, then for each camera after the first its rotation in the
  // first (rotation vector of R_est * R_true^T, deg, three axes) and translation (t_est - t_true,
  // m). The board poses (6 a frame) are nuisance parameters, marginalized.
  std::vector<std::string> names;
  Eigen::VectorXd sigma;       // marginal 1-sigma: sqrt(diag(noise^2 (J^T J)^-1))
  Eigen::MatrixXd covariance;  // of the same parameters, same units
  // The least-squares estimate's error to first order, (J^T J)^-1 J^T (observed - true
  // projection): what the solver's error should be for these corners if it finds the optimum.
  Eigen::VectorXd lsq_error;
  double noise_sigma_px = 0;  // per coordinate: rms of observed - true projection, inlier corners
  Eigen::Vector2d noise_mean_px = Eigen::Vector2d::Zero();  // mean of the same (a detector bias)
  // The bound's noise model is independent corners. Two checks of it on the same errors: the
  // mean error of each camera's corners in a frame, x and y, times sqrt(corners) / noise, RMS over
  // the views (1 for independent errors; above 1 when a view's corners err together), and the
  // correlation of neighbouring corners' errors (adjacent points of a row; 0 when independent).
  double view_mean_z_rms = 0, neighbour_correlation = 0;
  double condition = 0;  // of the normal matrix with its columns scaled to unit diagonal
  size_t n_corners = 0, n_frames = 0, n_parameters = 0;  // n_parameters: board poses included
};

// `cameras` and `T_cam_cam0` (identity for camera 0) are the truth, one a camera, one lens model
// for all; `T_cam0_board` the true board pose of every frame; `points_board` the target's object
// points; `corners` the solver's residuals (CalibrationResult::residuals): the inliers among them
// are the corners used, their `observed` pixels the measurements. Every frame with an inlier
// corner gets a board pose. Throws rigcal::Error when the normal matrix is singular.
CramerRaoBound cramer_rao_bound(const std::vector<rig::CameraModel>& cameras,
                                const std::vector<SE3>& T_cam_cam0,
                                const std::vector<SE3>& T_cam0_board,
                                const std::vector<Eigen::Vector3d>& points_board,
                                const std::vector<CornerResidual>& corners);

}  // namespace rigcal::camera
