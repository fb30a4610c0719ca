#include "rigcal/io/gnss_fixes.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <GeographicLib/LocalCartesian.hpp>
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>

#include "rigcal/core/error.h"
#include "rigcal/core/se3.h"
#include "rigcal/core/stats.h"
#include "rigcal/core/text.h"
#include "rigcal/core/time.h"
#include "rigcal/io/files.h"

namespace rigcal::io {
namespace {

std::string lower(std::string_view s) {
  std::string out(trim(s));
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

// The header's column index of each name (first of its aliases), -1 when absent.
enum Column {
  kTime,
  kLat,
  kLon,
  kHeight,
  kRoll,
  kPitch,
  kYaw,
  kStdE,
  kStdN,
  kStdU,
  kStatus,
  kFixType,
  kCovEN,
  kCovEU,
  kCovNU,
  kColumns
};
const std::array<std::vector<std::string_view>, kColumns> kAliases = {{
    {"time", "t", "timestamp", "stamp"},
    {"latitude", "lat"},
    {"longitude", "lon", "lng"},
    {"height", "alt", "altitude", "h"},
    {"roll"},
    {"pitch"},
    {"yaw", "heading", "azimuth"},
    {"std_east", "sigma_east"},
    {"std_north", "sigma_north"},
    {"std_up", "sigma_up"},
    {"status"},
    {"fix_type", "q", "quality"},
    {"cov_en"},
    {"cov_eu"},
    {"cov_nu"},
}};

// RTKLIB's Q codes, or the words.
std::optional<FixType> fix_type_of(std::string_view field) {
  const std::string name = lower(field);
  if (name == "1" || name == "fixed" || name == "fix" || name == "rtk_fixed")
    return FixType::rtk_fixed;
  if (name == "2" || name == "6" || name == "float" || name == "rtk_float")
    return FixType::rtk_float;
  if (name == "5" || name == "3" || name == "4" || name == "single") return FixType::single;
  return std::nullopt;
}

}  // namespace

std::string_view to_string(FixType type) {
  switch (type) {
    case FixType::rtk_fixed:
      return "fixed";
    case FixType::rtk_float:
      return "float";
    case FixType::single:
      return "single";
  }
  return "?";
}

GeodeticOrigin parse_geodetic_origin(std::string_view text, std::string_view what) {
  const std::vector<std::string_view> f = split_fields(text);
  const std::string expected = fmt::format(
      "{}: expected LAT,LON,HEIGHT (degrees, degrees, ellipsoidal m), got '{}'", what, text);
  if (f.size() != 3) throw Error(expected);
  GeodeticOrigin o;
  try {
    o.latitude_deg = parse_double(f[0], "latitude");
    o.longitude_deg = parse_double(f[1], "longitude");
    o.height_m = parse_double(f[2], "height");
  } catch (const Error&) {
    throw Error(expected);
  }
  if (std::abs(o.latitude_deg) > 90 || std::abs(o.longitude_deg) > 180 ||
      !(o.height_m >= -12000 && o.height_m <= 100000)) {
    throw Error(fmt::format(
        "{}: latitude {} / longitude {} / height {} m outside +-90 / +-180 / -12 km..100 km", what,
        o.latitude_deg, o.longitude_deg, o.height_m));
  }
  return o;
}

Attitude attitude_from_string(std::string_view name) {
  if (name == "enu") return Attitude::enu;
  if (name == "ned") return Attitude::ned;
  throw Error(fmt::format("--attitude: expected enu or ned, got '{}'", name));
}

bool is_gnss_fixes_file(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    const std::string_view t = trim(line);
    if (t.empty() || t.front() == '#') continue;
    for (std::string_view f : split_fields(t)) {
      const std::string name = lower(f);
      if (name == "latitude" || name == "lat") return true;
    }
    return false;
  }
  return false;
}

GnssFixes parse_gnss_fixes(std::string_view text, std::string_view file_name,
                           std::optional<Attitude> attitude,
                           const std::optional<GeodeticOrigin>& origin) {
  // The header: the first non-empty, non-comment line.
  std::array<int, kColumns> col;
  col.fill(-1);
  size_t pos = 0;
  int line_no = 0, header_line = 0;
  std::vector<std::pair<int, std::string_view>> rows;
  while (pos <= text.size()) {
    const size_t end = std::min(text.find('\n', pos), text.size());
    const std::string_view line = trim(text.substr(pos, end - pos));
    ++line_no;
    pos = end + 1;
    if (line.empty() || line.front() == '#') continue;
    if (header_line == 0) {
      header_line = line_no;
      const std::vector<std::string_view> names = split_fields(line);
      for (size_t i = 0; i < names.size(); ++i) {
        const std::string name = lower(names[i]);
        for (int c = 0; c < kColumns; ++c) {
          if (col[c] < 0 &&
              std::find(kAliases[c].begin(), kAliases[c].end(), name) != kAliases[c].end())
            col[c] = static_cast<int>(i);
        }
      }
      for (int c = 0; c <= (attitude ? kYaw : kHeight); ++c) {
        if (col[c] < 0) {
          fail_at(file_name, line_no, "",
                  fmt::format("the header has no '{}' column (GNSS fixes need time, latitude, "
                              "longitude, height{})",
                              kAliases[c].front(), attitude ? ", roll, pitch, yaw" : ""));
        }
      }
      continue;
    }
    rows.emplace_back(line_no, line);
  }
  if (rows.empty()) fail_at(file_name, header_line, "", "no fixes after the header");

  GnssFixes out;
  out.has_attitude = attitude.has_value();
  GeographicLib::LocalCartesian enu;
  std::vector<double> std_h, std_v;
  const Eigen::Matrix3d R_enu_ned = (Eigen::Matrix3d() << 0, 1, 0, 1, 0, 0, 0, 0, -1).finished();
  const double deg = M_PI / 180.0;
  for (const auto& row : rows) {
    // Not a structured binding: clang 14 (the sanitizer build) cannot capture one in a lambda.
    const int number = row.first;
    const std::vector<std::string_view> f = split_fields(row.second);
    auto value = [&](Column c) {
      const int i = col[c];
      if (i >= static_cast<int>(f.size())) {
        fail_at(
            file_name, number, "",
            fmt::format("{} fields, no '{}' (column {})", f.size(), kAliases[c].front(), i + 1));
      }
      try {
        return parse_double(f[i], kAliases[c].front());
      } catch (const Error&) {
        fail_at(file_name, number, "",
                fmt::format("column {} ({}): expected a number, got '{}'", i + 1,
                            kAliases[c].front(), f[i]));
      }
    };
    if (col[kTime] >= static_cast<int>(f.size())) {
      fail_at(file_name, number, "", fmt::format("{} fields, no time", f.size()));
    }
    Time stamp;
    try {
      stamp = parse_time(f[col[kTime]], "time");
    } catch (const Error& e) {
      fail_at(file_name, number, "", fmt::format("column {} (time): {}", col[kTime] + 1, e.what()));
    }
    const double lat = value(kLat), lon = value(kLon), h = value(kHeight);
    if (std::abs(lat) > 90 || std::abs(lon) > 360) {
      fail_at(file_name, number, "",
              fmt::format("latitude {} / longitude {} out of range (degrees expected)", lat, lon));
    }
    // A receiver on a rig: between the deepest mine and the edge of space.
    if (!(h >= -12000 && h <= 100000)) {
      fail_at(file_name, number, "",
              fmt::format("height {} m outside -12 km to 100 km (ellipsoidal metres expected)", h));
    }
    if (out.T_enu_gnss.stamps.empty()) {
      out.origin = origin.value_or(GeodeticOrigin{lat, lon, h});
      enu.Reset(out.origin.latitude_deg, out.origin.longitude_deg, out.origin.height_m);
    }
    if (!out.T_enu_gnss.stamps.empty() && stamp <= out.T_enu_gnss.stamps.back()) {
      fail_at(file_name, number, "",
              fmt::format("time {} does not increase (previous {} s)", f[col[kTime]],
                          to_seconds_text(out.T_enu_gnss.stamps.back())));
    }
    SE3 T;
    enu.Forward(lat, lon, h, T.t.x(), T.t.y(), T.t.z());
    if (attitude) {
      const double roll = value(kRoll) * deg, pitch = value(kPitch) * deg, yaw = value(kYaw) * deg;
      T.R = *attitude == Attitude::enu ? from_roll_pitch_yaw(roll, pitch, yaw)
                                       : R_enu_ned * from_roll_pitch_yaw(roll, pitch, yaw);
    }
    out.T_enu_gnss.stamps.push_back(stamp);
    out.T_enu_gnss.T_world_body.push_back(T);
    if (col[kStdE] >= 0 && col[kStdN] >= 0) std_h.push_back(std::hypot(value(kStdE), value(kStdN)));
    if (col[kStdU] >= 0) std_v.push_back(value(kStdU));
    if (col[kStdE] >= 0 && col[kStdN] >= 0 && col[kStdU] >= 0) {
      const Eigen::Vector3d s(value(kStdE), value(kStdN), value(kStdU));
      if (!(s.minCoeff() >= 0) || !s.allFinite()) {
        fail_at(file_name, number, "",
                fmt::format("standard deviations {} {} {}: expected numbers >= 0 (m)", s.x(), s.y(),
                            s.z()));
      }
      out.std_enu_m.push_back(s);
      // The off-diagonal terms (NavSatFix's full covariance, m^2), when given: the matrix must
      // be one (positive semi-definite), a receiver's numbers are not trusted blindly.
      if (col[kCovEN] >= 0 && col[kCovEU] >= 0 && col[kCovNU] >= 0) {
        Eigen::Matrix3d C = s.cwiseProduct(s).asDiagonal();
        C(0, 1) = C(1, 0) = value(kCovEN);
        C(0, 2) = C(2, 0) = value(kCovEU);
        C(1, 2) = C(2, 1) = value(kCovNU);
        const double smallest = C.allFinite() ? Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(
                                                    C, Eigen::EigenvaluesOnly)
                                                    .eigenvalues()
                                                    .minCoeff()
                                              : std::numeric_limits<double>::quiet_NaN();
        if (!(smallest >= -1e-9 * std::max(C.trace(), 1e-300))) {
          fail_at(file_name, number, "",
                  fmt::format("cov_en {} cov_eu {} cov_nu {} with standard deviations {} {} {}: "
                              "not a covariance (its smallest eigenvalue, {:.3g} m^2, is below "
                              "zero)",
                              C(0, 1), C(0, 2), C(1, 2), s.x(), s.y(), s.z(), smallest));
        }
        out.covariance_enu_m2.push_back(C);
      }
    }
    if (col[kStatus] >= 0) {
      const double status = value(kStatus);
      if (status != -1 && status != 0 && status != 1 && status != 2) {
        fail_at(file_name, number, "",
                fmt::format("status {}: expected -1 (no fix), 0 (fix), 1 (SBAS) or 2 (GBAS, RTK)",
                            status));
      }
      out.status.push_back(static_cast<int>(status));
    }
    if (col[kFixType] >= 0) {
      const int i = col[kFixType];
      if (i >= static_cast<int>(f.size())) {
        fail_at(file_name, number, "",
                fmt::format("{} fields, no 'fix_type' (column {})", f.size(), i + 1));
      }
      const std::optional<FixType> type = fix_type_of(f[i]);
      if (!type) {
        fail_at(file_name, number, "",
                fmt::format("column {} (fix_type): expected RTKLIB's Q (1 fixed, 2 float, 3 "
                            "SBAS, 4 DGPS, 5 single, 6 PPP) or fixed, float, single; got '{}'",
                            i + 1, f[i]));
      }
      out.fix_type.push_back(*type);
    }
  }
  if (!std_h.empty()) out.median_horizontal_std_m = median(std_h);
  if (!std_v.empty()) out.median_vertical_std_m = median(std_v);
  return out;
}

GnssFixes read_gnss_fixes(const std::filesystem::path& path, std::optional<Attitude> attitude,
                          const std::optional<GeodeticOrigin>& origin) {
  return parse_gnss_fixes(read_text_file(path), path.string(), attitude, origin);
}

std::string gnss_fixes_csv(const Trajectory& T_enu_gnss,
                           const std::vector<Eigen::Vector3d>& std_enu_m,
                           const std::vector<FixType>& fix_type, const GeodeticOrigin& origin) {
  if (std_enu_m.size() != T_enu_gnss.size() || fix_type.size() != T_enu_gnss.size()) {
    throw Error(fmt::format("{} fixes with {} standard deviations and {} fix types",
                            T_enu_gnss.size(), std_enu_m.size(), fix_type.size()));
  }
  const GeographicLib::LocalCartesian enu(origin.latitude_deg, origin.longitude_deg,
                                          origin.height_m);
  std::string out = "time,latitude,longitude,height,std_east,std_north,std_up,status,fix_type\n";
  for (size_t i = 0; i < T_enu_gnss.size(); ++i) {
    const Eigen::Vector3d& p = T_enu_gnss.T_world_body[i].t;
    double lat = 0, lon = 0, h = 0;
    enu.Reverse(p.x(), p.y(), p.z(), lat, lon, h);
    const Eigen::Vector3d& s = std_enu_m[i];
    out += fmt::format("{},{:.10f},{:.10f},{:.4f},{:.4f},{:.4f},{:.4f},{},{}\n",
                       to_seconds_text(T_enu_gnss.stamps[i]), lat, lon, h, s.x(), s.y(), s.z(),
                       fix_type[i] == FixType::single ? 0 : 2, to_string(fix_type[i]));
  }
  return out;
}

}  // namespace rigcal::io
