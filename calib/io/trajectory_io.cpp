#include "rigcal/io/trajectory_io.h"

#include <fmt/format.h>

#include <array>
#include <cctype>

#include "rigcal/core/error.h"
#include "rigcal/core/memory.h"
#include "rigcal/core/text.h"
#include "rigcal/io/files.h"

namespace rigcal::io {
namespace {

constexpr const char* kTumFields[] = {"t", "tx", "ty", "tz", "qx", "qy", "qz", "qw"};
constexpr const char* kEurocFields[] = {"timestamp", "px", "py", "pz", "qw", "qx", "qy", "qz"};

bool is_integer_text(std::string_view s) {
  if (s.empty()) return false;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
  }
  return true;
}

// OpenCalib's stamp, "2021-10-26-16-21-29-468": 7 dash-separated integers.
bool is_dashed_date(std::string_view s) {
  int dashes = 0;
  for (char c : s) {
    if (c == '-') {
      ++dashes;
    } else if (c < '0' || c > '9') {
      return false;
    }
  }
  return dashes == 6 && s.size() == 23;
}

constexpr size_t kMaxFields = 16;
using Fields = std::array<std::string_view, kMaxFields>;

TrajectoryFormat detect(std::string_view first_line, int line_number, const std::string& headers,
                        std::string_view file_name) {
  if (headers.find("[ns]") != std::string::npos || headers.find("p_RS_R") != std::string::npos) {
    return TrajectoryFormat::euroc;
  }
  Fields fields;
  const size_t n = split_fields(first_line, fields);
  const bool csv = file_name.size() >= 4 && file_name.substr(file_name.size() - 4) == ".csv";
  if (csv && n >= 8 && is_integer_text(fields[0])) return TrajectoryFormat::euroc;
  if (n == 12) return TrajectoryFormat::kitti;
  if (n == 8) return TrajectoryFormat::tum;
  if (n == 13 && is_dashed_date(fields[0])) return TrajectoryFormat::opencalib;
  fail_at(file_name, line_number, "",
          fmt::format("cannot tell the trajectory format from {} fields (TUM has 8, KITTI 12, "
                      "EuRoC CSV 8 or more with integer ns stamps, OpenCalib 13 with a dashed "
                      "date); give --format",
                      n));
}

[[noreturn]] void field_error(std::string_view file, int line, size_t field, std::string_view name,
                              std::string_view what) {
  fail_at(file, line, "", fmt::format("field {} ({}): {}", field + 1, name, what));
}

double number(std::string_view file, int line, const Fields& f, size_t i, std::string_view name) {
  try {
    return parse_double(f[i], name);
  } catch (const Error&) {
    field_error(file, line, i, name, fmt::format("expected a finite number, got '{}'", f[i]));
  }
}

Eigen::Quaterniond quaternion(std::string_view file, int line, double w, double x, double y,
                              double z) {
  const Eigen::Quaterniond q(w, x, y, z);
  const double norm = q.norm();
  if (!(norm > 1e-6)) fail_at(file, line, "", "zero quaternion");
  if (std::abs(norm - 1.0) > 1e-2) {
    fail_at(file, line, "",
            fmt::format("quaternion norm {:.6g} is far from 1: a wrong field order?", norm));
  }
  return q;
}

constexpr const char* kMatrixFields[] = {"r11", "r12", "r13", "r14", "r21", "r22",
                                         "r23", "r24", "r31", "r32", "r33", "r34"};

// A trajectory file read a line at a time, from a whole text or from a file's blocks.
struct PoseReader {
  PoseReader(std::string_view name, const TrajectoryReadOptions& o) : file_name(name), options(o) {}
  std::string_view file_name;
  const TrajectoryReadOptions& options;
  TrajectoryFile out;
  std::string headers;  // comment lines and the header before the first pose
  int line_number = 0;
  int n_data_lines = 0;
  int last_pose_line = 0;
  size_t file_bytes = 0;  // for a reserve: the file's size over its first line's

  void feed(std::string_view block) {
    size_t pos = 0;
    while (pos < block.size()) {
      size_t end = block.find('\n', pos);
      if (end == std::string_view::npos) end = block.size();
      const std::string_view line = trim(block.substr(pos, end - pos));
      ++line_number;
      if (!line.empty()) {
        if (line.front() == '#' ||
            (n_data_lines == 0 && std::isalpha(static_cast<unsigned char>(line.front())))) {
          if (n_data_lines == 0) headers += std::string(line) + "\n";
        } else {
          if (n_data_lines++ == 0) first(line, end - pos + 1);
          pose(line);
        }
      }
      pos = end + 1;
    }
  }

