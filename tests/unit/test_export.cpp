// Exports read back by the reader of each ecosystem: Kalibr and ROS YAML through yaml-cpp, OpenCV
// through cv::FileStorage, mrcal through libmrcal's own parser. Numbers must come back unchanged.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <random>

#include "rigcal/core/error.h"
#include "rigcal/rig/export.h"
#include "rigcal/rig/rig_yaml.h"
#include "test_rigs.h"

extern "C" {
#include <mrcal/mrcal.h>
}

namespace rigcal::rig {
namespace {

Rig sample_rig() { return read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml"); }

Eigen::Matrix4d yaml_matrix4(const YAML::Node& n) {
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) m(r, c) = n[r][c].as<double>();
  }
  return m;
}

std::vector<double> yaml_doubles(const YAML::Node& n) { return n.as<std::vector<double>>(); }

TEST(ExportKalibr, CamchainReadsBackWithTheRigsNumbers) {
  const Rig rig = sample_rig();
  const YAML::Node y = YAML::Load(kalibr_camchain_yaml(rig));
  const Sensor& cam_l = sensor(rig, "cam_l");
  const Sensor& cam_r = sensor(rig, "cam_r");
  EXPECT_EQ(y["cam0"]["camera_model"].as<std::string>(), "pinhole");
  EXPECT_EQ(y["cam0"]["distortion_model"].as<std::string>(), "radtan");
  EXPECT_EQ(
      yaml_doubles(y["cam0"]["intrinsics"]),
      (std::vector<double>{cam_l.camera.fx, cam_l.camera.fy, cam_l.camera.cx, cam_l.camera.cy}));
  EXPECT_EQ(yaml_doubles(y["cam1"]["distortion_coeffs"]), cam_r.camera.distortion_coeffs);
  EXPECT_EQ(y["cam1"]["resolution"].as<std::vector<int>>(), (std::vector<int>{1388, 700}));
  // T_cn_cnm1 maps cam0 points into cam1.
  EXPECT_EQ(yaml_matrix4(y["cam1"]["T_cn_cnm1"]), T_a_b(rig, "cam_r", "cam_l").matrix());
  EXPECT_FALSE(y["cam0"]["T_cn_cnm1"]);
  // T_cam_imu of the external IMU ("imu") and Kalibr's time shift: t_imu = t_cam + shift. With
  // offsets added to stamps to reach the base clock, the same instant has t_imu = t_cam + off_cam -
  // off_imu.
  EXPECT_EQ(yaml_matrix4(y["cam0"]["T_cam_imu"]), T_a_b(rig, "cam_l", "imu").matrix());
  EXPECT_EQ(y["cam0"]["timeshift_cam_imu"].as<double>(),
            cam_l.time_offset - sensor(rig, "imu").time_offset);
  EXPECT_EQ(y["cam1"]["cam_overlaps"].as<std::vector<int>>(), std::vector<int>{0});
  // Another IMU on request.
  const YAML::Node y2 = YAML::Load(kalibr_camchain_yaml(rig, {"os_imu"}));
  EXPECT_EQ(yaml_matrix4(y2["cam0"]["T_cam_imu"]), T_a_b(rig, "cam_l", "os_imu").matrix());
  EXPECT_THROW(kalibr_camchain_yaml(rig, {"lidar"}), Error);
}

TEST(ExportKalibr, RadtanWithK3) {
  Rig rig = sample_rig();
  sensor(rig, "cam_l").camera.distortion_coeffs.push_back(0.0);
  const YAML::Node y = YAML::Load(kalibr_camchain_yaml(rig));
  EXPECT_EQ(y["cam0"]["distortion_coeffs"].size(), 4u);  // k3 = 0 dropped
  sensor(rig, "cam_l").camera.distortion_coeffs.back() = 0.01;
  try {
    kalibr_camchain_yaml(rig);
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("Kalibr's radtan model has four coefficients"),
              std::string::npos);
  }
}

cv::Mat read_mat(const cv::FileStorage& fs, const char* key) {
  cv::Mat m;
  fs[key] >> m;
  return m;
}

Eigen::MatrixXd to_eigen(const cv::Mat& m) {
  Eigen::MatrixXd e;
  cv::cv2eigen(m, e);
  return e;
}

