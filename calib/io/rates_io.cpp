#include "rigcal/io/rates_io.h"

#include <fmt/format.h>

#include <cmath>

#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/io/files.h"
#include "rigcal/io/trajectory_io.h"

namespace rigcal::io {
namespace fs = std::filesystem;
namespace {

// A gyroscope's sample beyond any sensor's range (MEMS gyros end at 35 rad/s, 2000 deg/s) is a
// damaged row or a file in deg/s, not a motion to correlate.
void check_gyro_range(const Eigen::Vector3d& w, std::string_view file, int line) {
  if (w.cwiseAbs().maxCoeff() > time_sync::kMaxGyroRate) {
    fail_at(file, line, "",
            fmt::format("angular rate of {} rad/s, beyond any gyroscope ({} rad/s); damaged, or "
                        "in deg/s (rigcal reads rad/s)",
                        format_double(w.cwiseAbs().maxCoeff()), time_sync::kMaxGyroRate));
  }
}

using Format = RateReadOptions::Format;
using TimeUnit = RateReadOptions::TimeUnit;

Time parse_stamp(std::string_view text, TimeUnit unit, std::string_view file, int line) {
  try {
    if (unit == TimeUnit::nanoseconds) return parse_nanoseconds(text);
    if (unit == TimeUnit::seconds) return parse_seconds(text);
    const bool integer =
        !text.empty() && text.find_first_not_of("0123456789-") == std::string_view::npos;
    const size_t digits = text.size() - (text.front() == '-');
    if (integer && digits >= 13) return parse_nanoseconds(text);
    return parse_time(text);
  } catch (const Error& e) {
    fail_at(file, line, "", fmt::format("time field '{}': {}", text, e.what()));
  }
}

// Column roles of a table: indices of t, wx, wy, wz.
struct Columns {
  int t = 0, w[3] = {1, 2, 3};
  size_t min_fields = 4;
};

Columns parse_columns(std::string_view spec) {
  Columns c;
  c.t = c.w[0] = c.w[1] = c.w[2] = -1;
  const std::vector<std::string_view> names = split_fields(spec);
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string_view n = names[i];
    const int idx = static_cast<int>(i);
    if (n == "t")
      c.t = idx;
    else if (n == "wx")
      c.w[0] = idx;
    else if (n == "wy")
      c.w[1] = idx;
    else if (n == "wz")
      c.w[2] = idx;
    else if (n != "-" && n != "ax" && n != "ay" && n != "az")
      throw Error(
          fmt::format("--columns '{}': unknown column '{}'; use t, wx, wy, wz, ax, ay, az "
                      "or - (skip)",
                      spec, n));
  }
  if (c.t < 0 || c.w[0] < 0 || c.w[1] < 0 || c.w[2] < 0)
    throw Error(fmt::format("--columns '{}' must name t, wx, wy and wz", spec));
  c.min_fields = names.size();
  return c;
}

RateFile read_table(const std::string& text, const std::string& file, const RateReadOptions& opt,
                    const Columns& cols) {
  RateFile out;
  out.format = "table";
  const std::vector<TextLine> lines = data_lines(text, nullptr);
  if (lines.empty()) fail_at(file, 0, "", "no samples: the file is empty or all comments");
  for (const TextLine& line : lines) {
    const std::vector<std::string_view> f = split_fields(line.text);
    if (f.size() < cols.min_fields) {
      fail_at(file, line.number, "",
              fmt::format("{} fields, expected at least {} (columns t, wx, wy, wz unless "
                          "--columns says otherwise)",
                          f.size(), cols.min_fields));
    }
    out.rates.stamps.push_back(parse_stamp(f[cols.t], opt.time_unit, file, line.number));
    Eigen::Vector3d w;
    for (int a = 0; a < 3; ++a) {
      try {
        w[a] = parse_double(f[cols.w[a]], "angular rate");
      } catch (const Error& e) {
        fail_at(file, line.number, "", fmt::format("field {}: {}", cols.w[a] + 1, e.what()));
      }
    }
    check_gyro_range(w, file, line.number);
    out.rates.rates.push_back(w);
  }
  return out;
}

RateFile read_vbr(const fs::path& dir) {
  const fs::path data = dir / "data" / "imu.txt", stamps = dir / "timestamps.txt";
  const std::string text = read_text_file(data), stamp_text = read_text_file(stamps);
  std::string headers;
  const std::vector<TextLine> lines = data_lines(text, &headers);
  const std::vector<TextLine> stamp_lines = data_lines(stamp_text, nullptr);
  const std::vector<std::string_view> names = split_fields(headers);
  // The angular rate's columns: vbr-devkit's own header names them gyr_x, gyr_y, gyr_z (its
  // later names repeat, so only these are looked up); the ROS message's field names
  // angular_velocity.x, .y, .z are read too. The first match of each counts.
  int w[3] = {-1, -1, -1};
  for (size_t i = 0; i < names.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      if (w[a] < 0 && (names[i] == std::string("angular_velocity.") + "xyz"[a] ||
                       names[i] == std::string("gyr_") + "xyz"[a]))
        w[a] = static_cast<int>(i);
    }
  }
  if (w[0] < 0 || w[1] < 0 || w[2] < 0) {
    fail_at(data.string(), 1, "",
            "the IMU header must name gyr_x, gyr_y and gyr_z (vbr-devkit) or angular_velocity.x, "
            "angular_velocity.y and angular_velocity.z");
  }
  if (lines.size() != stamp_lines.size()) {
    throw Error(fmt::format("{} has {} samples but {} has {} stamps", data.string(), lines.size(),
                            stamps.string(), stamp_lines.size()));
  }
  RateFile out;
  out.format = "vbr";
  for (size_t k = 0; k < lines.size(); ++k) {
    out.rates.stamps.push_back(parse_stamp(stamp_lines[k].text, TimeUnit::automatic,
                                           stamps.string(), stamp_lines[k].number));
    const std::vector<std::string_view> f = split_fields(lines[k].text);
    if (f.size() != names.size()) {
      fail_at(data.string(), lines[k].number, "",
              fmt::format("{} fields, the header names {}", f.size(), names.size()));
    }
    Eigen::Vector3d v;
    for (int a = 0; a < 3; ++a) {
      try {
        v[a] = parse_double(f[w[a]], "angular rate");
      } catch (const Error& e) {
        fail_at(data.string(), lines[k].number, "", e.what());
      }
    }
    check_gyro_range(v, data.string(), lines[k].number);
    out.rates.rates.push_back(v);
  }
  return out;
}

