// rigcal rig show FILE: the rig as a readable table.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <memory>

#include "cli.h"
#include "rigcal/rig/import.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/session/provenance.h"

namespace rigcal::cli {
namespace rig_show_command {

constexpr double kDeg = 180.0 / M_PI;

std::string optional_number(const std::optional<double>& v, std::string_view fmt_spec) {
  return v ? fmt::format(fmt::runtime(fmt_spec), *v) : std::string("-");
}

void print_rig(const std::string& file, const rig::Rig& r) {
  fmt::print("{}: {} sensors, base frame '{}'\n\n", file, r.sensors.size(), r.base_frame);
  fmt::print(
      "Poses in the base frame (T_b; translation in m, roll/pitch/yaw in deg, Z-Y-X),\n"
      "and clock offsets (ms, added to the sensor's stamps):\n");
  fmt::print("  {:<10} {:<7} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>10}\n", "sensor", "type", "x",
             "y", "z", "roll", "pitch", "yaw", "offset");
  // Values that print as zero print without a sign.
  auto clean = [](Eigen::Vector3d v, double resolution) {
    for (double& x : v) x = std::abs(x) < resolution / 2 ? 0.0 : x;
    return v;
  };
  for (const rig::Sensor& s : r.sensors) {
    const Eigen::Vector3d rpy = clean(roll_pitch_yaw(s.T_base_sensor.R) * kDeg, 1e-3);
    const Eigen::Vector3d t = clean(s.T_base_sensor.t, 1e-4);
    fmt::print("  {:<10} {:<7} {:>9.4f} {:>9.4f} {:>9.4f} {:>9.3f} {:>9.3f} {:>9.3f} {:>10.3f}\n",
               s.name, rig::to_string(s.type), t.x(), t.y(), t.z(), rpy.x(), rpy.y(), rpy.z(),
               s.time_offset * 1e3);
  }
  for (const rig::Sensor& s : r.sensors) {
    if (s.time_drift_ppm) {
      fmt::print("  {}: clock drift {:.3f} ppm from {} s on its clock\n", s.name, *s.time_drift_ppm,
                 to_seconds_text(s.time_drift_epoch));
    }
  }
  const std::vector<const rig::Sensor*> cams = rig::cameras(r);
  if (!cams.empty()) {
    fmt::print("\nCameras (pinhole; px):\n");
    fmt::print("  {:<10} {:>11} {:>10} {:>10} {:>9} {:>9}  {}\n", "camera", "resolution", "fx",
               "fy", "cx", "cy", "distortion");
    for (const rig::Sensor* c : cams) {
      const rig::CameraModel& m = c->camera;
      fmt::print("  {:<10} {:>11} {:>10.3f} {:>10.3f} {:>9.3f} {:>9.3f}  {} [{:.6g}]\n", c->name,
                 fmt::format("{}x{}", m.width, m.height), m.fx, m.fy, m.cx, m.cy,
                 rig::to_string(m.distortion_model), fmt::join(m.distortion_coeffs, ", "));
    }
    if (cams.size() >= 2) {
      const SE3 T_1_0 = rig::T_a_b(r, cams[1]->name, cams[0]->name);
      fmt::print("  stereo {} -> {}: baseline {:.4f} m, relative rotation {:.4f} deg\n",
                 cams[0]->name, cams[1]->name, T_1_0.t.norm(), rotation_angle(T_1_0.R) * kDeg);
    }
  }
  bool header = false;
  for (const rig::Sensor& s : r.sensors) {
    if (s.type != rig::SensorType::imu) continue;
    if (!header) {
      fmt::print("\nIMUs (noise densities and random walks, continuous time):\n");
      fmt::print("  {:<10} {:>8} {:>12} {:>12} {:>12} {:>12}\n", "imu", "rate Hz", "gyro n",
                 "gyro rw", "accel n", "accel rw");
      header = true;
    }
    fmt::print("  {:<10} {:>8} {:>12} {:>12} {:>12} {:>12}\n", s.name,
               optional_number(s.update_rate, "{:g}"),
               optional_number(s.imu.gyroscope_noise_density, "{:.4g}"),
               optional_number(s.imu.gyroscope_random_walk, "{:.4g}"),
               optional_number(s.imu.accelerometer_noise_density, "{:.4g}"),
               optional_number(s.imu.accelerometer_random_walk, "{:.4g}"));
  }
  const std::vector<session::StepRecord> steps = session::read_steps(r);
  if (!steps.empty()) {
    fmt::print("\nProvenance (rigcal.steps: how each part was estimated):\n");
    for (const session::StepRecord& s : steps) {
      fmt::print("  {}: {} ({})\n", s.step, s.status, s.tool_version);
      for (const session::HashedInput& in : s.inputs) {
        fmt::print("    {:<15} {}{} sha256 {}\n", in.role, in.path.string(),
                   in.files > 1 ? fmt::format(" ({} files)", in.files) : "",
                   in.sha256.substr(0, 16));
      }
      for (const auto& [label, figures] :
           {std::pair{"1-sigma", &s.sigmas}, std::pair{"residuals", &s.residuals}}) {
        if (figures->empty()) continue;
        std::vector<std::string> parts;
        for (const report::Figure& f : *figures)
          parts.push_back(fmt::format("{} {:.4g}", f.name, f.value));
        fmt::print("    {:<15} {}\n", label, fmt::join(parts, ", "));
      }
    }
  }
  if (!r.notes.empty()) {
    fmt::print("\nNotes:\n");
    for (const std::string& n : r.notes) fmt::print("  - {}\n", n);
  }
}

}  // namespace rig_show_command

void add_rig_show(CLI::App& parent) {
  using namespace rig_show_command;
  auto file = std::make_shared<std::string>();
  CLI::App* cmd = parent.add_subcommand(
      "show",
      "Print the rig as tables: every sensor's pose in the base frame (translation and\n"
      "roll/pitch/yaw in degrees), clock offsets, camera intrinsics, stereo baseline, IMU noise.");
  cmd->add_option("file", *file,
                  "calibration file (rigcal, VBR, Kalibr camchain, ROS camera_info, OpenCV, mrcal)")
      ->required();
  cmd->callback([file] { print_rig(*file, rig::read_calibration_file(*file)); });
}

}  // namespace rigcal::cli