  void first(std::string_view line, size_t line_bytes) {
    out.format = options.format == TrajectoryFormat::automatic
                     ? detect(line, line_number, headers, file_name)
                     : options.format;
    if (file_bytes > 0) {
      // A fifth more than the first line's length says: a vector that outgrows its reserve
      // doubles into fresh small pages (a 96 MB copy at a million poses). Pages never touched
      // cost nothing.
      const size_t n = file_bytes / std::max<size_t>(line_bytes, 40) * 6 / 5 + 1024;
      reserve_huge(out.trajectory.stamps, n);
      reserve_huge(out.trajectory.T_world_body, n);
    }
  }

  void pose(std::string_view text) {
    Fields f;
    const size_t n = split_fields(text, f);
    Trajectory& traj = out.trajectory;
    const int line = line_number;
    SE3 T;
    Time stamp;
    switch (out.format) {
      case TrajectoryFormat::tum: {
        if (n != 8) {
          fail_at(file_name, line, "",
                  fmt::format("expected 8 fields 't tx ty tz qx qy qz qw' (TUM), got {}", n));
        }
        try {
          stamp = parse_seconds(f[0], "t");
        } catch (const Error&) {
          field_error(file_name, line, 0, "t", fmt::format("expected seconds, got '{}'", f[0]));
        }
        double v[8];
        for (size_t i = 1; i < 8; ++i) v[i] = number(file_name, line, f, i, kTumFields[i]);
        T = SE3::from_quaternion(quaternion(file_name, line, v[7], v[4], v[5], v[6]),
                                 Eigen::Vector3d(v[1], v[2], v[3]));
        break;
      }
      case TrajectoryFormat::euroc: {
        if (n < 8) {
          fail_at(file_name, line, "",
                  fmt::format("expected at least 8 fields 'timestamp[ns], px, py, pz, qw, qx, qy, "
                              "qz' (EuRoC), got {}",
                              n));
        }
        try {
          stamp = parse_nanoseconds(f[0], "timestamp");
        } catch (const Error&) {
          field_error(file_name, line, 0, "timestamp",
                      fmt::format("expected integer nanoseconds, got '{}'", f[0]));
        }
        double v[8];
        for (size_t i = 1; i < 8; ++i) v[i] = number(file_name, line, f, i, kEurocFields[i]);
        T = SE3::from_quaternion(quaternion(file_name, line, v[4], v[5], v[6], v[7]),
                                 Eigen::Vector3d(v[1], v[2], v[3]));
        break;
      }
      case TrajectoryFormat::kitti:
      case TrajectoryFormat::opencalib: {
        const bool oc = out.format == TrajectoryFormat::opencalib;
        const size_t first = oc ? 1 : 0;
        if (n != 12 + first) {
          fail_at(
              file_name, line, "",
              oc ? fmt::format("expected a stamp YYYY-MM-DD-HH-MM-SS-mmm and 12 numbers "
                               "(OpenCalib: row-major 3x4 [R | t]), got {} fields",
                               n)
                 : fmt::format("expected 12 numbers (KITTI: row-major 3x4 [R | t]), got {}", n));
        }
        Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
        for (size_t i = 0; i < 12; ++i) {
          m(i / 4, i % 4) = number(file_name, line, f, first + i, kMatrixFields[i]);
        }
        T = SE3::from_matrix(m);  // kept as read, as the KITTI devkit and evo use it
        const double err = orthonormality_error(T.R);
        if (err > 1e-3 || T.R.determinant() < 0) {
          fail_at(file_name, line, "",
                  fmt::format("the 3x3 block is not a rotation (max |R^T R - I| = {:.3g})", err));
        }
        stamp = Time{static_cast<int64_t>(traj.size()) * 1000000000LL};
        if (oc) {
          std::string iso(f[0]);
          if (!is_dashed_date(iso)) {
            field_error(file_name, line, 0, "stamp",
                        fmt::format("expected YYYY-MM-DD-HH-MM-SS-mmm, got '{}'", f[0]));
          }
          iso[10] = 'T', iso[13] = ':', iso[16] = ':', iso[19] = '.';
          try {
            stamp = parse_iso8601(iso, "stamp");
          } catch (const Error& e) {
            field_error(file_name, line, 0, "stamp", e.what());
          }
        }
        break;
      }
      case TrajectoryFormat::automatic:
        break;
    }
    // Beyond any trajectory (the Moon is 4e8 m away); squares of such numbers overflow.
    if (!(T.t.cwiseAbs().maxCoeff() <= kMaxTrajectoryPosition_m)) {
      fail_at(file_name, line, "",
              fmt::format("position ({}, {}, {}) m lies beyond {:g} m from the origin", T.t.x(),
                          T.t.y(), T.t.z(), kMaxTrajectoryPosition_m));
    }
    if (out.format != TrajectoryFormat::kitti && !traj.stamps.empty() &&
        stamp <= traj.stamps.back()) {
      using D = TrajectoryReadOptions::Duplicates;
      if (stamp == traj.stamps.back() && options.duplicates != D::error) {
        ++out.duplicate_stamps;
        if (options.duplicates == D::drop) return;
      } else {
        fail_at(
            file_name, line, "",
            fmt::format("stamp {} is {} the previous one ({} s, line {}); stamps must increase{}",
                        f[0], stamp == traj.stamps.back() ? "equal to" : "before",
                        to_seconds_text(traj.stamps.back()), last_pose_line,
                        stamp == traj.stamps.back() ? " (--duplicate-stamps drop|keep)" : ""));
      }
    }
    if (traj.size() == traj.T_world_body.capacity()) {  // past the reserve: grow by half
      reserve_huge(traj.stamps, traj.size() * 3 / 2 + 1024);
      reserve_huge(traj.T_world_body, traj.size() * 3 / 2 + 1024);
    }
    traj.stamps.push_back(stamp);
    traj.T_world_body.push_back(T);
    last_pose_line = line;
  }

