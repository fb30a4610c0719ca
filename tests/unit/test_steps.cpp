// Each calibration step run in process as the command line and the session pipeline run it: the
// result's rig, the sensors it wrote, its report (with the status) and its status; and the one
// way of saying "the data do not determine this" (status undetermined, reason and remedy).
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "rigcal/camera/step.h"
#include "rigcal/core/error.h"
#include "rigcal/hand_eye/step.h"
#include "rigcal/io/session.h"
#include "rigcal/io/trajectory_io.h"
#include "rigcal/lidar_camera/step.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/time_sync/step.h"
#include "test_rigs.h"

namespace rigcal {
namespace {

namespace fs = std::filesystem;


class Steps : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           fmt::format("rigcal_steps_{}_{}", ::getpid(),
                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  // A simulated session of the sample rig with the parts in `what`.
  fs::path simulate(const std::string& what, const std::string& config) {
    std::ofstream(dir_ / "sim.yaml") << config;
    const std::string cmd =
        fmt::format("{} simulate --out {} --config {} --what {} > /dev/null", RIGCAL_CLI,
                    (dir_ / "s").string(), (dir_ / "sim.yaml").string(), what);
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    return dir_ / "s";
  }
  fs::path dir_;
};

const std::string* find_file(const report::StepResult& r, const std::string& name) {
  for (const io::OutputFile& f : r.report_files) {
    if (f.path == name) return &f.content;
  }
  return nullptr;
}

TEST_F(Steps, CamerasWritesBothCamerasAndReusesItsDetections) {
  const fs::path s = simulate("stereo", "stereo:\n  views: 8\n");
  camera::StepInputs in;
  in.target = s / "target.yaml";
  in.images = io::read_session_images(io::recording_for(io::read_session(s), "cameras"));
  in.rig = rig::read_rig_file(kPrior);
  const report::StepResult r = camera::calibrate_cameras(in, {});
  EXPECT_EQ(r.status, report::StepStatus::ok);
  EXPECT_EQ(r.step, "cameras");
  EXPECT_EQ(r.wrote, (std::vector<std::string>{"cam_l", "cam_r"}));
  EXPECT_EQ(r.report["status"], "ok");
  EXPECT_LT(r.report["rms_2d_px"].get<double>(), 0.15);
  ASSERT_NE(find_file(r, "cameras.json"), nullptr);
  ASSERT_NE(find_file(r, "corners.vnl"), nullptr);
  // Intrinsics estimated, cam_l's pose kept from the prior, everything else untouched.
  const rig::Rig prior = rig::read_rig_file(kPrior), truth = rig::read_rig_file(kTruth);
  EXPECT_NEAR(rig::sensor(r.rig, "cam_r").camera.fx, rig::sensor(truth, "cam_r").camera.fx, 2.0);
  EXPECT_EQ(rig::sensor(r.rig, "cam_l").T_base_sensor.matrix(),
            rig::sensor(prior, "cam_l").T_base_sensor.matrix());
  EXPECT_EQ(rig::rig_to_yaml(rig::Rig{{rig::sensor(r.rig, "gnss")}, "gnss", {}, {}}),
            rig::rig_to_yaml(rig::Rig{{rig::sensor(prior, "gnss")}, "gnss", {}, {}}));
  EXPECT_FALSE(r.sigmas.empty());
  // The detections cache: a second run reads every detection from it.
  io::write_file_atomic(dir_ / "corners.vnl", *find_file(r, "corners.vnl"));
  in.corners_cache = dir_ / "corners.vnl";
  const report::StepResult again = camera::calibrate_cameras(in, {});
  EXPECT_NE(again.summary[0].find("from " + in.corners_cache.string()), std::string::npos)
      << again.summary[0];
  EXPECT_EQ(again.rig.sensors.size(), r.rig.sensors.size());
  EXPECT_EQ(rig::sensor(again.rig, "cam_l").camera.fx, rig::sensor(r.rig, "cam_l").camera.fx);
}

TEST_F(Steps, LidarCameraPlacesBothCamerasAndRefusesTooFewBoards) {
  const fs::path s = simulate("lidar-camera", "lidar_camera:\n  pairs: 6\n");
  const rig::Rig truth = rig::read_rig_file(kTruth);
  lidar_camera::StepOptions o;
  lidar_camera::StepInputs in = lidar_camera::pairs_from_recording(s / "lidar_camera", truth, o);
  in.target = s / "target.yaml";
  EXPECT_EQ(in.images.size(), 6u);
  const report::StepResult r = lidar_camera::calibrate_lidar_camera(in, o);
  EXPECT_EQ(r.status, report::StepStatus::ok);
  EXPECT_EQ(r.report["status"], "ok");
  EXPECT_EQ(r.wrote, (std::vector<std::string>{"cam_l", "cam_r"}));
  const SE3 e = rig::T_a_b(r.rig, "cam_r", "lidar"), t = rig::T_a_b(truth, "cam_r", "lidar");
  EXPECT_LT((e.t - t.t).norm(), 0.01);
  // The stereo extrinsic is kept: the left camera moves with the right one.
  EXPECT_TRUE(rig::T_a_b(r.rig, "cam_l", "cam_r")
                  .matrix()
                  .isApprox(rig::T_a_b(truth, "cam_l", "cam_r").matrix(), 1e-12));
  in.images.resize(2), in.scans.resize(2);
  EXPECT_THROW(lidar_camera::calibrate_lidar_camera(in, o), Error);
}

TEST_F(Steps, TimeSyncWritesTheOffsetOrSaysWhyNot) {
  const fs::path s = simulate("imu", "");
  time_sync::StepInputs in = time_sync::streams_of_recording(s);
  in.rig = rig::read_rig_file(kPrior);
  const report::StepResult r = time_sync::estimate_clock(in, {});
  ASSERT_EQ(r.status, report::StepStatus::ok) << r.reason;
  EXPECT_EQ(r.wrote, (std::vector<std::string>{"imu"}));
  EXPECT_NEAR(rig::sensor(r.rig, "imu").time_offset,
              rig::sensor(rig::read_rig_file(kTruth), "imu").time_offset, 5e-4);
  EXPECT_EQ(r.report["status"], "ok");
  ASSERT_NE(find_file(r, "time_sync.json"), nullptr);

  // A rig held still: no offset, said as undetermined with the remedy; the rig unchanged.
  std::string still = "t wx wy wz\n";
  for (int k = 0; k < 3000; ++k) still += fmt::format("{:.2f} 0.001 -0.002 0.0005\n", 0.01 * k);
  std::ofstream(dir_ / "still_a.txt") << still;
  std::ofstream(dir_ / "still_b.txt") << still;
  in.reference.path = dir_ / "still_a.txt";
  in.other.path = dir_ / "still_b.txt";
  const report::StepResult u = time_sync::estimate_clock(in, {});
  EXPECT_EQ(u.status, report::StepStatus::undetermined);
  EXPECT_NE(u.reason.find("not enough excitation"), std::string::npos) << u.reason;
  EXPECT_FALSE(u.remedy.empty());
  EXPECT_TRUE(u.wrote.empty());
  EXPECT_EQ(rig::sensor(u.rig, "imu").time_offset, 0.0);
  EXPECT_EQ(u.report["status"], "undetermined");
  EXPECT_EQ(u.report["reason"], u.reason);
  // An IMU log with a header and no samples is bad input, not a crash.
  std::ofstream(dir_ / "empty.txt") << "t wx wy wz\n";
  in.other.path = dir_ / "empty.txt";
  EXPECT_THROW(time_sync::estimate_clock(in, {}), Error);
}

TEST_F(Steps, HandEyeMovesTheInsImuWithIt) {
  const fs::path s = simulate("trajectories", "");
  hand_eye::StepInputs in;
  in.lidar = s / "trajectories" / "lidar_odometry.tum";
  in.gnss = s / "trajectories" / "gnss_ins.tum";
  in.rig = rig::read_rig_file(kPrior);
  hand_eye::StepOptions o;
  o.estimate_offset = true;
  const report::StepResult r = hand_eye::estimate_extrinsic(in, o);
  ASSERT_EQ(r.status, report::StepStatus::ok) << r.reason;
  EXPECT_EQ(r.wrote, (std::vector<std::string>{"gnss", "imu.T_b"}));  // the IMU's pose only
  const rig::Rig truth = rig::read_rig_file(kTruth);
  const SE3 e = rig::T_a_b(r.rig, "gnss", "lidar"), t = rig::T_a_b(truth, "gnss", "lidar");
  EXPECT_LT((e.t - t.t).norm(), 0.01);
  EXPECT_NEAR(rig::sensor(r.rig, "gnss").time_offset, rig::sensor(truth, "gnss").time_offset, 1e-3);
  // One rigid body: the INS's IMU kept its pose relative to the GNSS/INS.
  EXPECT_TRUE(rig::T_a_b(r.rig, "gnss", "imu")
                  .matrix()
                  .isApprox(rig::T_a_b(*in.rig, "gnss", "imu").matrix(), 1e-12));
  EXPECT_EQ(r.report["status"], "ok");

  // Not estimating the offset keeps the prior's (0 s, 3.1 ms off the truth), and says so.
  o.estimate_offset = false;
  const report::StepResult kept = hand_eye::estimate_extrinsic(in, o);
  ASSERT_EQ(kept.status, report::StepStatus::ok);
  EXPECT_EQ(rig::sensor(kept.rig, "gnss").time_offset, 0.0);
  bool said = false;
  for (const std::string& n : kept.notes) said |= n.find("put the clocks -3.") != std::string::npos;
  EXPECT_TRUE(said) << "no note of the 3.1 ms disagreement";
  o.estimate_offset = true;

  // Straight-line motion gives no clock offset: undetermined, nothing written.
  Trajectory line;
  for (int k = 0; k < 1000; ++k) {
    line.stamps.push_back(Time::from_seconds(0.1 * k));
    line.T_world_body.push_back(SE3{Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.1 * k, 0, 0)});
  }
  io::write_file_atomic(dir_ / "line.tum", io::trajectory_to_tum(line));
  in.lidar = in.gnss = dir_ / "line.tum";
  const report::StepResult u = hand_eye::estimate_extrinsic(in, o);
  EXPECT_EQ(u.status, report::StepStatus::undetermined);
  EXPECT_NE(u.reason.find("clock offset"), std::string::npos) << u.reason;
  EXPECT_TRUE(u.wrote.empty());
  EXPECT_EQ(u.report["status"], "undetermined");
  EXPECT_EQ(u.report["reason"], u.reason);
  ASSERT_NE(find_file(u, "hand_eye.json"), nullptr);
}

// Rows swapped in an IMU log (two pairs of 12,000, far apart) shifted the offset by 2.6 ms (1-sigma
// 0.9 ms); the isolated samples are now repaired, said in the notes, and the offset is the
// clean log's. A sample beyond any gyroscope (1e308, or a log in deg/s) names its line.
TEST_F(Steps, TimeSyncRepairsSwappedRowsAndRefusesImpossibleRates) {
  const fs::path s = simulate("imu", "");
  time_sync::StepInputs in = time_sync::streams_of_recording(s);
  in.rig = rig::read_rig_file(kPrior);
  const double clean = rig::sensor(time_sync::estimate_clock(in, {}).rig, "imu").time_offset;
  const fs::path imu = s / "imu" / "data" / "imu.txt";
  std::vector<std::string> rows;
  {
    std::ifstream f(imu);
    for (std::string line; std::getline(f, line);) rows.push_back(line);
  }
  ASSERT_GT(rows.size(), 9002u);
  std::swap(rows[2001], rows[9001]);
  std::swap(rows[5001], rows[7001]);
  auto write_rows = [&] {
    std::ofstream f(imu);
    for (const std::string& r : rows) f << r << "\n";
  };
  write_rows();
  const report::StepResult r = time_sync::estimate_clock(in, {});
  ASSERT_EQ(r.status, report::StepStatus::ok) << r.reason;
  EXPECT_NEAR(rig::sensor(r.rig, "imu").time_offset, clean, 2e-5);
  bool said = false;
  for (const std::string& n : r.notes)
    said |= n.find("imu: 4 isolated samples far from both neighbours") != std::string::npos;
  EXPECT_TRUE(said) << "no note of the repaired samples";

  // One row's angular rate set to 1e308 rad/s.
  std::string& row = rows[3001];
  for (int comma = 0, i = 0; i < static_cast<int>(row.size()); ++i) {
    if (row[i] == ',' && ++comma == 3) {
      row.insert(static_cast<size_t>(i) + 1, "1e308");
      break;
    }
  }
  // The field now reads "1e308-1.23...": put a comma-free value there instead.
  const size_t start = row.find("1e308"), end = row.find(',', start);
  row.replace(start, end - start, "1e308");
  write_rows();
  try {
    time_sync::estimate_clock(in, {});
    ADD_FAILURE() << "a 1e308 rad/s sample was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              imu.string() +
                  ":3002: angular rate of 1e+308 rad/s, beyond any gyroscope (100 rad/s); "
                  "damaged, or in deg/s (rigcal reads rad/s)");
  }
}

