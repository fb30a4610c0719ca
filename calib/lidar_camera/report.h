#pragma once
// The LiDAR-camera report (doc/lidar-camera.md): lidar_camera.json (every figure with its
// definition) and, per pair, pair_NN.png: the image with the LiDAR points projected through the
// extrinsic and the lens, coloured by depth, the board's points outlined, so a person sees at a
// glance whether edges line up.
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "rigcal/io/files.h"
#include "rigcal/lidar_camera/solve.h"
#include "rigcal/rig/rig.h"

namespace rigcal::lidar_camera {

struct LidarCameraInputs {
  std::vector<std::string> images, scans;  // per pair, as given
  std::string target, rig, camera;
  double board_width_m = 0, board_height_m = 0;
};

std::vector<io::OutputFile> lidar_camera_report_files(const std::filesystem::path& dir,
                                                      const LidarCameraInputs& in,
                                                      const std::vector<PairInput>& pairs,
                                                      const Calibration& c,
                                                      const rig::CameraModel& camera,
                                                      const std::vector<cv::Mat>& images);

// The quick-look image of one pair (BGR): `image` with `scan` projected (points within 0.2-30 m,
// coloured by depth, near red to far blue), the LiDAR board points in white.
cv::Mat overlay(const cv::Mat& image, const std::vector<Eigen::Vector3d>& scan,
                const std::vector<Eigen::Vector3d>& board_points, const SE3& T_camera_lidar,
                const rig::CameraModel& camera);

}  // namespace rigcal::lidar_camera
