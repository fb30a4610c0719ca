// LiDAR-camera extrinsic (issue 8): the board found in simulated scans with clutter, its plane in
// the camera from the detected corners, and the plane-to-plane solve against the simulator's truth.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <tuple>

#include "fixtures.h"
#include "lidar_camera_sim.h"
#include "rigcal/camera/detect.h"
#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/io/point_cloud_io.h"
#include "rigcal/lidar_camera/board_lidar.h"
#include "rigcal/lidar_camera/solve.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/sim/session.h"

namespace rigcal::lidar_camera {
namespace {

double rotation_error_deg(const SE3& a, const SE3& b) {
  return rotation_angle(a.R * b.R.transpose()) * 180.0 / M_PI;
}

// Acceptance 2 and 1: 10 pairs with a person-sized box next to the board, seeds 1-3: the board is
// found in every scan; translation <= 5 mm, rotation and translation within 3 reported sigmas.
// The 0.1 deg rotation bar is a rate, not a per-seed promise (its 1-sigma about the camera's
// optical axis is 0.05-0.11 deg with 10 boards; 15 of 20 seeds in make test-long, which asserts at
// least 70 %, doc/lidar-camera.md): here at least 2 of the 3 seeds (seed 1: 0.039 deg).
TEST(LidarCameraSim, TenPairsWithClutter) {
  int rot_ok = 0;
  for (uint64_t seed = 1; seed <= 3; ++seed) {
    SCOPED_TRACE(seed);
    const testing::SimRun r = testing::simulate_and_solve(seed, 10, seed == 1);
    const Solution& s = r.solution;
    const double rot = rotation_error_deg(s.T_camera_lidar, r.truth);
    const Eigen::Vector3d e = s.T_camera_lidar.t - r.truth.t;
    std::printf(
        "seed %llu: found the board in %d of %d scans; closed form %.4f deg %.1f mm; refined %.4f "
        "deg (1-sigma %.4f %.4f %.4f), %.2f mm (%.2f %.2f %.2f; 1-sigma %.2f %.2f %.2f); noise "
        "scale %.2f; normals' condition %.1f\n",
        static_cast<unsigned long long>(seed), r.found, r.pairs,
        rotation_error_deg(s.closed_form, r.truth), 1e3 * (s.closed_form.t - r.truth.t).norm(), rot,
        s.rotation_sigma_deg[0], s.rotation_sigma_deg[1], s.rotation_sigma_deg[2], 1e3 * e.norm(),
        1e3 * e.x(), 1e3 * e.y(), 1e3 * e.z(), 1e3 * s.translation_sigma_m[0],
        1e3 * s.translation_sigma_m[1], 1e3 * s.translation_sigma_m[2], s.noise_scale,
        s.observability.condition);
    if (seed == 1) {
      for (const PairResidual& p : s.residuals) {
        std::printf("  normal %.3f deg, distance %.1f mm, points RMS %.1f mm%s\n",
                    p.normal_angle_deg, 1e3 * p.distance_m, 1e3 * p.point_rms_m,
                    p.outlier ? " (outlier)" : "");
      }
    }
    rot_ok += rot <= 0.1;
    EXPECT_EQ(r.found, r.pairs);
    EXPECT_LE(e.norm(), 0.005);
    const Eigen::Vector3d dr = rotation_vector(s.T_camera_lidar.R * r.truth.R.transpose());
    for (int i = 0; i < 3; ++i) {
      EXPECT_LE(std::abs(e[i]), 3 * s.translation_sigma_m[i]) << i;
      EXPECT_LE(std::abs(dr[i]) * 180 / M_PI, 3 * s.rotation_sigma_deg[i]) << i;
    }
  }
  EXPECT_GE(rot_ok, 2);
}

// The board's points are the board's: the stand's post just below the board (1-2 cm behind its
// plane, within the range noise) is not taken with it. The simulator knows which object each
// point hit; a post kept at the board's lower edge tilted the plane by ~0.1 deg (about the camera's
// x axis, in most seeds) before the strips spanning less than half the board were dropped.
TEST(LidarCameraSim, StandPostIsNotTakenAsBoard) {
  const rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  sim::SimConfig cfg;
  cfg.seed = 1;
  cfg.lidar_camera_pairs = 6;
  const sim::LidarCameraPart part = sim::simulate_lidar_camera(rig, cfg);
  const camera::Outline outline = camera::outline(cfg.target);
  int stand_points = 0, board_points = 0, pairs_with_stand_points = 0;
  for (size_t k = 0; k < part.scans.size(); ++k) {
    std::vector<Eigen::Vector3d> scan;
    std::map<std::tuple<float, float, float>, int> object;
    for (const sim::LidarPoint& p : part.scans[k]) {
      scan.push_back(p.p.cast<double>());
      object[{p.p.x(), p.p.y(), p.p.z()}] = p.object;
    }
    BoardSearch s;
    s.board_width_m = outline.width();
    s.board_height_m = outline.height();
    s.seed = k;
    const LidarBoard b = find_board(scan, s);
    ASSERT_TRUE(b.found) << k << ": " << b.reason;
    int stand = 0;
    for (const Eigen::Vector3d& x : b.points) {
      const Eigen::Vector3f f = x.cast<float>();
      stand += object.at({f.x(), f.y(), f.z()}) != 1;
    }
    std::printf("pair %zu: %zu board points, %d of them not on the board\n", k, b.points.size(),
                stand);
    stand_points += stand;
    board_points += static_cast<int>(b.points.size());
    pairs_with_stand_points += stand > 2;
  }
  // A few mixed returns at the post's junction may remain; whole rings across the post may not.
  EXPECT_LE(stand_points, board_points / 500);
  EXPECT_EQ(pairs_with_stand_points, 0);
}

// Acceptance 3, real data: ACFR's 11 pairs (Ouster 64-beam full scans, 1920 x 1208 fisheye images,
// a 7 x 5 chessboard of 95 mm squares on a 610 x 850 mm backing board mounted as a diamond). The
// board is found in every scan without clicks; the extrinsic is compared with the source's own
// (the mean of its 50 optimised sets, T_lidar_camera as roll, pitch, yaw, x, y, z), and both are
// scored on the same planes.
TEST(LidarCameraReal, AcfrBoardFoundInEveryScanAndSourceCompared) {
  RIGCAL_REQUIRE_FIXTURE(dir, "lidar_camera/acfr/2022-11-09_00-54-42");
  rig::CameraModel cam;  // cfg/camera_info.yaml of the fixture
  cam.fx = 959.554, cam.fy = 960.194, cam.cx = 940.789, cam.cy = 670.737;
  cam.distortion_model = rig::DistortionModel::equidistant;
  cam.distortion_coeffs = {-0.097824, 0.141429, -0.148385, 0.055918};
  cam.width = 1920, cam.height = 1208;
  camera::Target target;
  target.name = "acfr";
  target.cols = 7, target.rows = 5, target.square = 0.095;
  std::vector<PairInput> in;
  for (int k = 1; k <= 11; ++k) {
    PairInput p;
    const cv::Mat img =
        cv::imread(fmt::format("{}/images/pose{}.png", dir, k), cv::IMREAD_GRAYSCALE);
    const camera::Detection det = camera::detect(img, target);
    ASSERT_TRUE(det.found) << "pose" << k << ": " << det.note;
    p.camera = board_in_camera(cam, target, det.pixels);
    p.scan = io::read_point_cloud(fmt::format("{}/pcd/pose{}_full.pcd", dir, k));
    in.push_back(std::move(p));
  }
  BoardSearch search;
  search.board_width_m = 0.61, search.board_height_m = 0.85;
  const Calibration c = calibrate(in, search);
  int found = 0;
  for (const PairOutcome& o : c.pairs) found += o.used;
  EXPECT_EQ(found, 11);
  // The source's answer: the mean of the rows of its calibration CSV.
  std::ifstream csv(dir + "/calibration_2022-11-09_01-02-13.csv");
  std::string line;
  std::getline(csv, line);  // header
  Eigen::Matrix<double, 6, 1> mean = Eigen::Matrix<double, 6, 1>::Zero();
  int rows = 0;
  while (std::getline(csv, line)) {
    const std::vector<std::string_view> f = split_fields(line);
    if (f.size() != 6) continue;
    for (int i = 0; i < 6; ++i) mean[i] += parse_double(f[i], "csv");
    ++rows;
  }
  ASSERT_EQ(rows, 50);
  mean /= rows;
  SE3 T_lidar_camera_src;
  T_lidar_camera_src.R = from_roll_pitch_yaw(mean[0], mean[1], mean[2]);
  T_lidar_camera_src.t = mean.tail<3>();
  const SE3 ours = c.solution.T_camera_lidar.inverse();
  const double drot = rotation_angle(ours.R * T_lidar_camera_src.R.transpose()) * 180 / M_PI;
  const Eigen::Vector3d dt = ours.t - T_lidar_camera_src.t;
  std::vector<BoardPair> used;
  for (size_t k = 0; k < in.size(); ++k) {
    if (c.pairs[k].used)
      used.push_back({in[k].camera->plane, c.pairs[k].lidar.plane, c.pairs[k].lidar.points});
  }
  auto summary = [](const std::vector<PairResidual>& r) {
    double a = 0, d = 0, p = 0;
    for (const PairResidual& x : r) {
      a += x.normal_angle_deg * x.normal_angle_deg, d += x.distance_m * x.distance_m;
      p += x.point_rms_m * x.point_rms_m;
    }
    const double n = static_cast<double>(r.size());
    return fmt::format("normal angle RMS {:.3f} deg, distance RMS {:.1f} mm, points RMS {:.1f} mm",
                       std::sqrt(a / n), 1e3 * std::sqrt(d / n), 1e3 * std::sqrt(p / n));
  };
  std::printf(
      "ACFR: board in %d of 11 scans; T_lidar_camera rigcal t (%.4f %.4f %.4f) m, source mean "
      "(%.4f %.4f %.4f); difference %.3f deg, %.1f mm (%.1f %.1f %.1f); rigcal 1-sigma %.3f %.3f "
      "%.3f deg, %.1f %.1f %.1f mm\n  residuals, rigcal: %s\n  residuals, source: %s\n",
      found, ours.t.x(), ours.t.y(), ours.t.z(), T_lidar_camera_src.t.x(), T_lidar_camera_src.t.y(),
      T_lidar_camera_src.t.z(), drot, 1e3 * dt.norm(), 1e3 * dt.x(), 1e3 * dt.y(), 1e3 * dt.z(),
      c.solution.rotation_sigma_deg[0], c.solution.rotation_sigma_deg[1],
      c.solution.rotation_sigma_deg[2], 1e3 * c.solution.translation_sigma_m[0],
      1e3 * c.solution.translation_sigma_m[1], 1e3 * c.solution.translation_sigma_m[2],
      summary(c.solution.residuals).c_str(),
      summary(residuals_at(used, T_lidar_camera_src.inverse())).c_str());
  EXPECT_LT(drot, 2.0);
  EXPECT_LT(dt.norm(), 0.05);
  // Many of these pairs are outliers (6 of 11 when the issue was filed): the step says
  // so as a warning rather than passing it silently.
  int outliers = 0;
  for (const PairResidual& r : c.solution.residuals) outliers += r.outlier;
  const std::vector<std::string> warnings = outlier_warnings(c.solution);
  std::printf("ACFR: %d outlier pairs of %zu; warning: %s\n", outliers, c.solution.residuals.size(),
              warnings.empty() ? "none" : warnings[0].c_str());
  EXPECT_GT(3 * outliers, static_cast<int>(c.solution.residuals.size()));  // 6 of 11 when found
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0].rfind(fmt::format("{} of the {} pairs used are outliers", outliers,
                                          c.solution.residuals.size()),
                              0),
            0u);
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
