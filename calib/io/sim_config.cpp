#include "rigcal/io/sim_config.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <functional>
#include <map>

#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/io/files.h"
#include "rigcal/io/target_yaml.h"
#include "rigcal/io/yaml.h"

namespace rigcal::io {
namespace {

using Setter = std::function<void(const YAML::Node&)>;

}  // namespace

void apply_sim_config(std::string_view text, std::string_view file, sim::SimConfig& c) {
  const YAML::Node root = io::load_yaml(text, file);
  io::refuse_duplicate_keys(root, file);
  if (root.IsNull()) return;
  const std::filesystem::path base = std::filesystem::path(std::string(file)).parent_path();
  std::string key_now;
  // Every number within what a simulated session may be (doc/simulator.md): a typo such as
  // views 1e8 or a duration of 1e12 s is an error, not hours of work and a machine out of memory.
  auto in_range = [](double x, double low, double high) {
    if (!(x >= low && x <= high))
      throw Error(fmt::format("{} is outside {}..{}", format_double(x), format_double(low),
                              format_double(high)));
  };
  auto num = [&](double& v, double low, double high) {
    return Setter([&v, low, high, in_range](const YAML::Node& n) {
      const double x = n.as<double>();
      in_range(x, low, high);
      v = x;
    });
  };
  int columns = 0, beams = 0;  // lidar.columns and lidar.beams, applied after lidar.model
  auto integer = [&](int& v, int low, int high) {
    return Setter([&v, low, high, in_range](const YAML::Node& n) {
      const double x = n.as<double>();
      if (x != std::floor(x))
        throw Error(fmt::format("expected a whole number, got {}", n.Scalar()));
      in_range(x, low, high);
      v = static_cast<int>(x);
    });
  };
  auto flag = [&](bool& v) { return Setter([&v](const YAML::Node& n) { v = n.as<bool>(); }); };
  auto spans = [&](std::vector<std::pair<double, double>>& v) {
    return Setter([&v](const YAML::Node& n) {
      v.clear();
      for (const YAML::Node& s : n) {
        if (!s.IsSequence() || s.size() != 2)
          throw Error("expected a list of [from, to] pairs (s)");
        const double from = s[0].as<double>(), to = s[1].as<double>();
        if (!(std::isfinite(from) && std::isfinite(to) && from <= to))
          throw Error("expected [from, to] with finite from <= to (s)");
        v.emplace_back(from, to);
      }
    });
  };
  auto motion = [&](sim::MotionKind& v) {
    return Setter([&v](const YAML::Node& n) {
      const std::string s = n.as<std::string>();
      if (s == "handheld")
        v = sim::MotionKind::handheld;
      else if (s == "car")
        v = sim::MotionKind::car;
      else if (s == "walk")
        v = sim::MotionKind::walk;
      else
        throw Error(fmt::format("expected handheld, car or walk, got '{}'", s));
    });
  };
  auto imu = [&](const std::string& p, sim::ImuSimConfig& v) {
    return std::map<std::string, Setter>{{p + ".rate_hz", num(v.rate_hz, 0.1, 2000)},
                                         {p + ".jitter_s", num(v.jitter_s, 0, 0.01)},
                                         {p + ".drift_ppm", num(v.drift_ppm, -10000, 10000)},
                                         {p + ".gaps", spans(v.gaps)}};
  };
  std::map<std::string, Setter> setters = {
      {"seed", Setter([&](const YAML::Node& n) { c.seed = n.as<uint64_t>(); })},
      {"base_start_s", num(c.base_start_s, 0, 1e10)},
      {"target", Setter([&](const YAML::Node& n) {
         c.target = read_target_file(base / n.as<std::string>());
       })},
      {"board_warp_mm", Setter([&](const YAML::Node& n) {
         if (!n.IsSequence() || n.size() != 2)
           throw Error("expected [x, y]: the board's warp along x and y (mm)");
         const double x = n[0].as<double>(), y = n[1].as<double>();
         if (!(std::abs(x) <= 100 && std::abs(y) <= 100))
           throw Error("expected a warp within 100 mm along each axis");
         c.board_warp_m = Eigen::Vector2d(x, y) / 1000.0;
       })},
      {"stereo.views", integer(c.boards.views, 1, 1000)},
      {"stereo.min_fill", num(c.boards.min_fill, 0.01, 1)},
      {"stereo.max_fill", num(c.boards.max_fill, 0.01, 1)},
      {"stereo.max_tilt_deg", num(c.boards.max_tilt_deg, 0, 89)},
      {"stereo.max_roll_deg", num(c.boards.max_roll_deg, 0, 180)},
      {"stereo.margin_px", num(c.boards.margin_px, 0, 1000)},
      {"stereo.min_square_px", num(c.boards.min_square_px, 0.1, 1000)},
      {"stereo.frame_period_s", num(c.frame_period_s, 0.001, 3600)},
      {"image.supersample", integer(c.image.supersample, 1, 16)},
      {"image.blur_sigma_px", num(c.image.blur_sigma_px, 0, 100)},
      {"image.black_dn", num(c.image.black_dn, 0, 65535)},
      {"image.white_dn", num(c.image.white_dn, 0, 65535)},
      {"image.background_dn", num(c.image.background_dn, 0, 65535)},
      {"image.gain_dn_per_e", num(c.image.gain_dn_per_e, 0.0001, 1000)},
      {"image.read_noise_dn", num(c.image.read_noise_dn, 0, 1000)},
      {"image.vignetting", num(c.image.vignetting, 0, 1)},
      {"image.bayer", flag(c.image.bayer)},
      {"lidar.model", Setter([&](const YAML::Node& n) {
         const std::string s = n.as<std::string>();
         const double noise = c.lidar.range_noise_m;
         if (s == "os0-128")
           c.lidar = sim::os0_128();
         else if (s == "os1-64")
           c.lidar = sim::os1_64();
         else
           throw Error(fmt::format("expected os0-128 or os1-64, got '{}'", s));
         c.lidar.range_noise_m = noise;
       })},
      {"lidar.range_noise_m", num(c.lidar.range_noise_m, 0, 10)},
      {"lidar.columns", integer(columns, 64, 4096)},
      {"lidar.beams", integer(beams, 8, 256)},
      {"lidar_camera.pairs", integer(c.lidar_camera_pairs, 1, 200)},
      {"lidar_camera.camera",
       Setter([&](const YAML::Node& n) { c.lidar_camera_camera = n.as<std::string>(); })},
      {"lidar_camera.clutter", flag(c.clutter)},
      {"imu_duration_s", num(c.imu_duration_s, 1, 3600)},
      {"imu_motion", motion(c.imu_motion)},
      {"trajectories.duration_s", num(c.trajectory_duration_s, 1, 36000)},
      {"trajectories.motion", motion(c.trajectory_motion)},
      {"trajectories.scans", flag(c.trajectory_scans)},
      {"trajectories.markers", integer(c.markers, 0, 24)},
      {"trajectories.building", flag(c.building)},
      {"trajectories.marker_side_m", num(c.marker_side_m, 0.02, 2)},
      {"trajectories.replay",
       Setter([&](const YAML::Node& n) { c.replay_tum = (base / n.as<std::string>()).string(); })},
      {"trajectories.odometry.trans_sigma_m", num(c.odometry.trans_sigma_m, 0, 10)},
      {"trajectories.odometry.rot_sigma_deg", num(c.odometry.rot_sigma_deg, 0, 90)},
      {"trajectories.odometry.scale_error", num(c.odometry.scale_error, -0.5, 0.5)},
      {"trajectories.gnss.rate_hz", num(c.gnss.rate_hz, 0.1, 100)},
      {"trajectories.gnss.horizontal_sigma_m", num(c.gnss.horizontal_sigma_m, 0, 100)},
      {"trajectories.gnss.vertical_sigma_m", num(c.gnss.vertical_sigma_m, 0, 100)},
      {"trajectories.gnss.rot_sigma_deg", num(c.gnss.rot_sigma_deg, 0, 180)},
      {"trajectories.gnss.correlation_time_s", num(c.gnss.correlation_time_s, 0, 100000)},
      {"trajectories.gnss.outages", spans(c.gnss.outages)},
      {"trajectories.gnss.float_fixes", spans(c.gnss.float_spans)},
      {"trajectories.gnss.single_fixes", spans(c.gnss.single_spans)},
      {"trajectories.gnss.float_horizontal_sigma_m", num(c.gnss.float_horizontal_sigma_m, 0, 100)},
      {"trajectories.gnss.float_vertical_sigma_m", num(c.gnss.float_vertical_sigma_m, 0, 100)},
      {"trajectories.gnss.single_horizontal_sigma_m",
       num(c.gnss.single_horizontal_sigma_m, 0, 1000)},
      {"trajectories.gnss.single_vertical_sigma_m", num(c.gnss.single_vertical_sigma_m, 0, 1000)},
      {"trajectories.gnss.outlier_probability", num(c.gnss.outlier_probability, 0, 1)},
      {"trajectories.gnss.outlier_jump_m", num(c.gnss.outlier_jump_m, 0, 10000)},
      {"scans.count", integer(c.scans, 1, 10000)},
  };
  setters.merge(imu("imu", c.imu));
  setters.merge(imu("os_imu", c.os_imu));
  std::function<void(const YAML::Node&, const std::string&)> walk = [&](const YAML::Node& map,
                                                                        const std::string& prefix) {
    if (!map.IsMap()) fail_at(file, yaml_line(map), prefix, "expected a map of keys");
    for (auto it = map.begin(); it != map.end(); ++it) {
      const std::string key =
          prefix.empty() ? it->first.Scalar() : prefix + "." + it->first.Scalar();
      const auto s = setters.find(key);
      if (s != setters.end()) {
        try {
          s->second(it->second);
        } catch (const YAML::Exception&) {
          fail_at(file, yaml_line(it->second), key, "wrong type of value");
        } catch (const Error& e) {
          fail_at(file, yaml_line(it->second), key, e.what());
        }
      } else if (it->second.IsMap()) {
        walk(it->second, key);
      } else {
        fail_at(file, yaml_line(it->first), key, "unknown key (doc/simulator.md lists the keys)");
      }
    }
  };
  walk(root, "");
  if (columns > 0) c.lidar.columns = columns;  // whichever of lidar.model and it comes first
  if (beams > 0) c.lidar.beams = beams;
}

void read_sim_config(const std::filesystem::path& path, sim::SimConfig& config) {
  apply_sim_config(read_text_file(path, kMaxYamlBytes), path.string(), config);
}

}  // namespace rigcal::io
