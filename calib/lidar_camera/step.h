#pragma once
// The LiDAR-camera step (doc/lidar-camera.md): T_camera_lidar from image + scan pairs of the
// board, written into the rig as the camera's T_b (the other cameras follow through the stereo
// extrinsic).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/io/image_io.h"
#include "rigcal/lidar_camera/solve.h"
#include "rigcal/report/step.h"

namespace rigcal::lidar_camera {

struct StepOptions {
  std::string camera = "cam_r", lidar = "lidar";        // the rig's sensors
  std::optional<double> board_width_m, board_height_m;  // a backing board larger than the target
  std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> roi;  // LiDAR frame, min and max
  double corner_sigma_px = 0.1;
  double max_dt_s = 0.05;             // a recording's image takes the nearest scan within this
  io::Bayer bayer = io::Bayer::none;  // raw mosaics: demosaiced to gray
  // Also the boards' residuals at the given rig's extrinsic (rigcal check: the new data at the
  // stored calibration): the report's `at_rig` and the residual figures named `..._at_rig_<unit>`.
  bool fit_at_rig = false;
  // The extrinsic T_camera_lidar to fit them at instead of the given rig's (the session pipeline
  // passes the stored calibration's: its rig has the re-estimated cameras by then).
  std::optional<SE3> fit_at;
};

struct StepInputs {
  std::filesystem::path target;
  rig::Rig rig;                            // with the camera's intrinsics
  std::string rig_source;                  // where the rig came from, for the report
  std::vector<std::string> images, scans;  // the pairs: images[k] with scans[k]
  std::vector<std::string> notes;          // from the pairing
};

// Pairs from a recording (camera_left/ for cam_l, camera_right/ otherwise, and ouster_points/,
// each data/ + timestamps.txt) by stamp on the base clock (the rig's time offsets applied), each
// image the nearest scan within max_dt_s; images without one are listed in `notes`.
StepInputs pairs_from_recording(const std::filesystem::path& recording, const rig::Rig& rig,
                                const StepOptions& options);
// Pairs from two globs, matched by the last number in the file names.
StepInputs pairs_from_globs(const std::string& images, const std::string& scans,
                            const rig::Rig& rig);

// Throws rigcal::Error on bad input: sensors missing from the rig, unreadable files, images of
// the wrong size, fewer than 3 usable boards or boards that do not determine the extrinsic.
report::StepResult calibrate_lidar_camera(const StepInputs& inputs, const StepOptions& options,
                                          const report::Progress& progress = {});

}  // namespace rigcal::lidar_camera
