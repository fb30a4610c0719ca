#pragma once
// The capture step (doc/capture.md): what `rigcal capture` was given turned into a recording's
// options, and the lines a person reads about the cameras and the result. The command parses its
// options, installs Ctrl-C, calls record() and prints these.
#include <atomic>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/capture/record.h"

namespace rigcal::capture {

struct CaptureRequest {
  std::filesystem::path config;  // the capture config, or
  std::string left, right;       // the cameras by id, with the defaults
  std::filesystem::path out;
  std::filesystem::path target;  // assistance with this board ("" none)
  std::string bayer;             // the assistance's mosaic ("" from the pixel format)
  bool fake = false;             // Aravis' in-process fake camera, Fake_1, visible
  std::optional<size_t> frames;  // 0: no limit
  std::optional<double> duration_s;
};

// The recording's options: the config read (or the cameras by id with the defaults), the board
// read for the assistance, the fake interface enabled when asked. Throws rigcal::Error when
// --out is missing, when cameras come from both or neither of the file and the ids, and for a
// config or target file that does not read.
RecordOptions record_options(const CaptureRequest& request, const std::atomic<bool>* interrupt);

// `rigcal capture --list`: each camera, its vendor, model, serial, address and pixel formats.
std::vector<std::string> camera_list_lines(bool include_fake);
// The progress line ("12 s: camera_left 360 frames (2 missing) ...").
std::string progress_line(const RecordProgress& progress, const io::CaptureConfig& config);
// The result: each camera's features as taken and its counts, the pairs and what they mean for
// calibrate, the stop, the assistance's verdict, the Bayer pattern calibrate needs.
std::vector<std::string> summary_lines(const CaptureRun& run);

}  // namespace rigcal::capture
