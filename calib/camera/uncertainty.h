#pragma once
// Projection uncertainty over the image (doc/cameras.md), on a grid of cells: the 1-sigma of the
// pixel in its worst direction (the square root of the largest eigenvalue of J Σ Jᵀ) of the point
// at a given distance along each cell's ray.
#include <Eigen/Core>
#include <vector>

#include "rigcal/rig/rig.h"

namespace rigcal::camera {

struct CalibrationResult;

struct UncertaintyMap {
  int cols = 0, rows = 0;        // grid cells
  double cell_px = 0;            // cell size
  std::vector<double> sigma_px;  // row-major
  double mean_px = 0, max_px = 0, centre_px = 0;
};

// mrcal's definition: the point is fixed in the boards' frames (p_board_f = T_board_f_cam0 p_cam0
// for every frame f with a board pose); with every parameter perturbed (intrinsics, camera poses,
// board poses: result.covariance whole), the camera finds it again as the mean over the frames of
// T'_cam0_board_f p_board_f, moves it into camera `camera` by T'_cam_cam0 and projects it through
// the perturbed intrinsics. So the uncertainty of where the camera is, relative to what it
// calibrated against, counts as well as that of its lens: small where the boards were, growing
// away from them.
UncertaintyMap projection_uncertainty(const CalibrationResult& result, int camera,
                                      double distance_m, int cell_px = 40);

// The intrinsics' covariance alone (a fixed point in the camera frame through perturbed
// intrinsics): larger than mrcal's in the boards' region, where the board poses absorb part of an
// intrinsics error. Kept for comparison in the report.
UncertaintyMap projection_uncertainty_intrinsics_only(const rig::CameraModel& model,
                                                      const Eigen::MatrixXd& intrinsics_cov,
                                                      double distance_m, int cell_px = 40);

}  // namespace rigcal::camera
