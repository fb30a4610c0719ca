#include "rigcal/io/sim_config.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <functional>
#include <map>

#include "rigcal/core/error.h"
#include "rigcal/io/files.h"
#include "rigcal/io/target_yaml.h"
#include "rigcal/io/yaml.h"

namespace rigcal::io {
namespace {

using Setter = std::function<void(const YAML::Node&)>;

}  // namespace

void apply_sim_config(std::string_view text, std::string_view file, sim::SimConfig& c) {
  const YAML::Node root = io::load_yaml(text, file);
  if (root.IsNull()) return;
  const std::filesystem::path base = std::filesystem::path(std::string(file)).parent_path();
  std::string key_now;
  auto num = [&](double& v) { return Setter([&v](const YAML::Node& n) { v = n.as<double>(); }); };
  auto integer = [&](int& v) { return Setter([&v](const YAML::Node& n) { v = n.as<int>(); }); };
  auto flag = [&](bool& v) { return Setter([&v](const YAML::Node& n) { v = n.as<bool>(); }); };
  auto spans = [&](std::vector<std::pair<double, double>>& v) {
    return Setter([&v](const YAML::Node& n) {
      v.clear();
      for (const YAML::Node& s : n) {
        if (!s.IsSequence() || s.size() != 2)
          throw Error("expected a list of [from, to] pairs (s)");
        v.emplace_back(s[0].as<double>(), s[1].as<double>());
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
      else
        throw Error(fmt::format("expected handheld or car, got '{}'", s));
    });
  };
  auto imu = [&](const std::string& p, sim::ImuSimConfig& v) {
    return std::map<std::string, Setter>{{p + ".rate_hz", num(v.rate_hz)},
                                         {p + ".jitter_s", num(v.jitter_s)},
                                         {p + ".drift_ppm", num(v.drift_ppm)},
                                         {p + ".gaps", spans(v.gaps)}};
  };
  std::map<std::string, Setter> setters = {
      {"seed", Setter([&](const YAML::Node& n) { c.seed = n.as<uint64_t>(); })},
      {"base_start_s", num(c.base_start_s)},
      {"target", Setter([&](const YAML::Node& n) {
         c.target = read_target_file(base / n.as<std::string>());
       })},
      {"stereo.views", integer(c.boards.views)},
      {"stereo.min_fill", num(c.boards.min_fill)},
      {"stereo.max_fill", num(c.boards.max_fill)},
      {"stereo.max_tilt_deg", num(c.boards.max_tilt_deg)},
      {"stereo.max_roll_deg", num(c.boards.max_roll_deg)},
      {"stereo.margin_px", num(c.boards.margin_px)},
      {"stereo.min_square_px", num(c.boards.min_square_px)},
      {"stereo.frame_period_s", num(c.frame_period_s)},
      {"image.supersample", integer(c.image.supersample)},
      {"image.blur_sigma_px", num(c.image.blur_sigma_px)},
      {"image.black_dn", num(c.image.black_dn)},
      {"image.white_dn", num(c.image.white_dn)},
      {"image.background_dn", num(c.image.background_dn)},
      {"image.gain_dn_per_e", num(c.image.gain_dn_per_e)},
      {"image.read_noise_dn", num(c.image.read_noise_dn)},
      {"image.vignetting", num(c.image.vignetting)},
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
      {"lidar.range_noise_m", num(c.lidar.range_noise_m)},
      {"lidar_camera.pairs", integer(c.lidar_camera_pairs)},
      {"lidar_camera.camera",
       Setter([&](const YAML::Node& n) { c.lidar_camera_camera = n.as<std::string>(); })},
      {"lidar_camera.clutter", flag(c.clutter)},
      {"imu_duration_s", num(c.imu_duration_s)},
      {"imu_motion", motion(c.imu_motion)},
      {"trajectories.duration_s", num(c.trajectory_duration_s)},
      {"trajectories.motion", motion(c.trajectory_motion)},
      {"trajectories.replay",
       Setter([&](const YAML::Node& n) { c.replay_tum = (base / n.as<std::string>()).string(); })},
      {"trajectories.odometry.trans_sigma_m", num(c.odometry.trans_sigma_m)},
      {"trajectories.odometry.rot_sigma_deg", num(c.odometry.rot_sigma_deg)},
      {"trajectories.odometry.scale_error", num(c.odometry.scale_error)},
      {"trajectories.gnss.rate_hz", num(c.gnss.rate_hz)},
      {"trajectories.gnss.horizontal_sigma_m", num(c.gnss.horizontal_sigma_m)},
      {"trajectories.gnss.vertical_sigma_m", num(c.gnss.vertical_sigma_m)},
      {"trajectories.gnss.rot_sigma_deg", num(c.gnss.rot_sigma_deg)},
      {"trajectories.gnss.correlation_time_s", num(c.gnss.correlation_time_s)},
      {"trajectories.gnss.outages", spans(c.gnss.outages)},
      {"trajectories.gnss.outlier_probability", num(c.gnss.outlier_probability)},
      {"trajectories.gnss.outlier_jump_m", num(c.gnss.outlier_jump_m)},
      {"scans.count", integer(c.scans)},
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
}

void read_sim_config(const std::filesystem::path& path, sim::SimConfig& config) {
  apply_sim_config(read_text_file(path, kMaxYamlBytes), path.string(), config);
}

}  // namespace rigcal::io
