#include "rigcal/io/ground_truth_io.h"

#include <fmt/format.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <map>

#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/core/time.h"
#include "rigcal/io/files.h"
#include "rigcal/io/trajectory_io.h"

namespace rigcal::io {

std::string ground_truth_to_text(const Trajectory& T_world_lidar) {
  return "#timestamp tx ty tz qx qy qz qw\n" + trajectory_to_tum(T_world_lidar);
}

std::string pose_sigmas_to_text(const Trajectory& T_world_lidar,
                                const std::vector<Eigen::Matrix<double, 6, 6>>& covariance) {
  if (covariance.size() != T_world_lidar.size()) {
    throw Error(
        fmt::format("{} covariances for {} poses", covariance.size(), T_world_lidar.size()));
  }
  std::string out =
      "#timestamp sigma_x_m sigma_y_m sigma_z_m sigma_rx_deg sigma_ry_deg sigma_rz_deg\n";
  out.reserve(out.size() + T_world_lidar.size() * 90);
  const double deg = 180.0 / M_PI;
  for (size_t k = 0; k < T_world_lidar.size(); ++k) {
    const Eigen::Matrix<double, 6, 1> s = covariance[k].diagonal().cwiseMax(0.0).cwiseSqrt();
    out += fmt::format("{} {:.6g} {:.6g} {:.6g} {:.6g} {:.6g} {:.6g}\n",
                       to_seconds_text(T_world_lidar.stamps[k]), s(3), s(4), s(5), deg * s(0),
                       deg * s(1), deg * s(2));
  }
  return out;
}

gt::MarkerSurvey read_marker_survey(const std::filesystem::path& path) {
  return parse_marker_survey(read_text_file(path, size_t(1) << 24), path.string());
}

gt::MarkerSurvey parse_marker_survey(std::string_view text, const std::string& source) {
  gt::MarkerSurvey survey;
  std::map<std::string, size_t, std::less<>> index;
  auto marker = [&](std::string_view id) {
    const auto it = index.find(id);
    if (it != index.end()) return it->second;
    index.emplace(std::string(id), survey.ids.size());
    survey.ids.emplace_back(id);
    return survey.ids.size() - 1;
  };
  size_t width = 0;
  bool first = true;
  int number = 0;
  for (size_t start = 0; start < text.size();) {
    const size_t end = std::min(text.find('\n', start), text.size());
    const std::string_view line = trim(text.substr(start, end - start));
    start = end + 1;
    ++number;
    if (line.empty() || line[0] == '#') continue;
    const std::vector<std::string_view> f = split_fields(line);
    const std::string where = fmt::format("{}:{}", source, number);
    // A header: a first row whose coordinates (all three) or distance are not numbers.
    auto is_number = [](std::string_view v) {
      const std::string t(v);
      char* stop = nullptr;
      std::strtod(t.c_str(), &stop);
      return !t.empty() && *stop == 0;
    };
    if (first && ((f.size() == 4 && !is_number(f[1]) && !is_number(f[2]) && !is_number(f[3])) ||
                  (f.size() == 3 && !is_number(f[2])))) {
      first = false;
      continue;
    }
    first = false;
    if (width == 0) width = f.size();
    if (f.size() != width || (width != 3 && width != 4)) {
      throw Error(fmt::format(
          "{}: {} fields; expected id,x,y,z (a marker) or id_a,id_b,distance (m), the same in "
          "every row",
          where, f.size()));
    }
    if (width == 4) {
      const size_t before = survey.ids.size();
      marker(f[0]);
      if (survey.ids.size() == before)
        throw Error(fmt::format("{}: marker '{}' given twice", where, printable(f[0])));
      survey.positions.emplace_back(parse_double(f[1], where + " x"),
                                    parse_double(f[2], where + " y"),
                                    parse_double(f[3], where + " z"));
    } else {
      const size_t a = marker(f[0]), b = marker(f[1]);
      const double m = parse_double(f[2], where + " distance");
      if (a == b)
        throw Error(fmt::format("{}: a distance from '{}' to itself", where, printable(f[0])));
      if (!(m > 0)) throw Error(fmt::format("{}: distance {} m is not positive", where, m));
      survey.distances.push_back({a, b, m});
    }
  }
  if (survey.ids.size() < 2)
    throw Error(fmt::format("{}: {} markers; at least 2 needed", source, survey.ids.size()));
  for (size_t a = 0; a < survey.positions.size(); ++a) {
    for (size_t b = a + 1; b < survey.positions.size(); ++b)
      survey.distances.push_back({a, b, (survey.positions[a] - survey.positions[b]).norm()});
  }
  return survey;
}

std::string point_cloud_to_ply(const std::vector<Eigen::Vector3d>& points,
                               const std::vector<float>& intensity) {
  if (intensity.size() != points.size())
    throw Error(fmt::format("{} intensities for {} points", intensity.size(), points.size()));
  static_assert(std::endian::native == std::endian::little);
  std::string out = fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment rigcal ground-truth map\nelement vertex "
      "{}\nproperty float x\nproperty float y\nproperty float z\nproperty float "
      "intensity\nend_header\n",
      points.size());
  const size_t header = out.size();
  out.resize(header + 16 * points.size());
  char* at = out.data() + header;
  for (size_t i = 0; i < points.size(); ++i, at += 16) {
    const float v[4] = {float(points[i].x()), float(points[i].y()), float(points[i].z()),
                        intensity[i]};
    std::memcpy(at, v, 16);
  }
  return out;
}

}  // namespace rigcal::io
