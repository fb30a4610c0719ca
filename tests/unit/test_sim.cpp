// The simulator against its own truth and against independent measurements: OpenCV's detectors
// on the rendered images, planes, integration of the IMU signals, a brute-force clock offset.
#include <gtest/gtest.h>

#include <opencv2/aruco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <set>

#include "rigcal/camera/detect.h"
#include "rigcal/camera/lens.h"
#include "rigcal/core/error.h"
#include "rigcal/core/trajectory.h"
#include "rigcal/io/sim_config.h"
#include "rigcal/io/target_yaml.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/sim/session.h"

extern "C" {
#include <apriltag/tag36h11.h>
}

namespace rigcal::sim {
namespace {

rig::Rig sample_rig() { return rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml"); }

TEST(SimLens, ProjectAndUnprojectInvertEachOther) {
  rig::Rig rig = sample_rig();
  for (const rig::DistortionModel model :
       {rig::DistortionModel::radtan, rig::DistortionModel::equidistant}) {
    rig::CameraModel cam = rig::sensor(rig, "cam_l").camera;
    cam.distortion_model = model;
    if (model == rig::DistortionModel::equidistant)
      cam.distortion_coeffs = {0.05, -0.01, 0.002, -0.0004};
    for (double u = 0; u < cam.width; u += 97) {
      for (double v = 0; v < cam.height; v += 61) {
        const Eigen::Vector2d xn = camera::unproject(cam, Eigen::Vector2d(u, v));
        const Eigen::Vector2d back =
            *camera::project(cam, Eigen::Vector3d(xn.x(), xn.y(), 1.0) * 3.0);
        EXPECT_LT((back - Eigen::Vector2d(u, v)).norm(), 1e-8) << u << " " << v;
      }
    }
  }
  // radtan by hand at one point: OpenCV's formula.
  rig::CameraModel c;
  c.fx = 500, c.fy = 400, c.cx = 300, c.cy = 200;
  c.distortion_coeffs = {0.1, -0.05, 0.001, 0.002, 0.01};
  const double x = 0.3, y = -0.2, r2 = x * x + y * y;
  const double radial = 1 + 0.1 * r2 - 0.05 * r2 * r2 + 0.01 * r2 * r2 * r2;
  const double xd = x * radial + 2 * 0.001 * x * y + 0.002 * (r2 + 2 * x * x);
  const double yd = y * radial + 0.001 * (r2 + 2 * y * y) + 2 * 0.002 * x * y;
  EXPECT_LT((*camera::project(c, Eigen::Vector3d(x, y, 1)) -
             Eigen::Vector2d(500 * xd + 300, 400 * yd + 200))
                .norm(),
            1e-12);
}

TEST(SimTargets, KalibrFilesAndTagCodes) {
  const camera::Target grid =
      io::read_target_file(RIGCAL_SOURCE_DIR "/targets/aprilgrid_6x6_88mm.yaml");
  EXPECT_EQ(grid.type, camera::TargetType::aprilgrid);
  EXPECT_EQ(camera::object_points(grid).size(), 144u);
  const camera::Target board =
      io::read_target_file(RIGCAL_SOURCE_DIR "/targets/a3_checkerboard_8x5_40mm.yaml");
  EXPECT_EQ(camera::object_points(board).size(), 40u);
  EXPECT_NEAR(camera::outline(board).width(), 0.416, 1e-12);
  EXPECT_THROW(io::parse_target_yaml("target_type: circles\n", "t.yaml"), Error);
  EXPECT_THROW(io::parse_target_yaml("target_type: aprilgrid\ntagCols: 6\n", "t.yaml"), Error);
  // Every tag of the printed grid carries its tag36h11 code: sample the 6 x 6 data cells, rotate
  // them back by 180 degrees (OpenCV's reading order) and compare with AprilTag's code words.
  const camera::Pattern pattern(grid);
  apriltag_family_t* family = tag36h11_create();
  const double pitch = grid.tag_size * (1 + grid.tag_spacing), cell = grid.tag_size / 10;
  for (int id = 0; id < 36; ++id) {
    const double x0 = (id % 6) * pitch, y0 = (id / 6) * pitch;
    for (uint32_t i = 0; i < family->nbits; ++i) {
      const int col = 6 - static_cast<int>(family->bit_x[i]) + 2,
                row = 6 - static_cast<int>(family->bit_y[i]) + 2;
      const double x = x0 + (col + 0.5) * cell, y = y0 + grid.tag_size - (row + 0.5) * cell;
      const bool white = (family->codes[id] >> (family->nbits - 1 - i)) & 1ULL;
      ASSERT_EQ(pattern.albedo(x, y), white ? 1.0 : 0.0) << "tag " << id << " bit " << i;
    }
    EXPECT_EQ(pattern.albedo(x0 + 0.5 * cell, y0 + 0.5 * cell), 0.0);  // the 2-cell black border
    EXPECT_EQ(pattern.albedo(x0 - 0.5 * grid.tag_spacing * grid.tag_size,
                             y0 - 0.5 * grid.tag_spacing * grid.tag_size),
              0.0);  // corner square
  }
  tag36h11_destroy(family);
}

// Rendered checkerboards against the written truth, measured by OpenCV's detector
// (findChessboardCornersSB) and cornerSubPix with a window from the observed square size.
TEST(SimStereo, RenderedCornersMatchTruthToSubPixel) {
  const rig::Rig rig = sample_rig();
  SimConfig cfg;
  cfg.boards.views = 9;
  const StereoPart part = simulate_stereo(rig, cfg);
  ASSERT_EQ(part.left.size(), 9u);
  double sse = 0.0;
  size_t n = 0, detected = 0;
  for (size_t k = 0; k < part.left.size(); ++k) {
    for (int side = 0; side < 2; ++side) {
      const cv::Mat& img = side == 0 ? part.left[k] : part.right[k];
      const auto& truth = side == 0 ? part.corners_left[k] : part.corners_right[k];
      EXPECT_EQ(img.cols, 1388);
      EXPECT_EQ(img.rows, 700);
      // rigcal's detector: OpenCV's findChessboardCornersSB on a probe (and at full resolution
      // when that fails), then cornerSubPix with a window from the observed square size.
      const camera::Detection d = camera::detect(img, cfg.target);
      if (!d.found) continue;
      ++detected;
      for (size_t i = 0; i < d.pixels.size(); ++i) {
        sse += (d.pixels[i] - truth[d.point_ids[i]]).squaredNorm();
        ++n;
      }
    }
  }
  EXPECT_GE(detected, 16u) << "of 18 images";
  const double rms = std::sqrt(sse / n);
  std::printf("rendered corners vs truth: %.4f px RMS over %zu corners of %zu images\n", rms, n,
              detected);
  RecordProperty("corner_rms_px", std::to_string(rms));
  EXPECT_LT(rms, 0.12) << "OpenCV corners vs truth";
  // The truth is the projection of the object points through the true model and pose.
  const rig::Sensor& left = rig::sensor(rig, "cam_l");
  const std::vector<Eigen::Vector3d> pts = camera::object_points(cfg.target);
  for (size_t i = 0; i < pts.size(); ++i) {
    EXPECT_LT(
        (*camera::project(left.camera, part.T_left_board[3] * pts[i]) - part.corners_left[3][i])
            .norm(),
        1e-12);
  }
}

TEST(SimStereo, AprilGridsDecodeWithCorrectIdsAndOrientation) {
  const rig::Rig rig = sample_rig();
  SimConfig cfg;
  cfg.target = io::read_target_file(RIGCAL_SOURCE_DIR "/targets/aprilgrid_6x6_88mm.yaml");
  cfg.boards.views = 4;
  cfg.boards.min_fill = 0.35;
  const StereoPart part = simulate_stereo(rig, cfg);
  auto dict = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_APRILTAG_36h11);
  auto params = cv::aruco::DetectorParameters::create();
  params->markerBorderBits = 2;
  params->minMarkerDistanceRate = 0.01;  // Kalibr grids: neighbours are 0.3 tag sizes apart
  size_t detected = 0, correct_first_corner = 0;
  for (size_t k = 0; k < part.left.size(); ++k) {
    std::vector<int> ids;
    std::vector<std::vector<cv::Point2f>> corners;
    cv::aruco::detectMarkers(part.left[k], dict, corners, ids, params);
    for (size_t i = 0; i < ids.size(); ++i) {
      ASSERT_LT(ids[i], 36) << "a tag decoded with a wrong id";
      ++detected;
      // aruco's first corner is the tag's printed top left: of the tag's four Kalibr points,
      // (2c, 2r + 1) must be the nearest.
      const int c = ids[i] % 6, r = ids[i] / 6;
      const Eigen::Vector2d first(corners[i][0].x, corners[i][0].y);
      int nearest = -1;
      double best = INFINITY;
      for (int q = 0; q < 4; ++q) {
        const double d =
            (first - part.corners_left[k][(2 * r + q / 2) * 12 + 2 * c + q % 2]).norm();
        if (d < best) best = d, nearest = q;
      }
      correct_first_corner += nearest == 2;  // q = 2: (dm 0, dn 1)
    }
  }
  // Stock aruco decodes 96 of the 144 tags here (seed 1): a floor that a broken pattern fails.
  // Raising the detection rate on Kalibr grids is the camera step's work, not the simulator's.
  EXPECT_GE(detected, 4u * 36u * 6 / 10);
  EXPECT_GE(correct_first_corner, detected * 95 / 100);
}

TEST(SimLidar, BoardPointsLieOnTheTruePlaneWithinTheRangeNoise) {
  const rig::Rig rig = sample_rig();
  SimConfig cfg;
  cfg.lidar_camera_pairs = 4;
  const LidarCameraPart part = simulate_lidar_camera(rig, cfg);
  for (size_t k = 0; k < part.scans.size(); ++k) {
    const SE3& T = part.T_lidar_board[k];
    const Eigen::Vector3d n = T.R.col(2);
    double sse = 0.0;
    size_t on_board = 0, others = 0;
    for (const LidarPoint& p : part.scans[k]) {
      if (p.object != 1) {
        others += p.object == 2;  // the clutter box is there too
        continue;
      }
      const double d = n.dot(p.p.cast<double>() - T.t);
      if (d > 0.5 * cfg.target.thickness) continue;  // edge hits on the board's thickness
      sse += d * d;
      ++on_board;
    }
    ASSERT_GT(on_board, 200u) << "pair " << k;
    EXPECT_GT(others, 0u);
    const double rms = std::sqrt(sse / on_board);
    // Range noise is along the ray: its component along the normal is smaller.
    EXPECT_LT(rms, 1.1 * cfg.lidar.range_noise_m) << "pair " << k;
    EXPECT_GT(rms, 0.3 * cfg.lidar.range_noise_m) << "pair " << k;
  }
}

// The sweep tests only the rectangles within range, nearest first, by azimuth sector: the same
// points as casting every beam against every rectangle (the later rectangle winning ties), on a
// courtyard along a walk and on the board's room, where ties decide which face a point is on.
TEST(SimLidar, TheCulledSweepIsTheSweepOfEveryRectangle) {
  const rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  sim::SimConfig config;
  config.trajectory_duration_s = 2;
  config.trajectory_motion = sim::MotionKind::walk;
  config.lidar.columns = 256;
  const sim::TrajectoryPart part = sim::simulate_trajectories(rig, config);
  const sim::SweepDrive drive = sim::trajectory_drive(rig, config, part);
  // Every beam against every rectangle, in the scene's order: the reference.
  auto reference = [](const sim::Scene& scene, const sim::LidarModel& m,
                      const std::function<SE3(double)>& T_world_lidar, double t0) {
    std::vector<std::pair<Eigen::Vector3f, int>> out;
    for (int c = 0; c < m.columns; ++c) {
      const SE3 T = T_world_lidar(t0 + c / (m.rate_hz * m.columns));
      const double azimuth = 2.0 * M_PI * (1.0 - static_cast<double>(c) / m.columns);
      for (int b = 0; b < m.beams; ++b) {
        const double e =
            (0.5 * m.vertical_fov_deg - m.vertical_fov_deg * b / std::max(1, m.beams - 1)) * M_PI /
            180.0;
        const Eigen::Vector3d d_lidar(std::cos(e) * std::cos(azimuth),
                                      std::cos(e) * std::sin(azimuth), std::sin(e));
        const Eigen::Vector3d d = T.R * d_lidar;
        double best = m.max_range_m;
        int hit = -1;
        for (size_t i = 0; i < scene.rects.size(); ++i) {
          const sim::Rect& r = scene.rects[i];
          const Eigen::Vector3d n = r.u.cross(r.v);
          if (std::abs(n.dot(d)) < 1e-12) continue;
          const double s = n.dot(r.centre - T.t) / n.dot(d);
          if (s < m.min_range_m || s > best) continue;
          const Eigen::Vector3d q = T.t + s * d - r.centre;
          if (std::abs(q.dot(r.u)) > r.half_u || std::abs(q.dot(r.v)) > r.half_v) continue;
          best = s;
          hit = int(i);
        }
        if (hit >= 0) out.push_back({(best * d_lidar).cast<float>(), hit});
      }
    }
    return out;
  };
  auto check = [&](const sim::Scene& scene, const sim::LidarModel& m,
                   const std::function<SE3(double)>& T_world_lidar, double t0) {
    sim::LidarModel exact = m;
    exact.range_noise_m = 0;
    std::mt19937_64 rng(1);
    const std::vector<sim::LidarPoint> culled = sim::sweep(scene, exact, T_world_lidar, t0, rng);
    const auto all = reference(scene, exact, T_world_lidar, t0);
    ASSERT_EQ(culled.size(), all.size());
    ASSERT_GT(all.size(), 1000u);
    size_t same = 0;
    for (size_t i = 0; i < all.size(); ++i)
      same += culled[i].p == all[i].first && culled[i].object == scene.rects[all[i].second].id;
    EXPECT_EQ(same, all.size());
  };
  check(drive.scene, drive.lidar, drive.T_world_lidar, 0.5);
  // The board's room: its front face wins the tie with its box's front face.
  sim::SimConfig board_config;
  board_config.lidar.columns = 256;
  sim::Scene room;
  sim::add_room(room, 4, 5, -1.2, 2.2);
  const camera::Target target = sim::default_target();
  const camera::Pattern pattern(target);
  SE3 T_world_board;
  T_world_board.R = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T_world_board.t = Eigen::Vector3d(2.0, -0.2, 0.0);
  sim::add_board(room, target, pattern, T_world_board, -1.2, 1);
  check(
      room, board_config.lidar, [](double) { return SE3(); }, 0.0);
}

TEST(SimImu, SignalsIntegrateBackToTheTrueMotion) {
  std::mt19937_64 rng(5);
  const Motion motion = random_motion(MotionKind::handheld, 12.0, rng);
  const SE3 T_base_imu =
      SE3::from_rotation_vector(Eigen::Vector3d(0.2, -0.3, 0.5), Eigen::Vector3d(0.1, -0.05, 0.2));
  // Integrate the ideal IMU (RK4 on rotation and velocity, 1 ms) for 10 s from the true state.
  const double dt = 1e-3, t_end = 10.0;
  MotionState s0 = evaluate(motion, 0.0);
  Eigen::Matrix3d R = s0.T_world_base.R * T_base_imu.R;
  Eigen::Vector3d p = s0.T_world_base * T_base_imu.t;
  Eigen::Vector3d v = s0.v_world + s0.T_world_base.R * s0.omega_base.cross(T_base_imu.t);
  auto deriv = [&](double t, const Eigen::Matrix3d& Rt) {
    const auto [w, f] = ideal_imu(motion, T_base_imu, t);
    return std::pair<Eigen::Matrix3d, Eigen::Vector3d>(Rt * skew(w), Rt * f + kGravityWorld);
  };
  for (double t = 0.0; t < t_end - 1e-9; t += dt) {
    const auto [dR1, a1] = deriv(t, R);
    const Eigen::Matrix3d R2 = R + 0.5 * dt * dR1;
    const auto [dR2, a2] = deriv(t + 0.5 * dt, R2);
    const Eigen::Matrix3d R3 = R + 0.5 * dt * dR2;
    const auto [dR3, a3] = deriv(t + 0.5 * dt, R3);
    const Eigen::Matrix3d R4 = R + dt * dR3;
    const auto [dR4, a4] = deriv(t + dt, R4);
    p += dt * v + dt * dt / 6.0 * (a1 + a2 + a3);
    v += dt / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4);
    R = nearest_rotation(R + dt / 6.0 * (dR1 + 2 * dR2 + 2 * dR3 + dR4));
  }
  const MotionState s1 = evaluate(motion, t_end);
  EXPECT_LT((p - s1.T_world_base * T_base_imu.t).norm(), 0.01);  // 1 cm after 10 s of walking
  EXPECT_LT(rotation_angle(R.transpose() * s1.T_world_base.R * T_base_imu.R) * 180 / M_PI, 0.01);
}

TEST(SimImu, NoiseHasTheConfiguredDensityAndStampsFollowTheClock) {
  std::mt19937_64 rng(6);
  const Motion motion = random_motion(MotionKind::handheld, 61.0, rng);
  rig::ImuSpec spec;
  spec.gyroscope_noise_density = 2e-3;
  spec.gyroscope_random_walk = 1e-9;  // ~no bias motion, to measure the white noise
  spec.accelerometer_noise_density = 2e-2;
  spec.accelerometer_random_walk = 1e-9;
  ImuSimConfig cfg;
  cfg.rate_hz = 200;
  cfg.time_offset_s = 0.25;
  cfg.gaps = {{10.0, 13.0}};
  const SE3 T_base_imu;
  const auto samples =
      simulate_imu(motion, T_base_imu, spec, cfg, Time::from_seconds(1000), 60.0, rng);
  std::vector<double> gyro_err, accel_err;
  Eigen::Vector3d gyro_mean = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> g;
  for (const ImuSample& s : samples) {
    const double t = s.stamp.seconds() + 0.25 - 1000.0;  // t_base = t_stamp + offset
    EXPECT_FALSE(t >= 10.0 && t < 13.0) << "a sample inside the gap";
    const auto [w, f] = ideal_imu(motion, T_base_imu, t);
    g.push_back(s.gyro - w);
    gyro_mean += s.gyro - w;
    accel_err.push_back((s.accel - f).x());
  }
  gyro_mean /= g.size();
  double var = 0.0;
  for (const Eigen::Vector3d& e : g) var += (e.x() - gyro_mean.x()) * (e.x() - gyro_mean.x());
  const double std_x = std::sqrt(var / g.size());
  EXPECT_NEAR(std_x, 2e-3 * std::sqrt(200.0), 0.05 * 2e-3 * std::sqrt(200.0));
  EXPECT_NEAR(samples.size(), 57 * 200, 3);
}

// The two IMU streams carry the rig's clock offsets: a brute-force search over the offset
// (0.1 ms steps, angular-velocity norms, linear interpolation) finds the true difference.
TEST(SimImu, TheWrittenClockOffsetIsRecoverableByBruteForce) {
  rig::Rig rig = sample_rig();
  rig::sensor(rig, "imu").time_offset = 0.0373;
  rig::sensor(rig, "os_imu").time_offset = -0.0121;
  SimConfig cfg;
  cfg.imu_duration_s = 40.0;
  const ImuPart part = simulate_imu_part(rig, cfg);
  // Put both on the base clock with a trial offset for os_imu only: t = stamp + offset.
  auto norm_at = [](const std::vector<ImuSample>& s, double t, double offset) -> double {
    const double first = s.front().stamp.seconds() + offset;
    const double k = (t - first) * 100.0;
    if (k < 0) return std::nan("");  // before converting: a negative double to size_t is UB
    const size_t i = static_cast<size_t>(k);
    if (i + 1 >= s.size()) return std::nan("");
    const double f = k - i;
    return (1 - f) * s[i].gyro.norm() + f * s[i + 1].gyro.norm();
  };
  double best = 0, best_cost = INFINITY;
  for (double offset = -0.1; offset <= 0.1; offset += 1e-4) {
    double cost = 0;
    for (const ImuSample& a : part.imu) {
      const double t = a.stamp.seconds() + 0.0373;
      const double b = norm_at(part.os_imu, t, offset);
      if (!std::isnan(b)) cost += (a.gyro.norm() - b) * (a.gyro.norm() - b);
    }
    if (cost < best_cost) best_cost = cost, best = offset;
  }
  EXPECT_NEAR(best, -0.0121, 5e-4);
}

TEST(SimTrajectories, OdometryDriftsSlowlyAndGnssHasOutagesAndFlaggedOutliers) {
  const rig::Rig rig = sample_rig();
  SimConfig cfg;
  cfg.trajectory_duration_s = 120;
  cfg.gnss.outages = {{30.0, 50.0}};
  cfg.gnss.outlier_probability = 0.01;
  const TrajectoryPart part = simulate_trajectories(rig, cfg);
  EXPECT_EQ(part.truth_base.size(), 1201u);  // 10 Hz
  EXPECT_EQ(part.odometry.size(), 1201u);
  // Odometry: relative motions close to the truth over 1 s (1 % scale noise allowed).
  for (size_t k = 10; k < part.odometry.size(); k += 97) {
    const SE3 d_true =
        part.truth_base.T_world_body[k - 10].inverse() * part.truth_base.T_world_body[k];
    const SE3 d_odom = part.odometry.T_world_body[k - 10].inverse() * part.odometry.T_world_body[k];
    EXPECT_LT((d_true.t - d_odom.t).norm(), 0.02 + 0.01 * d_true.t.norm());
  }
  // GNSS: none in the outage; outliers far off, the rest within 5 sigma of the truth.
  const SE3& T_base_gnss = rig::sensor(rig, "gnss").T_base_sensor;
  const double offset = rig::sensor(rig, "gnss").time_offset;
  std::set<size_t> outliers(part.gnss_outliers.begin(), part.gnss_outliers.end());
  EXPECT_GT(outliers.size(), 3u);
  for (size_t i = 0; i < part.gnss.size(); ++i) {
    const double t = part.gnss.stamps[i].seconds() + offset - cfg.base_start_s;
    EXPECT_FALSE(t >= 30.0 && t < 50.0);
    // The true GNSS pose from the truth trajectory at the LiDAR rate, interpolated.
    const size_t j = std::min<size_t>(static_cast<size_t>(t * 10), part.truth_base.size() - 2);
    const double f = t * 10 - j;
    const SE3 T_truth =
        part.T_enu_world *
        interpolate(part.truth_base.T_world_body[j], part.truth_base.T_world_body[j + 1], f) *
        T_base_gnss;
    const double err = (T_truth.t - part.gnss.T_world_body[i].t).norm();
    if (outliers.count(i)) {
      EXPECT_GT(err, 0.3) << i;
    } else {
      EXPECT_LT(err, 0.2) << i;  // 5 sigma of 2-3 cm, plus interpolation of a 10 Hz truth
    }
  }
}

// Spans of float and of single fixes: their states recorded, their errors at their own sigmas,
// and every other fix exactly as without them (they change no random draw).
TEST(SimTrajectories, FloatAndSingleFixesHaveTheirSigmasAndChangeNothingElse) {
  const rig::Rig rig = sample_rig();
  SimConfig cfg;
  cfg.trajectory_duration_s = 100;
  cfg.gnss.outlier_probability = 0;
  const TrajectoryPart plain = simulate_trajectories(rig, cfg);
  io::apply_sim_config(
      "trajectories:\n  gnss:\n    float_fixes: [[20, 50]]\n    single_fixes: [[60, 80], [45, "
      "50]]\n    float_horizontal_sigma_m: 0.25\n",
      "s.yaml", cfg);
  EXPECT_DOUBLE_EQ(cfg.gnss.single_horizontal_sigma_m, 1.5);  // the default
  const TrajectoryPart part = simulate_trajectories(rig, cfg);
  ASSERT_EQ(part.gnss.size(), plain.gnss.size());
  ASSERT_EQ(part.gnss_states.size(), part.gnss.size());
  ASSERT_EQ(part.gnss_std_enu_m.size(), part.gnss.size());
  const SE3& T_base_gnss = rig::sensor(rig, "gnss").T_base_sensor;
  const double offset = rig::sensor(rig, "gnss").time_offset;
  double sum2[3][3] = {}, count[3] = {};
  for (size_t i = 0; i < part.gnss.size(); ++i) {
    const double t = part.gnss.stamps[i].seconds() + offset - cfg.base_start_s;
    const FixState expected = (t >= 60 && t < 80) || (t >= 45 && t < 50) ? FixState::single
                              : t >= 20 && t < 50                        ? FixState::rtk_float
                                                                         : FixState::rtk_fixed;
    ASSERT_EQ(part.gnss_states[i], expected) << t;
    const auto [h, v] = fix_sigmas(cfg.gnss, expected);
    EXPECT_EQ(part.gnss_std_enu_m[i], Eigen::Vector3d(h, h, v));
    if (expected == FixState::rtk_fixed) {
      EXPECT_EQ(part.gnss.T_world_body[i].t, plain.gnss.T_world_body[i].t) << t;
    }
    const Eigen::Vector3d e =
        part.gnss.T_world_body[i].t - (part.T_enu_world * part.source(t) * T_base_gnss).t;
    const int s = static_cast<int>(expected);
    for (int a = 0; a < 3; ++a) sum2[s][a] += e(a) * e(a);
    ++count[s];
  }
  // White errors (no correlation time): thousands of fixes in each state, their rms within 10 %.
  const double sigma[3][3] = {{0.02, 0.02, 0.03}, {0.25, 0.25, 0.4}, {1.5, 1.5, 3.0}};
  for (int s = 0; s < 3; ++s) {
    ASSERT_GT(count[s], 1000);
    for (int a = 0; a < 3; ++a)
      EXPECT_NEAR(std::sqrt(sum2[s][a] / count[s]), sigma[s][a], 0.1 * sigma[s][a]) << s << a;
  }
  // Their keys are checked as the others are.
  EXPECT_THROW(
      io::apply_sim_config("trajectories: {gnss: {single_vertical_sigma_m: -1}}\n", "s.yaml", cfg),
      Error);
  EXPECT_THROW(
      io::apply_sim_config("trajectories: {gnss: {float_fixes: [[5, 1]]}}\n", "s.yaml", cfg),
      Error);
}

// The ground-truth recording's building (SimConfig::building): over the outage the path goes in
// through a door, climbs a storey and comes down again, and leaves through another door without
// coming near a wall; sweeps indoors see walls and roof all around within a few metres; no fix
// indoors. Off, the part is what it was.
TEST(SimTrajectories, TheBuildingOverTheOutageHasDoorsStairsWallsAndRoof) {
  const rig::Rig rig = sample_rig();
  SimConfig cfg;
  ground_truth_defaults(cfg);
  cfg.trajectory_duration_s = 30;
  cfg.gnss.outages = {{8.0, 22.0}};
  cfg.gnss.float_spans.clear();
  cfg.gnss.single_spans.clear();
  cfg.markers = 0;
  cfg.lidar.beams = 32;
  cfg.lidar.columns = 512;
  const TrajectoryPart part = simulate_trajectories(rig, cfg);
  ASSERT_TRUE(part.building);
  const Building& b = *part.building;
  EXPECT_DOUBLE_EQ(b.t_in, 8.0);
  EXPECT_DOUBLE_EQ(b.t_out, 22.0);
  // No fix indoors.
  const double offset = rig::sensor(rig, "gnss").time_offset;
  for (const Time& stamp : part.gnss.stamps) {
    const double t = stamp.seconds() + offset - cfg.base_start_s;
    EXPECT_FALSE(t >= 8.0 && t < 22.0) << t;
  }
  // The height: a storey up and back to the ground (the walk's own bob is 2 cm).
  const std::vector<SE3>& poses = part.truth_base.T_world_body;
  double z_before = 0, z_top = -1e9, z_after = 0;
  for (size_t k = 0; k < poses.size(); ++k) {
    const double t = 0.1 * double(k);
    if (t < 8.0) z_before = std::max(z_before, std::abs(poses[k].t.z() - poses[0].t.z()));
    if (t > 8.0 && t < 22.0) z_top = std::max(z_top, poses[k].t.z() - poses[0].t.z());
    if (t > 22.0) z_after = std::max(z_after, std::abs(poses[k].t.z() - poses[0].t.z()));
  }
  EXPECT_LT(z_before, 0.1);
  EXPECT_NEAR(z_top, b.storey_m(), 0.1);
  EXPECT_NEAR(b.storey_m(), 2.55, 1e-9);
  EXPECT_LT(z_after, 0.1);
  SweepDrive drive = trajectory_drive(rig, cfg, part);
  ASSERT_FALSE(drive.building.empty());
  // No wall within 0.4 m of the path, horizontally; a door's lintel at least 0.3 m above it.
  double nearest = 1e9, headroom = 1e9, z_ground = 1e9;
  int walls = 0, lintels = 0, steps = 0;
  for (const Box& box : drive.building)
    z_ground = std::min(z_ground, box.T_world_box.t.z() - box.half_extents.z());
  for (const Box& box : drive.building) {
    steps += box.id == kBuildingStairs;
    if (box.id != kBuildingWall) continue;
    const double bottom = box.T_world_box.t.z() - box.half_extents.z();
    const bool lintel = bottom > z_ground + 1.0;
    ++(lintel ? lintels : walls);
    for (const SE3& T : poses) {
      const Eigen::Vector3d q = box.T_world_box.inverse() * T.t;
      const Eigen::Vector2d outside =
          (q.head<2>().cwiseAbs() - box.half_extents.head<2>()).cwiseMax(0.0);
      if (lintel) {
        if (outside.norm() == 0) headroom = std::min(headroom, bottom - T.t.z());
      } else {
        nearest = std::min(nearest, outside.norm());
      }
    }
  }
  EXPECT_GT(walls, 20);
  EXPECT_EQ(lintels, 2);  // one door in, one out
  EXPECT_EQ(steps, 2 * b.steps);
  EXPECT_GT(nearest, 0.4);
  EXPECT_GT(headroom, 0.3);
  std::printf(
      "[ figures ] building: %.1f m of path indoors, %d wall boxes, the path %.2f m from the "
      "nearest wall, %.2f m below the lintels\n",
      b.length_m, walls, nearest, headroom);
  // Sweeps in the entrance hall, on the stairs and on the gallery: points of the building within
  // 6 m in each of 8 directions, walls and roof among them.
  for (const double t : {8.5, 8.0 + 4.0 / 1.3, 15.0}) {
    drive.next = static_cast<int>(std::lround(t * part.rate_hz));
    const Sweep s = next_sweep(drive);
    int sector_hits[8] = {}, roof = 0, wall = 0;
    for (const LidarPoint& p : s.points) {
      roof += p.object == kBuildingRoof;
      wall += p.object == kBuildingWall;
      if (p.object < kBuildingWall || p.object > kBuildingGallery || p.p.norm() > 6.0f) continue;
      const double a = std::atan2(p.p.y(), p.p.x()) + M_PI;
      ++sector_hits[std::min(7, static_cast<int>(a / (M_PI / 4)))];
    }
    EXPECT_GT(roof, 100) << t;
    EXPECT_GT(wall, 100) << t;
    for (int i = 0; i < 8; ++i) EXPECT_GT(sector_hits[i], 10) << t << " sector " << i;
  }
  // Off (the default elsewhere): no building, the same path as without the key.
  cfg.building = false;
  const TrajectoryPart flat = simulate_trajectories(rig, cfg);
  EXPECT_FALSE(flat.building);
  EXPECT_NEAR(flat.truth_base.T_world_body[150].t.z(), poses[0].t.z(), 0.1);
  EXPECT_EQ(flat.truth_base.T_world_body[50].t, poses[50].t);  // before the building
}

TEST(SimSession, SameSeedSameOutputOtherSeedOther) {
  const rig::Rig rig = sample_rig();
  SimConfig cfg;
  cfg.boards.views = 2;
  const StereoPart a = simulate_stereo(rig, cfg), b = simulate_stereo(rig, cfg);
  EXPECT_EQ(cv::norm(a.left[1], b.left[1], cv::NORM_INF), 0.0);
  cfg.seed = 2;
  const StereoPart c = simulate_stereo(rig, cfg);
  EXPECT_GT(cv::norm(a.left[1], c.left[1], cv::NORM_INF), 0.0);
  // Parts draw from their own streams: the IMU part does not depend on whether stereo ran.
  cfg.seed = 1;
  cfg.imu_duration_s = 5;
  const ImuPart i1 = simulate_imu_part(rig, cfg);
  const ImuPart i2 = simulate_imu_part(rig, cfg);
  EXPECT_EQ(i1.imu.back().gyro, i2.imu.back().gyro);
}

}  // namespace
}  // namespace rigcal::sim
