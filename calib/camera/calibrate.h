#pragma once
// Mono and stereo calibration of pinhole cameras (radtan or equidistant) from target detections
// (doc/cameras.md). One Ceres problem holds every camera's intrinsics, one board pose per frame
// (in the first camera) and the pose of every other camera in the first; frames seen by one
// camera only still count. Outliers are rejected iteratively (solve, drop corners beyond k sigma,
// re-solve); the final solve is plain least squares, and the parameters' covariance is scaled by
// the noise estimated from the residuals.
#include <optional>
#include <string>
#include <vector>

#include "rigcal/camera/detect.h"
#include "rigcal/camera/target.h"
#include "rigcal/rig/rig.h"

namespace rigcal::camera {

struct CameraInput {
  std::string name;
  int width = 0, height = 0;
  std::vector<Detection> frames;  // one per frame, the same frames for every camera
};

struct CalibrationOptions {
  rig::DistortionModel model = rig::DistortionModel::radtan;
  int radtan_coefficients = 4;  // 4 (k1 k2 p1 p2) or 5 (+ k3)
  // One lens a camera, in the cameras' order, when they differ (empty: `model` for all).
  struct Lens {
    rig::DistortionModel model = rig::DistortionModel::radtan;
    int radtan_coefficients = 4;
  };
  std::vector<Lens> per_camera;
  double outlier_k_sigma = 4.0;  // drop corners with a residual coordinate beyond k sigma
  int max_rejection_rounds = 5;
  double huber_px = 1.0;  // robust loss while outliers are rejected
  int min_views = 3;
  // Solve the board's warp too (target.h: two parabolas, as mrcal's calobject_warp): a printed
  // board on a backing is not flat. Off: the board is taken as flat.
  bool board_warp = false;
};

struct CornerResidual {
  int camera = 0, frame = 0, point = 0;
  Eigen::Vector2d observed = Eigen::Vector2d::Zero();
  Eigen::Vector2d residual = Eigen::Vector2d::Zero();  // projected - observed, px
  bool outlier = false;
};

struct CameraResult {
  rig::CameraModel model;
  std::vector<double> stddev;    // of fx, fy, cx, cy, k..., in the same order
  std::vector<double> view_rms;  // 2-D RMS per frame (NaN where the camera did not see it)
  size_t n_views = 0, n_corners = 0;
};

// The detections against given lenses and camera poses (a stored calibration), only the board
// poses free: how well new images fit the stored parameters. Outliers are rejected as calibrate()
// does (options.outlier_k_sigma), the RMS is over the inliers.
struct FitAtStored {
  double rms_2d_px = 0;                  // OpenCV's definition, as CalibrationResult's
  std::vector<double> camera_rms_2d_px;  // per camera
  size_t corners = 0, outliers = 0, views = 0;
};
// `models` and `T_cam_cam0` (camera 0: identity) one a camera, in the order of `cams`; the models
// may differ in lens model. Throws rigcal::Error on a lens it cannot fit or when no board was
// detected.
FitAtStored fit_at_stored(const Target& target, const std::vector<CameraInput>& cams,
                          const std::vector<rig::CameraModel>& models,
                          const std::vector<SE3>& T_cam_cam0, const CalibrationOptions& options);

struct CalibrationResult {
  std::vector<CameraResult> cameras;
  // T_cami_cam0 for every camera (identity for camera 0), and its 1-sigma in deg and m.
  std::vector<SE3> T_cam_cam0;
  std::vector<Eigen::Vector3d> rotation_stddev_deg, translation_stddev_m;
  std::vector<std::optional<SE3>> T_cam0_board;  // per frame
  std::vector<CornerResidual> residuals;         // every corner, outliers flagged
  double rms_2d_px = 0;                          // OpenCV's: sqrt(mean |r|^2) over inlier corners
  double rms_coord_px = 0;    // mrcal's: sqrt(mean r_x^2, r_y^2) = rms_2d / sqrt(2)
  double noise_sigma_px = 0;  // per coordinate, from the residuals and the degrees of freedom
  size_t n_outliers = 0, n_parameters = 0, n_residuals = 0;
  // Of every parameter, tangent space, scaled by noise_sigma_px^2: the intrinsics of each camera
  // (camera c's at intrinsics_covariance_index[c], as many as its stddev), then T_cami_cam0 for
  // i >= 1 (3 rotation + 3 translation each, at pose_covariance_index[i]; -1 for camera 0), then
  // the board pose T_cam0_board of frame f at board_covariance_index[f] (-1: no pose). Rotation
  // tangents are Ceres' quaternion ones: d rotates by 2|d| about d, on the left.
  Eigen::MatrixXd covariance;
  std::vector<int> intrinsics_covariance_index, pose_covariance_index;
  std::vector<int> board_covariance_index;
  // With CalibrationOptions::board_warp: the warp (x, y, m), its 1-sigma, and its place in the
  // covariance (after the board poses; -1 without).
  std::optional<Eigen::Vector2d> board_warp_m, board_warp_stddev_m;
  int warp_covariance_index = -1;
  std::vector<std::string> notes;
};

// Throws rigcal::Error for unusable input: cameras of different frame counts, fewer than
// options.min_views views with a detection in a camera, no frame shared between two cameras.
CalibrationResult calibrate(const Target& target, const std::vector<CameraInput>& cameras,
                            const CalibrationOptions& options = {});

}  // namespace rigcal::camera
