#include "rigcal/io/capture_config.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cctype>
#include <cmath>
#include <set>

#include "rigcal/core/error.h"
#include "rigcal/io/files.h"
#include "rigcal/io/yaml.h"

namespace rigcal::io {
namespace {

// The scalar text of a node; fails naming the key for a map or a list.
std::string scalar(const YAML::Node& n, std::string_view file, const std::string& key) {
  if (!n.IsScalar()) fail_at(file, yaml_line(n), key, "expected a single value");
  return n.Scalar();
}

double number(const YAML::Node& n, std::string_view file, const std::string& key, double low,
              double high) {
  const std::string s = scalar(n, file, key);
  double x = NAN;
  try {
    size_t used = 0;
    x = std::stod(s, &used);
    if (used != s.size()) x = NAN;
  } catch (const std::exception&) {
  }
  if (!(x >= low && x <= high))
    fail_at(file, yaml_line(n), key,
            fmt::format("expected a number in {}..{}, got '{}'", low, high, s));
  return x;
}

int whole(const YAML::Node& n, std::string_view file, const std::string& key, int low, int high) {
  const double x = number(n, file, key, low, high);
  if (x != std::floor(x))
    fail_at(file, yaml_line(n), key, fmt::format("expected a whole number, got '{}'", n.Scalar()));
  return static_cast<int>(x);
}

CaptureCameraConfig parse_camera(const std::string& folder, const YAML::Node& node,
                                 std::string_view file) {
  const std::string at = "cameras." + folder;
  if (!node.IsMap()) fail_at(file, yaml_line(node), at, "expected a map of the camera's settings");
  CaptureCameraConfig c;
  c.folder = folder;
  for (const auto& kv : node) {
    const std::string key = kv.first.Scalar();
    const std::string k = at + "." + key;
    const YAML::Node& v = kv.second;
    if (key == "id") {
      c.id = scalar(v, file, k);
    } else if (key == "pixel_format") {
      c.pixel_format = scalar(v, file, k);
      c.pixel_format_given = true;
    } else if (key == "region") {
      if (!v.IsSequence() || v.size() != 4)
        fail_at(file, yaml_line(v), k, "expected [x, y, width, height] in pixels");
      std::array<int, 4> r{};
      for (size_t i = 0; i < 4; ++i) r[i] = whole(v[i], file, k, i < 2 ? 0 : 1, 65535);
      c.region = r;
    } else if (key == "trigger") {
      c.trigger = scalar(v, file, k);
      c.trigger_given = true;
      if (c.trigger.empty())
        fail_at(file, yaml_line(v), k, "expected a line name, Software or off");
    } else if (key == "trigger_activation") {
      c.trigger_activation = scalar(v, file, k);
    } else if (key == "frame_rate_hz") {
      c.frame_rate_hz = number(v, file, k, 0.01, 10000);
      c.frame_rate_given = true;
    } else if (key == "exposure_us") {
      c.exposure_given = true;
      if (scalar(v, file, k) != "auto") c.exposure_us = number(v, file, k, 0.1, 1e8);
    } else if (key == "exposure_auto_max_us") {
      c.exposure_auto_max_us = number(v, file, k, 0.1, 1e8);
      c.exposure_auto_max_given = true;
    } else if (key == "gain") {
      const std::string s = scalar(v, file, k);
      if (s != "auto") number(v, file, k, -1000, 1000);
      c.gain = s;
    } else if (key == "balance_white") {
      c.balance_white = scalar(v, file, k);
      c.balance_white_given = true;
      if (c.balance_white != "auto" && c.balance_white != "off")
        fail_at(file, yaml_line(v), k,
                fmt::format("expected auto or off, got '{}'", c.balance_white));
    } else if (key == "features") {
      if (!v.IsMap() && !v.IsNull())
        fail_at(file, yaml_line(v), k, "expected a map of GenICam feature names to values");
      for (const auto& f : v)
        c.features.emplace_back(f.first.Scalar(),
                                scalar(f.second, file, k + "." + f.first.Scalar()));
    } else {
      fail_at(file, yaml_line(kv.first), k,
              "unknown key (expected id, pixel_format, region, trigger, trigger_activation, "
              "frame_rate_hz, exposure_us, exposure_auto_max_us, gain, balance_white, features)");
    }
  }
  if (c.id.empty())
    fail_at(file, yaml_line(node), at,
            "expected an id (what Aravis opens: device id, serial or address)");
  const bool hardware = c.trigger != "off" && c.trigger != "Software";
  if (hardware && c.frame_rate_given)
    fail_at(
        file, yaml_line(node), at,
        fmt::format("frame_rate_hz sets a free-running or software-triggered rate: with trigger "
                    "{} the rate is the trigger's",
                    c.trigger));
  if (!hardware && c.trigger_activation)
    fail_at(file, yaml_line(node), at,
            "trigger_activation applies to a hardware trigger line, not to Software or off");
  if (c.exposure_us && c.exposure_auto_max_given)
    fail_at(file, yaml_line(node), at,
            "exposure_auto_max_us caps the automatic exposure: give it with exposure_us: auto");
  return c;
}

}  // namespace

std::string_view to_string(CaptureStamps stamps) {
  return stamps == CaptureStamps::host ? "host" : "camera";
}

CaptureConfig parse_capture_config(std::string_view text, std::string_view file) {
  const YAML::Node root = load_yaml(text, file);
  refuse_duplicate_keys(root, file);
  if (!root.IsMap()) fail_at(file, yaml_line(root), "", "expected a map with a 'cameras' key");
  CaptureConfig config;
  bool have_cameras = false;
  for (const auto& kv : root) {
    const std::string key = kv.first.Scalar();
    const YAML::Node& v = kv.second;
    if (key == "stamps") {
      const std::string s = scalar(v, file, key);
      if (s == "host")
        config.stamps = CaptureStamps::host;
      else if (s == "camera")
        config.stamps = CaptureStamps::camera;
      else
        fail_at(file, yaml_line(v), key, fmt::format("expected host or camera, got '{}'", s));
    } else if (key == "buffers") {
      config.buffers = whole(v, file, key, 2, 1000);
    } else if (key == "max_waiting_mb") {
      config.max_waiting_mb = whole(v, file, key, 1, 1 << 20);
    } else if (key == "cameras") {
      have_cameras = true;
      if (!v.IsMap() || v.size() == 0)
        fail_at(file, yaml_line(v), key,
                "expected camera_left and/or camera_right with their settings");
      for (const auto& cam : v) {
        const std::string folder = cam.first.Scalar();
        if (folder != "camera_left" && folder != "camera_right")
          fail_at(file, yaml_line(cam.first), "cameras." + folder,
                  "expected camera_left or camera_right (the recording's folders)");
        config.cameras.push_back(parse_camera(folder, cam.second, file));
      }
    } else {
      fail_at(file, yaml_line(kv.first), key,
              "unknown key (expected cameras, stamps, buffers, max_waiting_mb)");
    }
  }
  if (!have_cameras) fail_at(file, 0, "cameras", "missing: the cameras to record");
  std::set<std::string> ids;
  for (const CaptureCameraConfig& c : config.cameras)
    if (!ids.insert(c.id).second)
      fail_at(file, 0, "cameras." + c.folder + ".id",
              fmt::format("'{}' names another camera too", c.id));
  return config;
}

CaptureConfig read_capture_config(const std::filesystem::path& path) {
  return parse_capture_config(read_text_file(path, kMaxYamlBytes), path.string());
}

}  // namespace rigcal::io
