#pragma once
// Shared by tests/unit/test_camera.cpp and tests/long/test_camera_long.cpp: one simulated
// calibration against truth, its errors in units of the reported 1-sigma.
#include <cstdint>
#include <vector>

#include "rigcal/rig/rig.h"

namespace rigcal::camera {

struct TruthZ {
  std::vector<double> parameters;  // fx fy cx cy of both cameras, the stereo rotation's 3 axes
  std::vector<double> projection;  // |projection error| / mrcal-style 1-sigma, 5 pixels a camera
  // The figures: worst of both cameras, and the stereo extrinsic's errors.
  double focal_rel = 0, principal_point_px = 0, baseline_m = 0, rotation_deg = 0;
  // The reported 1-sigmas behind the principal-point and rotation bars: cx, cy of each
  // camera (px), and the stereo rotation about each axis (deg).
  std::vector<double> principal_point_sigma_px;
  Eigen::Vector3d rotation_sigma_deg = Eigen::Vector3d::Zero();
};

// Every seed's figures are printed; nothing is asserted per seed.
TruthZ check_against_truth_for_long_test(rig::DistortionModel model, uint64_t seed);
// The same with the 6 x 6 AprilGrid (88 mm tags), radtan.
TruthZ check_aprilgrid_for_long_test(uint64_t seed);

}  // namespace rigcal::camera
