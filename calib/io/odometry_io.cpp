#include "rigcal/io/odometry_io.h"

#include <fmt/format.h>

#include <sstream>

#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/io/files.h"

namespace rigcal::io {

std::filesystem::path step_covariances_beside(const std::filesystem::path& trajectory) {
  return std::filesystem::path(trajectory).replace_extension("").string() + "_covariances.txt";
}

std::string step_covariances_to_text(const std::vector<StepCovariance>& steps) {
  std::string out =
      "# rigcal odometry: covariance of each step T_prev_cur (doc/odometry.md)\n"
      "# t_prev t_cur, then the upper triangle row by row; order rx ry rz (rad) tx ty tz (m),\n"
      "# left perturbation in the previous sensor frame\n";
  for (const StepCovariance& s : steps) {
    out += to_seconds_text(s.prev);
    out += ' ';
    out += to_seconds_text(s.cur);
    for (int r = 0; r < 6; ++r) {
      for (int c = r; c < 6; ++c) {
        out += ' ';
        out += format_double(s.covariance(r, c));
      }
    }
    out += '\n';
  }
  return out;
}

std::vector<StepCovariance> read_step_covariances(const std::filesystem::path& path) {
  const std::string text = read_text_file(path);
  std::vector<StepCovariance> out;
  std::istringstream in(text);
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    const std::vector<std::string_view> f = split_fields(line);
    if (f.empty() || f[0].front() == '#') continue;
    const std::string where = fmt::format("{}:{}", path.string(), line_no);
    if (f.size() != 23) {
      throw Error(
          fmt::format("{}: {} fields, expected 23 (t_prev t_cur and 21 covariance "
                      "entries)",
                      where, f.size()));
    }
    StepCovariance s;
    s.prev = parse_seconds(f[0], where + ": t_prev");
    s.cur = parse_seconds(f[1], where + ": t_cur");
    size_t k = 2;
    for (int r = 0; r < 6; ++r) {
      for (int c = r; c < 6; ++c) {
        s.covariance(r, c) = s.covariance(c, r) =
            parse_double(f[k++], fmt::format("{}: entry ({}, {})", where, r, c));
      }
    }
    for (int i = 0; i < 6; ++i) {
      if (!(s.covariance(i, i) >= 0))
        throw Error(fmt::format("{}: variance {} is negative or not a number", where, i));
    }
    out.push_back(s);
  }
  return out;
}

}  // namespace rigcal::io
