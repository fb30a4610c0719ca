#pragma once
// Calibrations other tools wrote, read into the rig model (doc/exports.md, "Reading other
// tools' files"), so that `rigcal rig validate|show|convert` and `rigcal diff` take them as they
// are: a Kalibr camchain (camchain.yaml, camchain-imucam.yaml), a ROS camera_info YAML (the
// camera_calibration_parsers form, or a CameraInfo message's fields K D width height), an OpenCV
// FileStorage file (cv::calibrateCamera's sample: camera_matrix, distortion_coefficients,
// image_width, image_height; cv::stereoCalibrate's: K1 D1 K2 D2 or M1 D1 M2 D2, R T, image sizes),
// an mrcal .cameramodel (read by libmrcal), or rigcal's own YAML (and VBR's).
//
// The cameras are named as rigcal names them, by their order in the file: cam_l, cam_r, then
// cam2, cam3 ... (ImportOptions::camera_names overrides), the file's own names kept in
// Rig::notes. The first camera is the base frame unless the file has a LiDAR (rigcal's own).
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "rigcal/rig/rig.h"

namespace rigcal::rig {

enum class CalibrationFormat { rigcal, kalibr, ros, opencv, mrcal };
std::string_view to_string(CalibrationFormat format);

struct ImportOptions {
  std::vector<std::string> camera_names;  // in the file's order; empty: cam_l, cam_r, cam2 ...
};

// The format of a calibration file's text, from its content (not its name).
CalibrationFormat detect_calibration_format(std::string_view text);

// Throws rigcal::Error naming the file, line and key on anything it cannot take: a lens model
// rigcal has no equivalent of (Kalibr's omni, ROS's rational_polynomial, mrcal's splined or
// CAHVOR), a missing image size, a non-rotation.
Rig parse_calibration(std::string_view text, std::string_view file_name,
                      const ImportOptions& options = {});
Rig read_calibration_file(const std::filesystem::path& path, const ImportOptions& options = {});

}  // namespace rigcal::rig