// Degenerate motion never gets a confident answer: a static LiDAR odometry against a moving
// GNSS/INS is refused (the two turn by different angles), and motion about one axis only leaves
// the rotation about it undetermined (before: T_b written with "0.000 +- 0.000 deg").
TEST_F(Steps, HandEyeRefusesStaticOdometryAndOneAxisMotion) {
  const fs::path s = simulate("trajectories", "");
  hand_eye::StepInputs in;
  in.gnss = s / "trajectories" / "gnss_ins.tum";
  in.rig = rig::read_rig_file(kPrior);
  const Trajectory moving = io::read_trajectory(in.gnss).trajectory;
  Trajectory still = moving;
  for (SE3& T : still.T_world_body) T = SE3{};
  io::write_file_atomic(dir_ / "still.tum", io::trajectory_to_tum(still));
  in.lidar = dir_ / "still.tum";
  try {
    hand_eye::estimate_extrinsic(in, {});
    ADD_FAILURE() << "a static odometry was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("still.tum against " + in.gnss.string() +
                                         ": the LiDAR odometry turns 0 times as far as the "
                                         "GNSS/INS"),
              std::string::npos)
        << e.what();
  }

  // Both sensors turning about z only (a yaw-only car), the GNSS/INS 0.3 m beside the LiDAR.
  Trajectory lidar, gnss;
  const SE3 T_lidar_gnss{Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.3, 0.1, 0.2)};
  for (int k = 0; k < 3000; ++k) {
    const double t = 0.01 * k, yaw = 0.8 * std::sin(0.7 * t) + 0.3 * std::sin(2.1 * t);
    const SE3 T_world_lidar{Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix(),
                            Eigen::Vector3d(2 * t, std::sin(t), 0)};
    lidar.stamps.push_back(Time::from_seconds(t));
    lidar.T_world_body.push_back(T_world_lidar);
    gnss.stamps.push_back(Time::from_seconds(t));
    gnss.T_world_body.push_back(T_world_lidar * T_lidar_gnss);
  }
  io::write_file_atomic(dir_ / "yaw_lidar.tum", io::trajectory_to_tum(lidar));
  io::write_file_atomic(dir_ / "yaw_gnss.tum", io::trajectory_to_tum(gnss));
  in.lidar = dir_ / "yaw_lidar.tum";
  in.gnss = dir_ / "yaw_gnss.tum";
  const report::StepResult u = hand_eye::estimate_extrinsic(in, {});
  EXPECT_EQ(u.status, report::StepStatus::undetermined);
  EXPECT_NE(u.reason.find("every motion pair turns about one axis, [0.000 0.000 1.000]"),
            std::string::npos)
      << u.reason;
  EXPECT_TRUE(u.wrote.empty());
}

