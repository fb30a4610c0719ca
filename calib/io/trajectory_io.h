#pragma once
// Trajectory files (doc/formats.md):
//   tum    "t tx ty tz qx qy qz qw", seconds; '#' comments; spaces, tabs or commas between fields
//   kitti  12 numbers a line, the row-major 3x4 [R | t]; stamps from an optional times file
//   euroc  CSV, "timestamp [ns], px, py, pz, qw, qx, qy, qz, ..." (w first), header lines '#'
//   opencalib  "YYYY-MM-DD-HH-MM-SS-mmm r11 r12 r13 tx r21 ... tz" (OpenCalib's lidar2imu pose
//          files: the stamp, read as UTC, then the row-major 3x4 [R | t])
// Stamps are parsed exactly (calib/core/time.h), never through a double. Every error names the
// file, the line and the field.
#include <filesystem>
#include <string>
#include <string_view>

#include "rigcal/core/trajectory.h"

namespace rigcal::io {

// Every position read lies within this many metres of the origin on each axis.
inline constexpr double kMaxTrajectoryPosition_m = 1e9;

enum class TrajectoryFormat { automatic, tum, kitti, euroc, opencalib };
// auto|tum|kitti|euroc|opencalib
TrajectoryFormat trajectory_format_from_string(std::string_view name);
std::string_view to_string(TrajectoryFormat format);

struct TrajectoryReadOptions {
  TrajectoryFormat format = TrajectoryFormat::automatic;
  // KITTI: a file of one time (s) a line, as many lines as poses. Empty: frame indices.
  std::filesystem::path kitti_times;
  // Equal stamps: an error naming both lines (error), keep the first pose (drop), or keep them all
  // (keep: what the VBR evaluator does; stamps then only need to be non-decreasing).
  enum class Duplicates { error, drop, keep } duplicates = Duplicates::error;
};

// "error" | "drop" | "keep"; throws rigcal::Error naming the option otherwise.
TrajectoryReadOptions::Duplicates duplicates_from_string(std::string_view name);

struct TrajectoryFile {
  Trajectory trajectory;
  TrajectoryFormat format = TrajectoryFormat::tum;  // the format read (after detection)
  size_t duplicate_stamps = 0;                      // dropped or kept, by `duplicates`
};

// Automatic detection: EuRoC when a header names "[ns]" or "p_RS_R", or when the file ends in
// .csv and its stamps are integers; else 12 fields make KITTI, 8 make TUM, and 13 whose first is a
// dashed date make OpenCalib.
TrajectoryFile parse_trajectory(std::string_view text, std::string_view file_name,
                                const TrajectoryReadOptions& options = {});
TrajectoryFile read_trajectory(const std::filesystem::path& path,
                               const TrajectoryReadOptions& options = {});

// TUM text with stamps in seconds to the nanosecond, numbers lossless.
std::string trajectory_to_tum(const Trajectory& trajectory);

}  // namespace rigcal::io