TEST(ExportOpenCV, FileStorageReadsKDRTAndRectification) {
  for (const DistortionModel model : {DistortionModel::radtan, DistortionModel::equidistant}) {
    SCOPED_TRACE(to_string(model));
    Rig rig = sample_rig();
    if (model == DistortionModel::equidistant) {
      for (const char* name : {"cam_l", "cam_r"}) {
        sensor(rig, name).camera.distortion_model = model;
        sensor(rig, name).camera.distortion_coeffs = {0.01, -0.002, 0.0003, -0.00004};
      }
    }
    const std::string text = opencv_yaml(rig);
    cv::FileStorage fs(text, cv::FileStorage::READ | cv::FileStorage::MEMORY);
    ASSERT_TRUE(fs.isOpened());
    const Sensor& cam_l = sensor(rig, "cam_l");
    const Sensor& cam_r = sensor(rig, "cam_r");
    EXPECT_EQ(Eigen::Matrix3d(to_eigen(read_mat(fs, "K1"))), cam_l.camera.K());
    EXPECT_EQ(Eigen::Matrix3d(to_eigen(read_mat(fs, "K2"))), cam_r.camera.K());
    const cv::Mat D2 = read_mat(fs, "D2");
    EXPECT_EQ(std::vector<double>(D2.begin<double>(), D2.end<double>()),
              cam_r.camera.distortion_coeffs);
    cv::Size size1;
    fs["image_size1"] >> size1;
    EXPECT_EQ(size1, cv::Size(1388, 700));
    // R, T as stereoCalibrate returns them: p2 = R p1 + T, exactly the rig's T_cam_r_cam_l.
    const SE3 T_r_l = T_a_b(rig, "cam_r", "cam_l");
    EXPECT_EQ(Eigen::Matrix3d(to_eigen(read_mat(fs, "R"))), T_r_l.R);
    EXPECT_EQ(Eigen::Vector3d(to_eigen(read_mat(fs, "T"))), T_r_l.t);
    // E and F satisfy the epipolar constraint for a point seen by both cameras.
    const Eigen::Vector3d p_l(0.3, -0.2, 4.0);
    const Eigen::Vector3d p_r = T_r_l * p_l;
    const Eigen::Vector3d x_l = cam_l.camera.K() * (p_l / p_l.z());
    const Eigen::Vector3d x_r = cam_r.camera.K() * (p_r / p_r.z());
    const Eigen::Matrix3d F = to_eigen(read_mat(fs, "F"));
    EXPECT_NEAR(x_r.dot(F * x_l), 0.0, 1e-9);
    // Rectification: both rectified frames share one orientation, and P2 holds -f' * baseline.
    const Eigen::Matrix3d R1 = to_eigen(read_mat(fs, "R1")), R2 = to_eigen(read_mat(fs, "R2"));
    EXPECT_TRUE((R2 * T_r_l.R * R1.transpose()).isIdentity(1e-12));
    const Eigen::MatrixXd P2 = to_eigen(read_mat(fs, "P2"));
    EXPECT_NEAR(P2(0, 3) / P2(0, 0), -T_r_l.t.norm(), 1e-12);
  }
}

