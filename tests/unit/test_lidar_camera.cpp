// LiDAR-camera extrinsic (issue 8): the board found in simulated scans with clutter, its plane in
// the camera from the detected corners, and the plane-to-plane solve against the simulator's truth.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "lidar_camera_sim.h"
#include "rigcal/camera/detect.h"
#include "rigcal/core/error.h"
#include "rigcal/lidar_camera/board_lidar.h"
#include "rigcal/lidar_camera/solve.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/sim/session.h"

namespace rigcal::lidar_camera {
namespace {

double rotation_error_deg(const SE3& a, const SE3& b) {
  return rotation_angle(a.R * b.R.transpose()) * 180.0 / M_PI;
}

// Acceptance 1 and 2 (seed 1): 10 pairs with a person-sized box next to the board: the board is
// found in every pair, rotation <= 0.1 deg, translation <= 5 mm, within 3 reported sigmas.
TEST(LidarCameraSim, TenPairsWithClutter) {
  const testing::SimRun r = testing::simulate_and_solve(1);
  const Solution& s = r.solution;
  const double rot = rotation_error_deg(s.T_camera_lidar, r.truth);
  const Eigen::Vector3d e = s.T_camera_lidar.t - r.truth.t;
  std::printf(
      "found the board in %d of %d scans; closed form %.4f deg %.1f mm; refined %.4f deg (1-sigma "
      "%.4f %.4f %.4f), %.2f mm (%.2f %.2f %.2f; 1-sigma %.2f %.2f %.2f); noise scale %.2f; "
      "normals' condition %.1f\n",
      r.found, r.pairs, rotation_error_deg(s.closed_form, r.truth),
      1e3 * (s.closed_form.t - r.truth.t).norm(), rot, s.rotation_sigma_deg[0],
      s.rotation_sigma_deg[1], s.rotation_sigma_deg[2], 1e3 * e.norm(), 1e3 * e.x(), 1e3 * e.y(),
      1e3 * e.z(), 1e3 * s.translation_sigma_m[0], 1e3 * s.translation_sigma_m[1],
      1e3 * s.translation_sigma_m[2], s.noise_scale, s.observability.condition);
  for (const PairResidual& p : s.residuals) {
    std::printf("  normal %.3f deg, distance %.1f mm, points RMS %.1f mm%s\n", p.normal_angle_deg,
                1e3 * p.distance_m, 1e3 * p.point_rms_m, p.outlier ? " (outlier)" : "");
  }
  EXPECT_EQ(r.found, r.pairs);
  EXPECT_LE(rot, 0.1);
  EXPECT_LE(e.norm(), 0.005);
  for (int i = 0; i < 3; ++i) EXPECT_LE(std::abs(e[i]), 3 * s.translation_sigma_m[i]) << i;
}

// Acceptance 4: parallel boards or two pairs: a clear message, no calibration.
TEST(LidarCameraSolve, DegenerateInputIsRefused) {
  BoardPair p;
  p.camera.n = p.lidar.n = Eigen::Vector3d(0, 0, 1);
  p.camera.d = 3, p.lidar.d = 3.1;
  p.camera.covariance = p.lidar.covariance = Eigen::Matrix3d::Identity() * 1e-6;
  try {
    solve({p, p});
    ADD_FAILURE() << "two pairs accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("at least 3"), std::string::npos) << e.what();
  }
  BoardPair q = p, s = p;
  q.camera.n = q.lidar.n = Eigen::Vector3d(0.05, 0, 1).normalized();
  s.camera.n = s.lidar.n = Eigen::Vector3d(0, 0.04, 1).normalized();
  try {
    solve({p, q, s, p});
    ADD_FAILURE() << "near-parallel boards accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("do not span space"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rigcal::lidar_camera
