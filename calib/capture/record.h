#pragma once
// Recording a calibration session's cameras (doc/capture.md): each camera configured through its
// GenICam features and read back, streamed in a thread of its own, its frames written by another
// in the session layout (camera_left/data/0000000000.png, timestamps.txt) with frames.csv (each
// file's camera frame id and both stamps), missing frames counted and listed, the cameras' frames
// paired by trigger, capture.json the report. A stop (Ctrl-C, the frames or the time asked, a
// camera lost) leaves every frame received on disk with its stamp: the recording is usable.
#include <atomic>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/capture/assist.h"
#include "rigcal/capture/camera.h"
#include "rigcal/io/capture_config.h"

namespace rigcal::capture {

// Configures one camera as `config` says (doc/capture.md: the order, the names tried). Throws
// rigcal::Error naming the camera and every required feature absent or refused; otherwise
// returns every feature's result.
std::vector<FeatureResult> configure(Camera& camera, const io::CaptureCameraConfig& config);

// A run of missing frame ids: `count` frames from `first_id`, missing after file `after_file`
// (-1: before the first file).
struct FrameGap {
  long after_file = -1;
  uint64_t first_id = 0;
  uint64_t count = 0;
};

// What a frame id says after the previous one: how many ids were skipped (the frames missing),
// from which, or that it went back (the camera restarted its count). GigE Vision ids (gige16) are
// 16 bits: 1..65535, 0 never used, 65535 followed by 1.
struct IdStep {
  uint64_t missing = 0, first_missing = 0;
  bool backwards = false;
};
IdStep id_step(uint64_t previous, uint64_t id, bool gige16);

struct CameraRecord {
  std::string folder;
  CameraInfo info;
  std::vector<FeatureResult> features;
  std::string pixel_format, trigger;
  size_t written = 0;     // files on disk, each with its line in timestamps.txt
  size_t incomplete = 0;  // buffers received damaged (missing packets, ...): not written
  std::vector<std::string> incomplete_statuses;  // "frame id: status", the first 100
  uint64_t missing = 0;                          // frame ids never received (gaps)
  std::vector<FrameGap> gaps;
  size_t triggers_sent = 0;              // software triggers the camera took
  size_t trigger_failures = 0;           // software triggers it refused
  std::vector<std::string> id_restarts;  // ids that went back ("12 after 4071")
  std::vector<Time> stamps;              // of the files written, the chosen clock
  double receive_cpu_s = 0, write_cpu_s = 0;
  size_t max_queue = 0;       // frames waiting for the writer at most
  double max_waiting_mb = 0;  // and their megabytes (MiB)
  std::string error;          // the camera lost, a write failed
};

struct CaptureRun {
  std::filesystem::path out;
  io::CaptureConfig config;
  std::vector<CameraRecord> cameras;
  double seconds = 0;
  std::string stopped_by;  // frames, duration, interrupt, error
  std::string error;       // "" when the recording ended as asked
  // Two cameras: the frames paired by trigger (nearest stamps within half the frame interval).
  size_t pairs = 0;
  double max_pair_difference_s = 0;      // of the pairs' stamps
  std::vector<CameraCoverage> coverage;  // with assistance: what the views covered at the end
};

struct RecordProgress {
  double seconds = 0;
  std::vector<size_t> written;
  std::vector<uint64_t> missing;
};

struct RecordOptions {
  io::CaptureConfig config;
  std::filesystem::path out;     // the recording folder: created; refused when it holds anything
  std::optional<size_t> frames;  // stop once every camera has this many frames
  std::optional<double> duration_s;                     // stop after this long
  const std::atomic<bool>* interrupt = nullptr;         // set by the caller (Ctrl-C): stop cleanly
  std::function<void(const RecordProgress&)> progress;  // about once a second
  // Calibration assistance (assist.h) on the recorded frames; its PNG is written as
  // OUT/coverage.png unless `assist->png` says otherwise. Its raw Bayer pattern, when none is
  // given, is the first camera's pixel format's.
  std::optional<AssistOptions> assist;
  std::function<void(const std::vector<CameraCoverage>&)> on_coverage;  // about once a second
  // Called with each camera once it is configured, before streaming (the tests attach their
  // simulators' images through it).
  std::function<void(const io::CaptureCameraConfig&, Camera&)> on_configured;
};

// Opens and configures every camera (throws rigcal::Error before anything is written when one is
// missing or refuses a required feature), records, and writes capture.json. A camera lost or a
// write failing mid-recording does not throw: the run's `error` says it, and what was recorded
// is on disk.
CaptureRun record(const RecordOptions& options);

nlohmann::json capture_report(const CaptureRun& run);
// The raw mosaic's pattern for `rigcal calibrate --bayer` ("rggb"), "" for other formats.
std::string bayer_pattern(const std::string& pixel_format);

}  // namespace rigcal::capture