RateFile read_pose_rates(const fs::path& path) {
  TrajectoryReadOptions topt;
  topt.duplicates = TrajectoryReadOptions::Duplicates::drop;
  const TrajectoryFile tf = read_trajectory(path, topt);
  if (!tf.trajectory.has_stamps) {
    throw Error(
        fmt::format("{}: the trajectory has no stamps (KITTI poses need a times file); "
                    "angular rates need time",
                    path.string()));
  }
  RateFile out;
  out.format = fmt::format("trajectory ({})", to_string(tf.format));
  out.rates = time_sync::angular_rates_from_trajectory(tf.trajectory);
  out.notes.push_back(fmt::format(
      "{}: angular rates from {} consecutive orientations (mean rate over each {:.4f} s step)",
      path.filename().string(), tf.trajectory.stamps.size(), out.rates.averaging_s));
  if (tf.duplicate_stamps) {
    out.notes.push_back(fmt::format("{}: {} poses with repeated stamps dropped",
                                    path.filename().string(), tf.duplicate_stamps));
  }
  return out;
}

// 8 fields whose last four are a unit quaternion: a TUM pose line.
bool looks_like_tum(const std::string& text) {
  const std::vector<TextLine> lines = data_lines(text, nullptr);
  if (lines.empty()) return false;
  const std::vector<std::string_view> f = split_fields(lines.front().text);
  if (f.size() != 8) return false;
  double n2 = 0;
  for (int i = 4; i < 8; ++i) {
    try {
      const double q = parse_double(f[i], "q");
      n2 += q * q;
    } catch (const Error&) {
      return false;
    }
  }
  return std::abs(std::sqrt(n2) - 1.0) < 1e-3;
}

}  // namespace

RateReadOptions::Format rate_format_from_string(std::string_view name) {
  if (name == "auto") return Format::automatic;
  if (name == "vbr") return Format::vbr;
  if (name == "table") return Format::table;
  if (name == "trajectory") return Format::trajectory;
  throw Error(
      fmt::format("unknown rate format '{}'; expected auto, vbr, table or trajectory", name));
}

RateFile read_rates(const fs::path& path, const RateReadOptions& opt) {
  RateFile out;
  Format format = opt.format;
  fs::path vbr_dir;
  std::string text;
  if (fs::is_directory(path)) {
    vbr_dir = path;
    format = Format::vbr;
  } else {
    text = read_text_file(path);
    const size_t eol = text.find('\n');
    const bool vbr_header = text.rfind("linear_acceleration.x", 0) == 0 ||
                            text.rfind("acc_x,", 0) == 0 || text.find("angular_velocity.x") < eol ||
                            text.find("gyr_x") < eol;
    if (format == Format::vbr || (format == Format::automatic && vbr_header)) {
      format = Format::vbr;
      vbr_dir = path.parent_path().parent_path();  // <dir>/data/imu.txt
    } else if (format == Format::automatic) {
      format = opt.columns.empty() && looks_like_tum(text) ? Format::trajectory : Format::table;
    }
  }
  if (format == Format::vbr) {
    out = read_vbr(vbr_dir);
  } else if (format == Format::trajectory) {
    out = read_pose_rates(path);
  } else {
    Columns cols;
    if (!opt.columns.empty()) {
      cols = parse_columns(opt.columns);
    } else {
      const std::vector<TextLine> lines = data_lines(text, nullptr);
      const size_t n = lines.empty() ? 0 : split_fields(lines.front().text).size();
      if (n != 4 && n != 7) {
        fail_at(path.string(), lines.empty() ? 0 : lines.front().number, "",
                fmt::format("{} fields: expected t wx wy wz [ax ay az] (4 or 7 fields); give the "
                            "columns (--columns wx,wy,wz,-,t) or the format",
                            n));
      }
    }
    out = read_table(text, path.string(), opt, cols);
  }
  try {
    out.merged = time_sync::merge_equal_stamps(out.rates);
  } catch (const Error& e) {
    throw Error(fmt::format("{}: {}", path.string(), e.what()));
  }
  if (const size_t spikes =
          format == Format::trajectory ? 0 : time_sync::repair_spikes(out.rates)) {
    out.notes.push_back(fmt::format(
        "{}: {} isolated samples far from both neighbours (rows swapped or damaged in the log) "
        "replaced by their neighbours' mean",
        path.filename().string(), spikes));
  }
  if (out.merged) {
    out.notes.push_back(fmt::format(
        "{}: {} samples share a stamp with the previous one (too few digits in the log); each "
        "group was replaced by its mean",
        path.filename().string(), out.merged));
  }
  return out;
}

std::vector<fs::path> rate_files(const fs::path& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) return {path / "timestamps.txt", path / "data" / "imu.txt"};
  if (path.parent_path().filename() == "data")
    return {path, path.parent_path().parent_path() / "timestamps.txt"};
  return {path};
}

}  // namespace rigcal::io
