#include "rigcal/rig/rig.h"

#include <fmt/format.h>

#include <algorithm>
#include <set>

#include "rigcal/core/error.h"
#include "rigcal/rig/checks.h"

namespace rigcal::rig {

std::string_view to_string(SensorType type) {
  switch (type) {
    case SensorType::camera:
      return "camera";
    case SensorType::lidar:
      return "lidar";
    case SensorType::imu:
      return "imu";
    case SensorType::gnss:
      return "gnss";
  }
  return "?";
}

std::string_view to_string(DistortionModel model) {
  return model == DistortionModel::radtan ? "radtan" : "equidistant";
}

SensorType sensor_type_from_string(std::string_view name) {
  for (SensorType t : {SensorType::camera, SensorType::lidar, SensorType::imu, SensorType::gnss}) {
    if (name == to_string(t)) return t;
  }
  throw Error(
      fmt::format("unknown sensor type '{}'; expected one of camera, lidar, imu, gnss", name));
}

DistortionModel distortion_model_from_string(std::string_view name) {
  if (name == "radtan") return DistortionModel::radtan;
  if (name == "equidistant") return DistortionModel::equidistant;
  throw Error(fmt::format(
      "unknown distortion model '{}'; expected radtan (k1 k2 p1 p2 [k3]) or equidistant "
      "(k1 k2 k3 k4)",
      name));
}

bool valid_coefficient_count(DistortionModel model, size_t count) {
  return model == DistortionModel::radtan ? (count == 4 || count == 5) : count == 4;
}

Eigen::Matrix3d CameraModel::K() const {
  Eigen::Matrix3d k;
  k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
  return k;
}

Time on_base_clock(const Sensor& sensor, Time t_sensor) {
  double s = sensor.time_offset;
  if (sensor.time_drift_ppm)
    s += *sensor.time_drift_ppm * 1e-6 * (t_sensor - sensor.time_drift_epoch).seconds();
  return t_sensor + Time::from_seconds(s);
}

const Sensor* find_sensor(const Rig& rig, std::string_view name) {
  for (const Sensor& s : rig.sensors) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

Sensor* find_sensor(Rig& rig, std::string_view name) {
  return const_cast<Sensor*>(find_sensor(static_cast<const Rig&>(rig), name));
}

const Sensor& sensor(const Rig& rig, std::string_view name) {
  if (const Sensor* s = find_sensor(rig, name)) return *s;
  std::vector<std::string> names;
  for (const Sensor& s : rig.sensors) names.push_back(s.name);
  throw Error(fmt::format("no sensor '{}' in the rig; it has: {}", name,
                          names.empty() ? "none" : fmt::format("{}", fmt::join(names, ", "))));
}

Sensor& sensor(Rig& rig, std::string_view name) {
  return const_cast<Sensor&>(sensor(static_cast<const Rig&>(rig), name));
}

std::vector<const Sensor*> cameras(const Rig& rig) {
  std::vector<const Sensor*> out;
  for (const Sensor& s : rig.sensors) {
    if (s.type == SensorType::camera) out.push_back(&s);
  }
  return out;
}

SE3 T_a_b(const Rig& rig, std::string_view a, std::string_view b) {
  return sensor(rig, a).T_base_sensor.inverse() * sensor(rig, b).T_base_sensor;
}

std::vector<Problem> find_problems(const Rig& rig) {
  std::vector<Problem> out;
  std::set<std::string> seen;
  for (const Sensor& s : rig.sensors) {
    auto add = [&](std::string_view key, std::string what) {
      out.push_back({fmt::format("{}{}{}", s.name, key.empty() ? "" : ".", key), std::move(what)});
    };
    if (s.name.empty()) add("", "a sensor needs a name");
    if (!seen.insert(s.name).second) add("", fmt::format("duplicate sensor '{}'", s.name));
    if (std::string what = check_rotation(s.T_base_sensor.R); !what.empty()) add("T_b", what);
    // Physical ranges (doc/calibration-yaml.md): finite but absurd numbers would pass on to the
    // exports as Inf and NaN.
    if (!s.T_base_sensor.t.allFinite()) {
      add("T_b", "translation must be finite");
    } else if (s.T_base_sensor.t.cwiseAbs().maxCoeff() > kMaxTranslationM) {
      add("T_b", fmt::format("translation {} m: a rig's sensors lie within {} m of each other",
                             s.T_base_sensor.t.cwiseAbs().maxCoeff(), kMaxTranslationM));
    }
    if (!std::isfinite(s.time_offset)) {
      add("time_offset", "must be a finite number of seconds");
    } else if (std::abs(s.time_offset) > kMaxTimeOffsetS) {
      add("time_offset", fmt::format("{} s is beyond {} s (even GPS against UNIX time is 3.2e8 s)",
                                     s.time_offset, kMaxTimeOffsetS));
    }
    if (s.time_drift_ppm && !(std::abs(*s.time_drift_ppm) < 1e4)) {
      add("time_drift_ppm",
          fmt::format("must be finite and below 1e4 ppm, got {}", *s.time_drift_ppm));
    }
    if (s.update_rate && !(*s.update_rate > 0 && *s.update_rate <= kMaxRateHz)) {
      add("update_rate",
          fmt::format("must be > 0 and at most {} Hz, got {}", kMaxRateHz, *s.update_rate));
    }
    if (s.type == SensorType::camera) {
      const CameraModel& c = s.camera;
      if (!(c.fx > 0 && c.fx <= kMaxPixels) || !(c.fy > 0 && c.fy <= kMaxPixels)) {
        add("intrinsics", fmt::format("focal lengths fx, fy must be > 0 and at most {} px, got "
                                      "fx = {}, fy = {}",
                                      kMaxPixels, c.fx, c.fy));
      }
      if (!(std::abs(c.cx) <= kMaxPixels) || !(std::abs(c.cy) <= kMaxPixels))
        add("intrinsics", fmt::format("cx, cy must be finite, within {} px", kMaxPixels));
      if (!valid_coefficient_count(c.distortion_model, c.distortion_coeffs.size())) {
        add("distortion_coeffs",
            fmt::format("{} takes {} coefficients, got {}", to_string(c.distortion_model),
                        c.distortion_model == DistortionModel::radtan
                            ? "4 (k1 k2 p1 p2) or 5 (k1 k2 "
                              "p1 p2 k3)"
                            : "4 (k1 k2 k3 k4)",
                        c.distortion_coeffs.size()));
      }
      for (double k : c.distortion_coeffs) {
        if (!(std::abs(k) <= kMaxDistortion)) {
          add("distortion_coeffs",
              fmt::format("coefficients must be finite, within +-{}, got {}", kMaxDistortion, k));
          break;
        }
      }
      if (c.width > kMaxImageSide || c.height > kMaxImageSide) {
        add("resolution",
            fmt::format("at most {} px a side, got [{}, {}]", kMaxImageSide, c.width, c.height));
      }
      if (c.width <= 0 || c.height <= 0) {
        add("resolution",
            fmt::format("width and height must be > 0 px, got [{}, {}]", c.width, c.height));
      }
    }
    if (s.type == SensorType::imu) {
      const std::pair<const char*, const std::optional<double>*> noise[] = {
          {"gyroscope_noise_density", &s.imu.gyroscope_noise_density},
          {"gyroscope_random_walk", &s.imu.gyroscope_random_walk},
          {"accelerometer_noise_density", &s.imu.accelerometer_noise_density},
          {"accelerometer_random_walk", &s.imu.accelerometer_random_walk}};
      for (const auto& [key, value] : noise) {
        if (*value && !(**value > 0 && **value <= kMaxNoise))
          add(key, fmt::format("must be > 0 and at most {}, got {}", kMaxNoise, **value));
      }
    }
    if (!s.attached_to.empty()) {
      if (s.attached_to == s.name) {
        add("attached_to", "a sensor cannot be attached to itself");
      } else if (!find_sensor(rig, s.attached_to)) {
        add("attached_to", fmt::format("'{}' is not a sensor of the rig", s.attached_to));
      } else {
        // Following attached_to from here must end: no cycle.
        std::string at = s.attached_to;
        for (size_t hops = 0; !at.empty(); ++hops) {
          if (hops > rig.sensors.size()) {
            add("attached_to", "the attachments form a cycle");
            break;
          }
          const Sensor* next = find_sensor(rig, at);
          at = next ? next->attached_to : "";
        }
      }
    }
    if (s.type == SensorType::gnss && s.gnss_frame != "ins" && s.gnss_frame != "antenna") {
      add("frame", fmt::format("expected ins or antenna, got '{}'", s.gnss_frame));
    }
  }
  if (!rig.sensors.empty() && !find_sensor(rig, rig.base_frame)) {
    out.push_back({"rigcal.base_frame",
                   fmt::format("base frame '{}' is not a sensor of the rig", rig.base_frame)});
  }
  return out;
}

std::vector<std::string> move_rigidly(Rig& rig, std::string_view name, const SE3& T_base_new) {
  const SE3 T_new_old = T_base_new * sensor(rig, name).T_base_sensor.inverse();
  std::vector<std::string> moved{std::string(name)};
  for (size_t i = 0; i < moved.size(); ++i) {
    for (const Sensor& s : rig.sensors) {
      if (s.attached_to == moved[i] && std::find(moved.begin(), moved.end(), s.name) == moved.end())
        moved.push_back(s.name);
    }
  }
  sensor(rig, name).T_base_sensor = T_base_new;  // exactly, not through T_new_old
  for (size_t i = 1; i < moved.size(); ++i) {
    Sensor& s = sensor(rig, moved[i]);
    s.T_base_sensor = T_new_old * s.T_base_sensor;
  }
  return moved;
}

void set_clock_from(Rig& rig, std::string_view sensor_name, std::string_view reference,
                    double offset_s, double drift_ppm, Time epoch) {
  double ref_offset = 0.0, ref_drift = 0.0;
  Time ref_epoch;
  if (!reference.empty()) {
    const Sensor& r = sensor(rig, reference);
    ref_offset = r.time_offset;
    if (r.time_drift_ppm) ref_drift = *r.time_drift_ppm, ref_epoch = r.time_drift_epoch;
  }
  // t_base = t_ref + off_ref + d_ref (t_ref - e_ref), t_ref = t + off + d (t - e): at t = e the
  // offset is off_ref + off + d_ref (e + off - e_ref); the drift is d + d_ref.
  Sensor& s = sensor(rig, sensor_name);
  s.time_offset =
      ref_offset + offset_s + ref_drift * 1e-6 * ((epoch - ref_epoch).seconds() + offset_s);
  if (drift_ppm != 0.0 || ref_drift != 0.0) {
    s.time_drift_ppm = drift_ppm + ref_drift;
    s.time_drift_epoch = epoch;
  } else {
    s.time_drift_ppm.reset();
    s.time_drift_epoch = Time{};
  }
}

void validate(const Rig& rig) {
  const std::vector<Problem> problems = find_problems(rig);
  if (!problems.empty()) {
    throw Error(fmt::format("key '{}': {}", problems.front().key, problems.front().what));
  }
}

std::string check_rotation(const Eigen::Matrix3d& R) {
  if (!R.allFinite()) return "rotation entries must be finite";
  const double err = orthonormality_error(R);
  if (err > kRotationTolerance) {
    return fmt::format(
        "rotation is not orthonormal: max |R^T R - I| = {:.3g} exceeds the tolerance {:g}", err,
        kRotationTolerance);
  }
  if (R.determinant() < 0) return "rotation has determinant < 0 (a reflection, not a rotation)";
  return {};
}

}  // namespace rigcal::rig
