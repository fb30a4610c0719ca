#pragma once
// Readers of angular-rate streams for the time-offset step (doc/time-offset.md):
//  - the vbr-devkit IMU folder (timestamps.txt of ISO-8601 stamps + data/imu.txt, a CSV with a
//    header and 37 columns), given as the folder or as its data/imu.txt;
//  - a text table, one sample a line, fields separated by spaces, tabs or commas, '#' comments
//    and one header line allowed; columns `t, wx, wy, wz[, ax, ay, az]` unless `columns` says
//    otherwise ("wx,wy,wz,-,t": '-' skips a field);
//  - a pose trajectory (TUM, EuRoC, or KITTI with times; 8 fields with a unit quaternion are
//    taken as TUM): rates from consecutive orientations.
// Time fields: decimal seconds, integer nanoseconds (integers of 13 digits or more) or
// ISO-8601. Samples sharing a stamp (logs printed with too few digits) are merged into their mean.
#include <filesystem>
#include <string>
#include <vector>

#include "rigcal/time_sync/time_sync.h"

namespace rigcal::io {

struct RateReadOptions {
  enum class Format { automatic, vbr, table, trajectory } format = Format::automatic;
  std::string columns;  // table only; empty: t,wx,wy,wz (4 or 7 fields)
  enum class TimeUnit { automatic, seconds, nanoseconds } time_unit = TimeUnit::automatic;
};

struct RateFile {
  time_sync::AngularRates rates;
  std::string format;              // "vbr", "table", "trajectory (tum)", ...
  size_t merged = 0;               // samples merged into others (equal stamps)
  std::vector<std::string> notes;  // what the reader assumed or did
};

// Throws rigcal::Error naming the file and line on bad input.
RateFile read_rates(const std::filesystem::path& path, const RateReadOptions& options = {});

// The files read_rates reads for `path`: a vbr-devkit folder's timestamps.txt and data/imu.txt;
// a file itself, with its folder's timestamps.txt when it is a devkit data/imu.txt.
std::vector<std::filesystem::path> rate_files(const std::filesystem::path& path);

RateReadOptions::Format rate_format_from_string(
    std::string_view name);  // auto|vbr|table|trajectory

}  // namespace rigcal::io
