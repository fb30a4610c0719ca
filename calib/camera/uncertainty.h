#pragma once
// Projection uncertainty over the image (doc/cameras.md): for each pixel, the point at a given
// distance along its ray is projected through intrinsics perturbed by their covariance; the
// result is the 1-sigma of the pixel in its worst direction (the square root of the largest
// eigenvalue of J Σ Jᵀ). This propagates the intrinsics' covariance only; mrcal also propagates
// the board poses' coupling, which this map does not.
#include <Eigen/Core>
#include <vector>

#include "rigcal/rig/rig.h"

namespace rigcal::camera {

struct UncertaintyMap {
  int cols = 0, rows = 0;        // grid cells
  double cell_px = 0;            // cell size
  std::vector<double> sigma_px;  // row-major
  double mean_px = 0, max_px = 0, centre_px = 0;
};

UncertaintyMap projection_uncertainty(const rig::CameraModel& model,
                                      const Eigen::MatrixXd& intrinsics_cov, double distance_m,
                                      int cell_px = 40);

}  // namespace rigcal::camera