TEST(Rig, AttachedSensorsMoveRigidlyAndCyclesAreRefused) {
  rig::Rig r = rig::read_rig_file(kPrior);
  ASSERT_EQ(rig::sensor(r, "imu").attached_to, "gnss");
  const SE3 before = rig::T_a_b(r, "gnss", "imu");
  const SE3 moved = SE3::from_rotation_vector(Eigen::Vector3d(0.01, 0.02, -0.03),
                                              Eigen::Vector3d(0.1, -0.2, 0.3));
  EXPECT_EQ(rig::move_rigidly(r, "gnss", moved), (std::vector<std::string>{"gnss", "imu"}));
  EXPECT_TRUE(rig::sensor(r, "gnss").T_base_sensor.matrix().isApprox(moved.matrix(), 1e-15));
  EXPECT_TRUE(rig::T_a_b(r, "gnss", "imu").matrix().isApprox(before.matrix(), 1e-12));
  // Read back from YAML; a cycle or an unknown sensor is an error naming the key.
  EXPECT_EQ(rig::sensor(rig::parse_rig_yaml(rig::rig_to_yaml(r), "x.yaml"), "imu").attached_to,
            "gnss");
  rig::sensor(r, "gnss").attached_to = "imu";
  EXPECT_THROW(rig::validate(r), Error);
  rig::sensor(r, "gnss").attached_to = "nothing";
  try {
    rig::validate(r);
    FAIL() << "an unknown sensor was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("gnss.attached_to"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rigcal
