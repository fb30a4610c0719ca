#pragma once
// Shared by tests/unit/test_camera_warp.cpp and tests/long/test_camera_long.cpp: one simulated
// calibration of a warped (or flat) A3 board, solved with the board taken as flat and with its
// warp, against truth.
#include <cstdint>
#include <vector>

#include "rigcal/core/se3.h"

namespace rigcal::camera {

struct WarpRun {
  // fx fy cx cy of both cameras: estimate minus truth, and the reported 1-sigma, px; for the board
  // taken as flat and for the warp solved.
  std::vector<double> flat_error, flat_sigma, warp_error, warp_sigma;
  double flat_rotation_deg = 0, warp_rotation_deg = 0;  // the stereo rotation's error
  double flat_rms_px = 0, warp_rms_px = 0;              // 2-D RMS of the inlier corners
  Eigen::Vector2d warp_m = Eigen::Vector2d::Zero(), warp_sigma_m = Eigen::Vector2d::Zero();
};

// The simulator's default stereo session (40 views, radtan) with the board warped by truth_m.
WarpRun warp_run(const Eigen::Vector2d& truth_m, uint64_t seed);

}  // namespace rigcal::camera
