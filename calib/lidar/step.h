#pragma once
// The odometry step (doc/odometry.md): the scans of a recording, streamed one at a time through
// the odometry, with the trajectory, the per-step covariances and a report as the result.
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rigcal/core/scan.h"
#include "rigcal/io/odometry_io.h"
#include "rigcal/lidar/odometry.h"
#include "rigcal/report/step.h"
#include "rigcal/rig/rig.h"

namespace rigcal::lidar {

// The scans a path given by the user stands for: an Ouster capture itself (CAPTURE.pcap, read as
// it streams with CAPTURE.json beside it), a topic folder (data/ with .bin or .pcd and
// timestamps.txt), else its ouster_points/ (a recording), a ROS1 bag or a folder of bags with a
// PointCloud2 topic (read as they stream, io/bag_scans.h), else the ouster_points/ of the
// session's motion recording, then of its lidar_camera recording (io::read_session: bags of
// Ouster packets are converted first); or a KITTI odometry sequence (velodyne/ and times.txt,
// read in place).
// Throws rigcal::Error saying what was looked for.
std::filesystem::path scans_folder(const std::filesystem::path& given,
                                   const report::Progress& progress = {});

// The scans of `scans` (a folder, a capture or bags, as scans_folder gives), one at a time in
// stamp order: a folder's stamps from its timestamps.txt (each sweep's first point, the time its
// per-point times count from), a capture's from the sensor (its first valid column's), the capture
// assembled packet by packet as it streams; bags' from their messages' header stamps. Throws
// rigcal::Error naming the file on a scan not read.
class ScanStream {
 public:
  explicit ScanStream(const std::filesystem::path& scans);
  ~ScanStream();
  ScanStream(const ScanStream&) = delete;
  ScanStream& operator=(const ScanStream&) = delete;
  std::optional<Scan> next();
  // Moves past the scans stamped before `stamp` without reading them, where the source allows it
  // (a folder: its stamps are known before its files are read); a capture or bags are not moved
  // (their scans are then read through by next()). Returns how many were skipped.
  size_t skip_before(Time stamp);
  size_t read() const { return read_; }
  size_t total() const;        // of a folder or bags; 0 for a capture (not known before the end)
  std::string source() const;  // the file of the last scan read, or the capture
  // What the stream saw that its reader should say: the scans without point times, a capture's
  // counters (once the stream is done).
  std::vector<std::string> notes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  size_t read_ = 0;
};

// A run stops (rigcal::Error) when this many scans in a row share no surface with the map: the
// odometry is lost, and a trajectory that jumps would be worse than none.
inline constexpr size_t kMaxScansLost = 10;

struct OdometryRun {
  std::filesystem::path scans;
  OdometryConfig config;
  Trajectory T_odom_lidar;
  std::vector<Step> steps;         // one a scan read, skipped ones included (Step::skipped)
  std::vector<std::string> notes;  // what the run assumed or could not do
  double seconds = 0;
};

// Reads and registers every scan of `scans` (a folder or a capture, as scans_folder gives) in
// stamp order; the stamps of timestamps.txt are taken as each sweep's first point, the time its
// per-point times count from (a capture's are the sensor's, its first valid column's). Throws
// rigcal::Error naming the file on a scan not read.
OdometryRun run_odometry(const std::filesystem::path& scans, const OdometryConfig& config,
                         const report::Progress& progress = {});

// The covariance of every motion between consecutive registered scans (skipped scans have none).
std::vector<io::StepCovariance> step_covariances(const OdometryRun& run);

// The preset a step runs the odometry with: `given` when not empty, else the one the rig LiDAR's
// model names (preset_for_model), else os0-128, with a note in `notes` saying so.
std::string choose_preset(const std::string& given, const rig::Sensor* lidar,
                          std::vector<std::string>& notes);

// The report: the configuration, a summary (frames, path length, timing, degenerate steps) and
// one row a step (doc/odometry.md says what each number is).
nlohmann::json odometry_report(const OdometryRun& run);

// The report's figures, rendered from its rows alone (so a stored odometry.json renders again):
// file name and SVG text of each: the residuals and noise level a step (mm), the inlier ratio,
// the degeneracy ratios (log10, with the threshold) and the time a step (ms), over the scans' time.
std::vector<std::pair<std::string, std::string>> odometry_figures(const nlohmann::json& report);

}  // namespace rigcal::lidar
