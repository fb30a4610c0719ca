// Other tools' calibration files read into the rig (calib/rig/import.h): each of rigcal's exports
// reads back to the rig it came from; the real files in the fixtures (OpenCV's calibration
// sample's output, a ROS camera_info of a real fisheye) read with their published numbers; what
// rigcal has no model for is refused, naming the key.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>

#include "fixtures.h"
#include "rigcal/core/error.h"
#include "rigcal/rig/export.h"
#include "rigcal/rig/import.h"
#include "rigcal/rig/rig_yaml.h"
#include "test_rigs.h"

namespace rigcal {
namespace {

using rig::CalibrationFormat;

using rig::testing::sample_rig;

void expect_same_lens(const rig::CameraModel& a, const rig::CameraModel& b, double tol) {
  EXPECT_NEAR(a.fx, b.fx, tol);
  EXPECT_NEAR(a.fy, b.fy, tol);
  EXPECT_NEAR(a.cx, b.cx, tol);
  EXPECT_NEAR(a.cy, b.cy, tol);
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.distortion_model, b.distortion_model);
  ASSERT_EQ(a.distortion_coeffs.size(), b.distortion_coeffs.size());
  for (size_t i = 0; i < a.distortion_coeffs.size(); ++i)
    EXPECT_NEAR(a.distortion_coeffs[i], b.distortion_coeffs[i], tol) << i;
}

void expect_same_pose(const SE3& a, const SE3& b, double tol) {
  EXPECT_LT((a.R - b.R).cwiseAbs().maxCoeff(), tol);
  EXPECT_LT((a.t - b.t).cwiseAbs().maxCoeff(), tol);
}

TEST(Import, EachExportReadsBackToTheRigItCameFrom) {
  const rig::Rig rig = sample_rig();
  const rig::CameraModel &l = rig::sensor(rig, "cam_l").camera,
                         &r = rig::sensor(rig, "cam_r").camera;
  const SE3 T_r_l = rig::T_a_b(rig, "cam_r", "cam_l");

  // Kalibr: both cameras, their relative pose, the IMU's pose and clock relative to them.
  const std::string camchain = rig::kalibr_camchain_yaml(rig);
  EXPECT_EQ(rig::detect_calibration_format(camchain), CalibrationFormat::kalibr);
  const rig::Rig k = rig::parse_calibration(camchain, "camchain.yaml");
  EXPECT_EQ(k.base_frame, "cam_l");
  expect_same_lens(rig::sensor(k, "cam_l").camera, l, 0.0);
  expect_same_lens(rig::sensor(k, "cam_r").camera, r, 0.0);
  expect_same_pose(rig::T_a_b(k, "cam_r", "cam_l"), T_r_l, 1e-12);
  expect_same_pose(rig::T_a_b(k, "cam_l", "imu"), rig::T_a_b(rig, "cam_l", "imu"), 1e-12);
  // Clocks relative to one another (the base clocks differ: the LiDAR's, cam_l's).
  const auto offset = [](const rig::Rig& x, const char* a, const char* b) {
    return rig::sensor(x, a).time_offset - rig::sensor(x, b).time_offset;
  };
  EXPECT_NEAR(offset(k, "imu", "cam_l"), offset(rig, "imu", "cam_l"), 1e-15);
  EXPECT_NEAR(offset(k, "cam_r", "cam_l"), offset(rig, "cam_r", "cam_l"), 1e-15);

  // ROS camera_info: the camera by its camera_name.
  const std::string info = rig::ros_camera_info_yaml(rig, "cam_r");
  EXPECT_EQ(rig::detect_calibration_format(info), CalibrationFormat::ros);
  const rig::Rig ros = rig::parse_calibration(info, "cam_r.yaml");
  ASSERT_EQ(ros.sensors.size(), 1u);
  EXPECT_EQ(ros.sensors[0].name, "cam_r");
  rig::CameraModel r5 = r;
  r5.distortion_coeffs.resize(5, 0.0);  // plumb_bob is k1 k2 p1 p2 k3
  expect_same_lens(ros.sensors[0].camera, r5, 0.0);

  // OpenCV FileStorage: both cameras and R, T (p2 = R p1 + T).
  const std::string cv_text = rig::opencv_yaml(rig);
  EXPECT_EQ(rig::detect_calibration_format(cv_text), CalibrationFormat::opencv);
  const rig::Rig cv = rig::parse_calibration(cv_text, "stereo.yaml");
  expect_same_lens(rig::sensor(cv, "cam_l").camera, l, 1e-12);
  expect_same_lens(rig::sensor(cv, "cam_r").camera, r, 1e-12);
  expect_same_pose(rig::T_a_b(cv, "cam_r", "cam_l"), T_r_l, 1e-12);

  // mrcal, through libmrcal's reader; --cameras-style names.
  const std::string model = rig::mrcal_cameramodel(rig, "cam_l");
  EXPECT_EQ(rig::detect_calibration_format(model), CalibrationFormat::mrcal);
  const rig::Rig m = rig::parse_calibration(model, "cam_l.cameramodel", {{"left"}});
  ASSERT_EQ(m.sensors.size(), 1u);
  EXPECT_EQ(m.sensors[0].name, "left");
  expect_same_lens(m.sensors[0].camera, l, 0.0);

  // rigcal's own YAML: as rig_yaml reads it.
  EXPECT_EQ(rig::detect_calibration_format(rig::rig_to_yaml(rig)), CalibrationFormat::rigcal);
}

TEST(Import, RealFilesOfOtherToolsReadWithTheirNumbers) {
  const std::string opencv = testing::fixture("stereo/opencv_samples/left_intrinsics.yml");
  const std::string acfr = testing::fixture("lidar_camera/acfr/cfg/camera_info.yaml");
  if (opencv.empty() || acfr.empty()) GTEST_SKIP() << "fixtures not found under ../shared/fixtures";
  // OpenCV's calibration sample's output (its numbers as printed in the file).
  const rig::Rig cv = rig::read_calibration_file(opencv);
  ASSERT_EQ(cv.sensors.size(), 1u);
  const rig::CameraModel& c = cv.sensors[0].camera;
  EXPECT_EQ(c.width, 640);
  EXPECT_EQ(c.height, 480);
  EXPECT_DOUBLE_EQ(c.fx, 5.3591573396163199e+02);
  EXPECT_DOUBLE_EQ(c.cy, 2.3557082909788173e+02);
  EXPECT_EQ(c.distortion_model, rig::DistortionModel::radtan);
  ASSERT_EQ(c.distortion_coeffs.size(), 5u);
  EXPECT_DOUBLE_EQ(c.distortion_coeffs[4], 2.3839153080878486e-01);
  // The ACFR rig's fisheye, a CameraInfo message's fields (K, D, width, height).
  const rig::Rig info = rig::read_calibration_file(acfr);
  const rig::CameraModel& f = info.sensors.at(0).camera;
  EXPECT_EQ(f.distortion_model, rig::DistortionModel::equidistant);
  EXPECT_EQ(f.width, 1920);
  EXPECT_EQ(f.height, 1208);
  EXPECT_DOUBLE_EQ(f.fx, 959.554);
  EXPECT_DOUBLE_EQ(f.fy, 960.194);
  EXPECT_DOUBLE_EQ(f.cx, 940.789);
  EXPECT_DOUBLE_EQ(f.cy, 670.737);
  EXPECT_EQ(f.distortion_coeffs, (std::vector<double>{-0.097824, 0.141429, -0.148385, 0.055918}));
}

TEST(Import, RefusesWhatRigcalHasNoModelForNamingTheKey) {
  const std::string omni =
      "cam0:\n  camera_model: omni\n  intrinsics: [0.8, 400, 400, 320, 240]\n"
      "  distortion_model: radtan\n  distortion_coeffs: [0, 0, 0, 0]\n  resolution: [640, 480]\n";
  std::string e = testing::error_message_of([&] { rig::parse_calibration(omni, "omni.yaml"); });
  EXPECT_NE(e.find("omni.yaml:2: key 'cam0.camera_model'"), std::string::npos) << e;
  const std::string rational =
      "image_width: 640\nimage_height: 480\ncamera_name: wide\ncamera_matrix:\n  rows: 3\n"
      "  cols: 3\n  data: [500, 0, 320, 0, 500, 240, 0, 0, 1]\ndistortion_model: "
      "rational_polynomial\ndistortion_coefficients:\n  rows: 1\n  cols: 8\n"
      "  data: [0.1, 0.01, 0, 0, 0.001, 0.2, 0, 0]\n";
  e = testing::error_message_of([&] { rig::parse_calibration(rational, "wide.yaml"); });
  EXPECT_NE(e.find("k4 and beyond not zero"), std::string::npos) << e;
  const std::string no_size =
      "%YAML:1.0\n---\ncamera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
      "   data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]\n";
  e = testing::error_message_of([&] { rig::parse_calibration(no_size, "k.yml"); });
  EXPECT_NE(e.find("no image size"), std::string::npos) << e;
  const std::string cahvor =
      "{\n    'lensmodel':  'LENSMODEL_CAHVOR',\n    'intrinsics': [500, 500, 320, 240, 0, 0, "
      "0, 0, 0],\n    'imagersize': [640, 480],\n    'extrinsics': [0, 0, 0, 0, 0, 0],\n}\n";
  e = testing::error_message_of([&] { rig::parse_calibration(cahvor, "c.cameramodel"); });
  EXPECT_NE(e.find("LENSMODEL_CAHVOR"), std::string::npos) << e;
}

}  // namespace
}  // namespace rigcal
