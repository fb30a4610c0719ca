#pragma once
// The capture configuration of `rigcal capture` (doc/capture.md): the rig's cameras, each with the
// GenICam features it is recorded with. YAML:
//
//   stamps: host                 # host (the host's clock when the frame arrived) | camera
//   buffers: 16                  # stream buffers a camera
//   max_waiting_mb: 1024         # frames received and not yet written, a camera, at most: past
//                                # it the disk does not keep up and the recording stops
//   cameras:
//     camera_left:               # the recording's folder (camera_left | camera_right)
//       id: 192.168.1.10         # what Aravis opens: its device id, serial number or address
//       pixel_format: BayerRG8
//       region: [0, 0, 1388, 700]   # x, y, width, height
//       trigger: Line0           # a line of the camera (hardware), Software (the host triggers
//                                # every camera at frame_rate_hz) or off (free running)
//       trigger_activation: RisingEdge
//       frame_rate_hz: 30        # the free-running or software-triggered rate
//       exposure_us: auto        # auto (ExposureAuto Continuous, capped by exposure_auto_max_us)
//       exposure_auto_max_us: 20000      # or a fixed exposure in microseconds
//       gain: 0                  # auto or a number; left as the camera has it when absent
//       balance_white: auto      # auto | off (colour and Bayer cameras)
//       features:                # any other GenICam feature, set in this order and read back
//         GevSCPSPacketSize: 9000
//
// A setting written in the file is required: a camera without the feature, or refusing the
// value, stops the capture with an error naming both. A default the file leaves out (the
// exposure's and white balance's auto modes) is applied where the camera has the feature and
// reported as absent where it has not.
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace rigcal::io {

struct CaptureCameraConfig {
  std::string folder;  // camera_left | camera_right
  std::string id;
  std::string pixel_format = "BayerRG8";
  bool pixel_format_given = false;
  std::optional<std::array<int, 4>> region;  // x, y, width, height
  std::string trigger = "Software";          // a line name, Software or off
  bool trigger_given = false;
  std::optional<std::string> trigger_activation;
  double frame_rate_hz = 10;
  bool frame_rate_given = false;
  std::optional<double> exposure_us;  // nullopt: auto
  bool exposure_given = false;
  double exposure_auto_max_us = 20000;
  bool exposure_auto_max_given = false;
  std::optional<std::string> gain;  // "auto" or a number
  std::string balance_white = "auto";
  bool balance_white_given = false;
  std::vector<std::pair<std::string, std::string>> features;  // in the file's order
};

enum class CaptureStamps { host, camera };

struct CaptureConfig {
  std::vector<CaptureCameraConfig> cameras;
  CaptureStamps stamps = CaptureStamps::host;
  int buffers = 16;
  int max_waiting_mb = 1024;
};

std::string_view to_string(CaptureStamps stamps);

// Throws rigcal::Error naming the file, line and key for a malformed file, an unknown key, a
// folder other than camera_left / camera_right, a camera without id, two cameras with the same
// id, or a value out of range.
CaptureConfig parse_capture_config(std::string_view text, std::string_view file_name);
CaptureConfig read_capture_config(const std::filesystem::path& path);

}  // namespace rigcal::io