  TrajectoryFile finish() {
    if (n_data_lines == 0) fail_at(file_name, 0, "", "no poses: the file is empty or all comments");
    Trajectory& traj = out.trajectory;
    if (out.format == TrajectoryFormat::kitti) {
      traj.has_stamps = false;
      if (!options.kitti_times.empty()) read_kitti_times(traj);
    }
    return std::move(out);
  }

  void read_kitti_times(Trajectory& traj) const {
    const std::string times_text = read_text_file(options.kitti_times);
    const std::string times_name = options.kitti_times.string();
    std::string_view times_view = times_text;
    if (times_view.starts_with("\xEF\xBB\xBF")) times_view.remove_prefix(3);
    const std::vector<TextLine> times = rigcal::data_lines(times_view, nullptr);
    if (times.size() != traj.size()) {
      fail_at(times_name, 0, "",
              fmt::format("{} times for {} poses of {}", times.size(), traj.size(), file_name));
    }
    for (size_t i = 0; i < times.size(); ++i) {
      try {
        traj.stamps[i] = parse_seconds(split_fields(times[i].text).at(0), "time");
      } catch (const std::exception&) {
        fail_at(times_name, times[i].number, "",
                fmt::format("expected a time in seconds, got '{}'", times[i].text));
      }
      if (i > 0 && traj.stamps[i] <= traj.stamps[i - 1]) {
        fail_at(times_name, times[i].number, "", "times must increase");
      }
    }
    traj.has_stamps = true;
  }
};

}  // namespace

TrajectoryFormat trajectory_format_from_string(std::string_view name) {
  for (TrajectoryFormat f :
       {TrajectoryFormat::automatic, TrajectoryFormat::tum, TrajectoryFormat::kitti,
        TrajectoryFormat::euroc, TrajectoryFormat::opencalib}) {
    if (name == to_string(f)) return f;
  }
  throw Error(fmt::format(
      "unknown trajectory format '{}'; expected auto, tum, kitti, euroc or opencalib", name));
}

TrajectoryReadOptions::Duplicates duplicates_from_string(std::string_view name) {
  using D = TrajectoryReadOptions::Duplicates;
  if (name == "error") return D::error;
  if (name == "drop") return D::drop;
  if (name == "keep") return D::keep;
  throw Error(fmt::format("--duplicate-stamps: expected error, drop or keep, got '{}'", name));
}

std::string_view to_string(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::automatic:
      return "auto";
    case TrajectoryFormat::tum:
      return "tum";
    case TrajectoryFormat::kitti:
      return "kitti";
    case TrajectoryFormat::euroc:
      return "euroc";
    case TrajectoryFormat::opencalib:
      return "opencalib";
  }
  return "?";
}

TrajectoryFile parse_trajectory(std::string_view text, std::string_view file_name,
                                const TrajectoryReadOptions& options) {
  // A UTF-8 byte-order mark (editors on Windows write one) is not part of the first line.
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
  PoseReader reader(file_name, options);
  reader.file_bytes = text.size();
  reader.feed(text);
  return reader.finish();
}

TrajectoryFile read_trajectory(const std::filesystem::path& path,
                               const TrajectoryReadOptions& options) {
  // In blocks: a file of a million poses is read without holding its 100 MB of text.
  const std::string name = path.string();
  PoseReader reader(name, options);
  reader.file_bytes = file_size_or_zero(path);
  bool first_block = true;
  read_text_blocks(path, [&](std::string_view block) {
    if (first_block && block.starts_with("\xEF\xBB\xBF")) block.remove_prefix(3);
    first_block = false;
    reader.feed(block);
  });
  return reader.finish();
}

std::string trajectory_to_tum(const Trajectory& trajectory) {
  std::string out;
  out.reserve(trajectory.size() * 120);
  for (size_t i = 0; i < trajectory.size(); ++i) {
    out += to_seconds_text(trajectory.stamps[i]);
    out += ' ';
    out += to_text(trajectory.T_world_body[i]);
    out += '\n';
  }
  return out;
}

}  // namespace rigcal::io