// OpenCV's stereo_calib sample's two files, as the sample reads them back (its keys M1 D1 M2 D2
// and R T R1 R2 P1 P2 Q), at alpha 1: the rectified views keep every source pixel, so their
// focal length is smaller than at alpha 0 (opencv_yaml's). One camera is refused.
TEST(ExportOpenCv, TheStereoSamplesTwoFiles) {
  const Rig rig = sample_rig();
  const std::filesystem::path dir = "cv_sample";  // names only: nothing is written
  const std::vector<io::OutputFile> files = export_files(rig, ExportFormat::opencv_sample, dir, {});
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(files[0].path, dir / "intrinsics.yml");
  EXPECT_EQ(files[1].path, dir / "extrinsics.yml");
  cv::FileStorage in(files[0].content, cv::FileStorage::READ | cv::FileStorage::MEMORY);
  cv::FileStorage ex(files[1].content, cv::FileStorage::READ | cv::FileStorage::MEMORY);
  ASSERT_TRUE(in.isOpened() && ex.isOpened());
  EXPECT_EQ(Eigen::Matrix3d(to_eigen(read_mat(in, "M1"))), sensor(rig, "cam_l").camera.K());
  EXPECT_EQ(Eigen::Matrix3d(to_eigen(read_mat(in, "M2"))), sensor(rig, "cam_r").camera.K());
  EXPECT_EQ(read_mat(in, "D2").total(), sensor(rig, "cam_r").camera.distortion_coeffs.size());
  const SE3 T_r_l = T_a_b(rig, "cam_r", "cam_l");
  EXPECT_EQ(Eigen::Matrix3d(to_eigen(read_mat(ex, "R"))), T_r_l.R);
  EXPECT_EQ(Eigen::Vector3d(to_eigen(read_mat(ex, "T"))), T_r_l.t);
  for (const char* key : {"R1", "R2", "P1", "P2", "Q"})
    EXPECT_FALSE(read_mat(ex, key).empty()) << key;
  cv::FileStorage one(opencv_yaml(rig), cv::FileStorage::READ | cv::FileStorage::MEMORY);
  const double f_alpha1 = read_mat(ex, "P1").at<double>(0, 0);
  const double f_alpha0 = read_mat(one, "P1").at<double>(0, 0);
  EXPECT_LT(f_alpha1, f_alpha0);
  Rig mono = rig;
  mono.sensors.erase(std::remove_if(mono.sensors.begin(), mono.sensors.end(),
                                    [](const Sensor& s) { return s.name == "cam_r"; }),
                     mono.sensors.end());
  try {
    export_files(mono, ExportFormat::opencv_sample, dir, {});
    ADD_FAILURE() << "one camera exported as a stereo pair";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("it needs two cameras"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(writes_folder(ExportFormat::opencv_sample));
  EXPECT_EQ(export_format_from_string("opencv-sample"), ExportFormat::opencv_sample);
}

TEST(ExportRos, CameraInfoPerCameraWithStereoRectification) {
  const Rig rig = sample_rig();
  const Sensor& cam_r = sensor(rig, "cam_r");
  const YAML::Node left = YAML::Load(ros_camera_info_yaml(rig, "cam_l"));
  const YAML::Node right = YAML::Load(ros_camera_info_yaml(rig, "cam_r"));
  EXPECT_EQ(right["image_width"].as<int>(), 1388);
  EXPECT_EQ(right["image_height"].as<int>(), 700);
  EXPECT_EQ(right["camera_name"].as<std::string>(), "cam_r");
  EXPECT_EQ(right["distortion_model"].as<std::string>(), "plumb_bob");
  EXPECT_EQ(yaml_doubles(right["camera_matrix"]["data"]),
            (std::vector<double>{cam_r.camera.fx, 0, cam_r.camera.cx, 0, cam_r.camera.fy,
                                 cam_r.camera.cy, 0, 0, 1}));
  std::vector<double> d = cam_r.camera.distortion_coeffs;
  d.push_back(0.0);  // plumb_bob has five
  EXPECT_EQ(yaml_doubles(right["distortion_coefficients"]["data"]), d);
  EXPECT_EQ(right["distortion_coefficients"]["cols"].as<int>(), 5);
  const std::vector<double> P1 = yaml_doubles(left["projection_matrix"]["data"]);
  const std::vector<double> P2 = yaml_doubles(right["projection_matrix"]["data"]);
  ASSERT_EQ(P2.size(), 12u);
  EXPECT_EQ(P1[3], 0.0);
  EXPECT_NEAR(P2[3] / P2[0], -T_a_b(rig, "cam_r", "cam_l").t.norm(), 1e-12);  // Tx = -f' B
  EXPECT_EQ(P1[0], P2[0]);  // one rectified focal length
  // Without a stereo partner: R = I, P = [K | 0].
  Rig mono = rig;
  mono.sensors.erase(mono.sensors.begin() + 1);
  const YAML::Node only = YAML::Load(ros_camera_info_yaml(mono, "cam_l"));
  EXPECT_EQ(yaml_doubles(only["rectification_matrix"]["data"]),
            (std::vector<double>{1, 0, 0, 0, 1, 0, 0, 0, 1}));
  const Sensor& cam_l = sensor(rig, "cam_l");
  EXPECT_EQ(yaml_doubles(only["projection_matrix"]["data"]),
            (std::vector<double>{cam_l.camera.fx, 0, cam_l.camera.cx, 0, 0, cam_l.camera.fy,
                                 cam_l.camera.cy, 0, 0, 0, 1, 0}));
  EXPECT_THROW(ros_camera_info_yaml(rig, "imu"), Error);
}

TEST(ExportMrcal, LibmrcalReadsTheModelLosslessly) {
  std::mt19937_64 rng(99);
  for (int trial = 0; trial < 20; ++trial) {
    const Rig rig = testing::random_rig(rng);
    for (const Sensor* cam : cameras(rig)) {
      if (cam->camera.distortion_model != DistortionModel::radtan) {
        EXPECT_THROW(mrcal_cameramodel(rig, cam->name), Error);
        continue;
      }
      const std::string text = mrcal_cameramodel(rig, cam->name);
      mrcal_cameramodel_t* model =
          mrcal_read_cameramodel_string(text.c_str(), static_cast<int>(text.size()));
      ASSERT_NE(model, nullptr) << text;
      const CameraModel& c = cam->camera;
      const size_t n = c.distortion_coeffs.size();
      EXPECT_STREQ(mrcal_lensmodel_name_unconfigured(&model->lensmodel),
                   n == 4 ? "LENSMODEL_OPENCV4" : "LENSMODEL_OPENCV5");
      ASSERT_EQ(mrcal_lensmodel_num_params(&model->lensmodel), static_cast<int>(4 + n));
      EXPECT_EQ(model->intrinsics[0], c.fx);
      EXPECT_EQ(model->intrinsics[1], c.fy);
      EXPECT_EQ(model->intrinsics[2], c.cx);
      EXPECT_EQ(model->intrinsics[3], c.cy);
      for (size_t k = 0; k < n; ++k) EXPECT_EQ(model->intrinsics[4 + k], c.distortion_coeffs[k]);
      EXPECT_EQ(model->imagersize[0], 1388u);
      EXPECT_EQ(model->imagersize[1], 700u);
      // rt_cam_ref with the rig's base frame as reference: the inverse of the camera's T_b.
      const SE3 T_cam_base = cam->T_base_sensor.inverse();
      const Eigen::Vector3d r(model->rt_cam_ref[0], model->rt_cam_ref[1], model->rt_cam_ref[2]);
      EXPECT_LT((rotation_from_vector(r) - T_cam_base.R).cwiseAbs().maxCoeff(), 1e-14);
      EXPECT_EQ(Eigen::Vector3d(model->rt_cam_ref[3], model->rt_cam_ref[4], model->rt_cam_ref[5]),
                T_cam_base.t);
      mrcal_free_cameramodel(&model);
    }
  }
}

TEST(Export, FilesAreNamedPerFormatAndFailuresWriteNothing) {
  const Rig rig = sample_rig();
  const std::filesystem::path out = "/x/out";
  EXPECT_EQ(export_files(rig, ExportFormat::kalibr, out).front().path, out);
  const auto ros = export_files(rig, ExportFormat::ros, out);
  ASSERT_EQ(ros.size(), 2u);
  EXPECT_EQ(ros[1].path, out / "cam_r.yaml");
  EXPECT_EQ(export_files(rig, ExportFormat::mrcal, out)[0].path, out / "cam_l.cameramodel");
  EXPECT_EQ(export_format_from_string("opencv"), ExportFormat::opencv);
  EXPECT_THROW(export_format_from_string("matlab"), Error);

  // One camera mrcal cannot express: the whole export fails before any file is produced.
  Rig mixed = rig;
  sensor(mixed, "cam_r").camera.distortion_model = DistortionModel::equidistant;
  EXPECT_THROW(export_files(mixed, ExportFormat::mrcal, out), Error);
  EXPECT_THROW(export_files(mixed, ExportFormat::vbr, out), Error);
}

TEST(Export, AtomicWriteLeavesNoTemporaries) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("rigcal_export_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  const Rig rig = sample_rig();
  io::write_files_atomic(export_files(rig, ExportFormat::mrcal, dir / "mrcal"));
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir / "mrcal")) {
    names.push_back(e.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"cam_l.cameramodel", "cam_r.cameramodel"}));
  // A destination that cannot be written (a folder in the way): error, and nothing left behind.
  std::filesystem::create_directories(dir / "blocked" / "rig.yaml");
  EXPECT_THROW(io::write_files_atomic(
                   {{dir / "blocked" / "a.yaml", "a"}, {dir / "blocked" / "rig.yaml", "b"}}),
               Error);
  EXPECT_FALSE(std::filesystem::exists(dir / "blocked" / "a.yaml"));
  size_t entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir / "blocked"))
    ++entries;
  EXPECT_EQ(entries, 1u);  // only the folder that was in the way
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace rigcal::rig
