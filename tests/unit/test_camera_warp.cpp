// The board's warp (doc/cameras.md, "Board warp"): simulated boards bent by a few millimetres,
// calibrated with the board taken as flat and with its warp solved.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>

#include "camera_truth.h"
#include "camera_warp.h"
#include "rigcal/camera/calibrate.h"
#include "rigcal/camera/detect.h"
#include "rigcal/camera/lens.h"
#include "rigcal/core/error.h"
#include "rigcal/io/sim_config.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/sim/session.h"

namespace rigcal::camera {

WarpRun warp_run(const Eigen::Vector2d& truth_m, uint64_t seed) {
  rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  rig::sensor(rig, "cam_l").camera.distortion_coeffs = {-0.0921, 0.0874, 0.00031, -0.00027};
  rig::sensor(rig, "cam_r").camera.distortion_coeffs = {-0.0897, 0.0832, -0.00019, 0.00042};
  sim::SimConfig cfg;
  cfg.seed = seed;
  cfg.board_warp_m = truth_m;
  const sim::StereoPart part = sim::simulate_stereo(rig, cfg);
  const std::vector<CameraInput> cams = detect_stereo(part, cfg.target);
  const SE3 T_r_l_true = rig::T_a_b(rig, "cam_r", "cam_l");
  WarpRun out;
  for (const bool solve_warp : {false, true}) {
    CalibrationOptions opt;
    opt.board_warp = solve_warp;
    const CalibrationResult r = calibrate(cfg.target, cams, opt);
    std::vector<double>& error = solve_warp ? out.warp_error : out.flat_error;
    std::vector<double>& sigma = solve_warp ? out.warp_sigma : out.flat_sigma;
    for (int c = 0; c < 2; ++c) {
      const std::vector<double> k_true =
          intrinsics_vector(rig::sensor(rig, c ? "cam_r" : "cam_l").camera);
      const std::vector<double> k_est = intrinsics_vector(r.cameras[c].model);
      for (int i = 0; i < 4; ++i) {
        error.push_back(k_est[i] - k_true[i]);
        sigma.push_back(r.cameras[c].stddev[i]);
      }
    }
    const double rotation_deg =
        rotation_vector(r.T_cam_cam0[1].R * T_r_l_true.R.transpose()).norm() * 180 / M_PI;
    (solve_warp ? out.warp_rotation_deg : out.flat_rotation_deg) = rotation_deg;
    (solve_warp ? out.warp_rms_px : out.flat_rms_px) = r.rms_2d_px;
    if (solve_warp) {
      EXPECT_TRUE(r.board_warp_m && r.board_warp_stddev_m);
      if (r.board_warp_m) out.warp_m = *r.board_warp_m, out.warp_sigma_m = *r.board_warp_stddev_m;
    } else {
      EXPECT_FALSE(r.board_warp_m);
    }
  }
  std::printf("seed %llu, board warp (%.2f, %.2f) mm: solved (%.3f ± %.3f, %.3f ± %.3f) mm\n",
              static_cast<unsigned long long>(seed), 1e3 * truth_m.x(), 1e3 * truth_m.y(),
              1e3 * out.warp_m.x(), 1e3 * out.warp_sigma_m.x(), 1e3 * out.warp_m.y(),
              1e3 * out.warp_sigma_m.y());
  const char* names[] = {"fx", "fy", "cx", "cy"};
  for (size_t i = 0; i < out.flat_error.size(); ++i) {
    std::printf(
        "  camera %zu %s: board flat %+.3f px (1-sigma %.3f), warp solved %+.3f px (%.3f)\n", i / 4,
        names[i % 4], out.flat_error[i], out.flat_sigma[i], out.warp_error[i], out.warp_sigma[i]);
  }
  std::printf("  stereo rotation %.4f deg flat, %.4f deg warp solved; RMS %.4f px flat, %.4f px\n",
              out.flat_rotation_deg, out.warp_rotation_deg, out.flat_rms_px, out.warp_rms_px);
  return out;
}

namespace {

// The simulator's warped board: the corners found in its images are the bent board's, not the
// flat one's (5 views, a warp exaggerated to 10 mm so the difference is plain), and the
// configuration key sets it.
TEST(SimStereo, AWarpedBoardsCornersAreWhereTheBentBoardPutsThem) {
  const rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  sim::SimConfig cfg;
  cfg.boards.views = 5;
  io::apply_sim_config("board_warp_mm: [10, -6]\n", "s.yaml", cfg);
  EXPECT_EQ(cfg.board_warp_m, Eigen::Vector2d(0.010, -0.006));
  EXPECT_THROW(io::apply_sim_config("board_warp_mm: 3\n", "s.yaml", cfg), Error);
  EXPECT_THROW(io::apply_sim_config("board_warp_mm: [1, 200]\n", "s.yaml", cfg), Error);
  const sim::StereoPart part = sim::simulate_stereo(rig, cfg);
  const rig::CameraModel& left = rig::sensor(rig, "cam_l").camera;
  const std::vector<Eigen::Vector3d> flat = object_points(cfg.target);
  double sse_bent = 0, sse_flat = 0;
  size_t n = 0;
  for (size_t k = 0; k < part.left.size(); ++k) {
    const Detection d = detect(part.left[k], cfg.target);
    for (size_t i = 0; i < d.pixels.size(); ++i) {
      const Eigen::Vector3d p_flat = flat[d.point_ids[i]];
      const Eigen::Vector3d p_bent = warped(cfg.target, p_flat, cfg.board_warp_m);
      // The written truth is the bent board's projection.
      EXPECT_LT(
          (*project(left, part.T_left_board[k] * p_bent) - part.corners_left[k][d.point_ids[i]])
              .norm(),
          1e-9);
      sse_bent += (d.pixels[i] - *project(left, part.T_left_board[k] * p_bent)).squaredNorm();
      sse_flat += (d.pixels[i] - *project(left, part.T_left_board[k] * p_flat)).squaredNorm();
      ++n;
    }
  }
  ASSERT_GT(n, 150u);
  const double rms_bent = std::sqrt(sse_bent / n), rms_flat = std::sqrt(sse_flat / n);
  std::printf(
      "detected corners of a board bent by (10, -6) mm: %.4f px RMS from the bent board's "
      "projection, %.4f px from the flat one's (%zu corners)\n",
      rms_bent, rms_flat, n);
  // As flat boards render (SimStereo.RenderedCornersMatchTruthToSubPixel: 0.077 px).
  EXPECT_LT(rms_bent, 0.12);
  EXPECT_GT(rms_flat, 5 * rms_bent);
}

// The A3 board (280 x 160 mm between its outer corners) bent by 4 mm along x and -2 mm along y.
// Taken as flat, the focal lengths come out 11-18 px (7-10 sigma) long and the stereo rotation
// 0.34 deg off, with an RMS ten times the noise: the bias the warp causes. With the warp solved,
// it is recovered to micrometres and every intrinsic is within 3 sigma of the truth.
TEST(CameraSim, AWarpedBoardIsRecoveredAndTheBiasItCausedGoes) {
  const Eigen::Vector2d truth(0.004, -0.002);
  const WarpRun w = warp_run(truth, 1);
  for (int a = 0; a < 2; ++a) {
    EXPECT_LE(std::abs(w.warp_m[a] - truth[a]), 3 * w.warp_sigma_m[a]) << "axis " << a;
    EXPECT_LT(w.warp_sigma_m[a], 0.02 * std::abs(truth[a])) << "axis " << a;
  }
  for (size_t i = 0; i < w.warp_error.size(); ++i)
    EXPECT_LE(std::abs(w.warp_error[i]), 3 * w.warp_sigma[i]) << "parameter " << i;
  // The bias of the flat model, which the warp removes: both focal lengths of both cameras.
  for (size_t i : {0, 1, 4, 5}) EXPECT_GT(std::abs(w.flat_error[i]), 5 * w.flat_sigma[i]) << i;
  EXPECT_GT(w.flat_rotation_deg, 0.1);
  EXPECT_LT(w.warp_rotation_deg, 0.03);
  EXPECT_GT(w.flat_rms_px, 5 * w.warp_rms_px);
}

}  // namespace
}  // namespace rigcal::camera
