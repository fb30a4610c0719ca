#include "rigcal/rig/rig_yaml.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <map>
#include <regex>
#include <set>

#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/core/version.h"
#include "rigcal/io/files.h"
#include "rigcal/io/yaml.h"
#include "rigcal/rig/checks.h"

namespace rigcal::rig {
namespace {

constexpr int kFormatVersion = 1;
const char* const kImuNoiseKeys[] = {"gyroscope_noise_density", "gyroscope_random_walk",
                                     "accelerometer_noise_density", "accelerometer_random_walk"};
const std::set<std::string> kKnownKeys = {"sensor_type",
                                          "camera_model",
                                          "distortion_model",
                                          "intrinsics",
                                          "distortion_coeffs",
                                          "resolution",
                                          "T_b",
                                          "time_offset",
                                          "time_drift_ppm",
                                          "time_drift_epoch",
                                          "update_rate",
                                          "model",
                                          "frame",
                                          "attached_to",
                                          "gyroscope_noise_density",
                                          "gyroscope_random_walk",
                                          "accelerometer_noise_density",
                                          "accelerometer_random_walk"};

// Reads one document, remembering where each key was so that later checks can name the line.
class Reader {
 public:
  explicit Reader(std::string_view file) : file_(file) {}

  [[noreturn]] void fail(const YAML::Node& at, std::string_view key, std::string_view what) const {
    fail_at(file_, line_of(at), key, what);
  }
  int line_of(const YAML::Node& n) const { return io::yaml_line(n); }
  void remember(const std::string& key, const YAML::Node& n) { lines_[key] = line_of(n); }
  int line_of_key(const std::string& key) const {
    auto it = lines_.find(key);
    if (it != lines_.end()) return it->second;
    const size_t dot = key.find('.');  // fall back to the sensor's line
    return dot == std::string::npos ? 0 : line_of_key(key.substr(0, dot));
  }
  const std::string& file() const { return file_; }

  double number(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar()) fail(n, key, "expected a number");
    try {
      return parse_double(n.Scalar(), "value");
    } catch (const Error&) {
      fail(n, key, fmt::format("expected a finite number, got '{}'", n.Scalar()));
    }
  }
  std::string text(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar()) fail(n, key, "expected a text value");
    return n.Scalar();
  }
  std::vector<double> numbers(const YAML::Node& n, const std::string& key,
                              std::string_view expected) const {
    if (!n.IsSequence()) fail(n, key, fmt::format("expected a list: {}", expected));
    std::vector<double> out;
    for (const YAML::Node& v : n) out.push_back(number(v, key));
    return out;
  }
  Eigen::Matrix4d matrix4(const YAML::Node& n, const std::string& key) const {
    constexpr std::string_view kShape = "expected a 4x4 matrix as a list of 4 rows of 4 numbers";
    if (!n.IsSequence()) fail(n, key, kShape);
    // Also accept the 16 numbers of a flat row-major list.
    if (n.size() == 16 && n[0].IsScalar()) {
      Eigen::Matrix4d m;
      for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = number(n[i], key);
      check_last_row(n, key, m);
      return m;
    }
    if (n.size() != 4) fail(n, key, fmt::format("{}; got {} rows", kShape, n.size()));
    Eigen::Matrix4d m;
    for (int r = 0; r < 4; ++r) {
      const YAML::Node row = n[r];
      if (!row.IsSequence() || row.size() != 4) {
        fail(row, key,
             fmt::format("{}; row {} has {} entries", kShape, r + 1,
                         row.IsSequence() ? row.size() : 1));
      }
      for (int c = 0; c < 4; ++c) m(r, c) = number(row[c], key);
    }
    check_last_row(n, key, m);
    return m;
  }

 private:
  void check_last_row(const YAML::Node& n, const std::string& key, const Eigen::Matrix4d& m) const {
    if (m.row(3) != Eigen::RowVector4d(0, 0, 0, 1)) {
      fail(n, key,
           fmt::format(
               "the last row of a rigid transform must be [0, 0, 0, 1], got [{}, {}, {}, {}]",
               m(3, 0), m(3, 1), m(3, 2), m(3, 3)));
    }
  }
  std::string file_;
  std::map<std::string, int> lines_;
};

// Every map and list of `n` in flow style (the style it was read in is kept by yaml-cpp).
void flow_style(YAML::Node n) {
  if (!(n.IsMap() || n.IsSequence())) return;
  n.SetStyle(YAML::EmitterStyle::Flow);
  if (n.IsMap()) {
    for (auto it = n.begin(); it != n.end(); ++it) flow_style(it->second);
  } else {
    for (YAML::Node c : n) flow_style(c);
  }
}

std::string flow_text(const YAML::Node& node) {
  YAML::Node n = YAML::Clone(node);
  flow_style(n);
  YAML::Emitter e;
  e << YAML::Flow << n;
  return e.c_str();
}

SensorType infer_type(const std::string& name, const YAML::Node& node) {
  if (node["intrinsics"]) return SensorType::camera;
  for (const char* key : kImuNoiseKeys) {
    if (node[key]) return SensorType::imu;
  }
  auto has = [&](std::string_view part) { return name.find(part) != std::string::npos; };
  if (has("imu")) return SensorType::imu;
  if (has("cam")) return SensorType::camera;
  if (has("lidar") || has("ouster") || has("velodyne")) return SensorType::lidar;
  if (has("gnss") || has("gps") || has("ins")) return SensorType::gnss;
  throw Error("cannot tell what kind of sensor this is; add 'sensor_type: camera|lidar|imu|gnss'");
}

// Levenshtein distance, for suggesting the key a typo meant.
size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
      diagonal = up;
    }
  }
  return row[b.size()];
}

Sensor read_sensor(Reader& r, const std::string& name, const YAML::Node& node, bool vbr_style,
                   std::vector<std::string>& notes) {
  Sensor s;
  s.name = name;
  r.remember(name, node);
  std::set<std::string> seen;
  for (auto it = node.begin(); it != node.end(); ++it) {
    const std::string key = it->first.Scalar();
    // yaml-cpp keeps both entries of a repeated key and node[key] finds the first: refused.
    if (!seen.insert(key).second)
      r.fail(it->first, name + "." + key, "given twice in this sensor (which one is meant?)");
    r.remember(name + "." + key, it->second);
    // A key one or two letters from a known one is a typo, not an extra key kept as it is
    // (time_offsett would otherwise leave the offset at 0 without a word).
    if (!kKnownKeys.count(key)) {
      for (const std::string& known : kKnownKeys) {
        if (edit_distance(key, known) <= 2) {
          r.fail(it->first, name + "." + key,
                 fmt::format("unknown key; did you mean '{}'? (other unknown keys are kept as "
                             "they are)",
                             known));
        }
      }
    }
  }
  auto key_of = [&](std::string_view k) { return fmt::format("{}.{}", name, k); };
  auto require = [&](const char* k) {
    if (!node[k]) r.fail(node, key_of(k), "missing required key");
    return node[k];
  };

  if (const YAML::Node t = node["sensor_type"]) {
    try {
      s.type = sensor_type_from_string(r.text(t, key_of("sensor_type")));
    } catch (const Error& e) {
      r.fail(t, key_of("sensor_type"), e.what());
    }
  } else {
    try {
      s.type = infer_type(name, node);
    } catch (const Error& e) {
      r.fail(node, name, e.what());
    }
  }

  s.T_base_sensor = SE3::from_matrix(r.matrix4(require("T_b"), key_of("T_b")));
  if (const YAML::Node n = node["time_offset"]) s.time_offset = r.number(n, key_of("time_offset"));
  if (const YAML::Node n = node["time_drift_ppm"]) {
    s.time_drift_ppm = r.number(n, key_of("time_drift_ppm"));
    const YAML::Node e = node["time_drift_epoch"];
    if (!e) r.fail(n, key_of("time_drift_ppm"), "needs time_drift_epoch (s, this sensor's clock)");
    try {
      s.time_drift_epoch = parse_seconds(r.text(e, key_of("time_drift_epoch")));
    } catch (const Error& err) {
      r.fail(e, key_of("time_drift_epoch"), err.what());
    }
  } else if (const YAML::Node e = node["time_drift_epoch"]) {
    r.fail(e, key_of("time_drift_epoch"), "given without time_drift_ppm");
  }
  if (const YAML::Node n = node["update_rate"]) s.update_rate = r.number(n, key_of("update_rate"));
  if (const YAML::Node n = node["model"]) s.model = r.text(n, key_of("model"));
  if (const YAML::Node n = node["attached_to"]) s.attached_to = r.text(n, key_of("attached_to"));

  auto forbid = [&](std::initializer_list<const char*> keys, std::string_view belongs_to) {
    for (const char* k : keys) {
      if (node[k]) {
        r.fail(node[k], key_of(k),
               fmt::format("'{}' belongs to {}, but this sensor is a {}", k, belongs_to,
                           to_string(s.type)));
      }
    }
  };
  if (s.type == SensorType::camera) {
    CameraModel& c = s.camera;
    if (const YAML::Node n = node["camera_model"]) {
      const std::string model = r.text(n, key_of("camera_model"));
      if (model != "pinhole") {
        r.fail(n, key_of("camera_model"),
               fmt::format("unknown camera model '{}'; rigcal supports pinhole", model));
      }
    }
    if (const YAML::Node n = node["distortion_model"]) {
      try {
        c.distortion_model = distortion_model_from_string(r.text(n, key_of("distortion_model")));
      } catch (const Error& e) {
        r.fail(n, key_of("distortion_model"), e.what());
      }
    }
    if (!node["camera_model"] || !node["distortion_model"]) {
      notes.push_back(fmt::format(
          "{}: {} not given; pinhole with {} distortion assumed{}", name,
          !node["camera_model"] && !node["distortion_model"] ? "camera_model and distortion_model"
          : !node["camera_model"]                            ? "camera_model"
                                                             : "distortion_model",
          to_string(c.distortion_model), vbr_style ? " (the VBR convention)" : ""));
    }
    const YAML::Node in = require("intrinsics");
    const std::vector<double> k = r.numbers(in, key_of("intrinsics"), "[fx, fy, cx, cy]");
    if (k.size() != 4) {
      r.fail(in, key_of("intrinsics"),
             fmt::format("expected 4 numbers [fx, fy, cx, cy], got {}", k.size()));
    }
    c.fx = k[0], c.fy = k[1], c.cx = k[2], c.cy = k[3];
    c.distortion_coeffs = r.numbers(require("distortion_coeffs"), key_of("distortion_coeffs"),
                                    "the distortion coefficients");
    const YAML::Node res = require("resolution");
    const std::vector<double> wh = r.numbers(res, key_of("resolution"), "[width, height]");
    if (wh.size() != 2 || wh[0] != std::floor(wh[0]) || wh[1] != std::floor(wh[1]) ||
        std::abs(wh[0]) > 1e6 || std::abs(wh[1]) > 1e6) {
      r.fail(res, key_of("resolution"), "expected [width, height] in whole pixels");
    }
    c.width = static_cast<int>(wh[0]), c.height = static_cast<int>(wh[1]);
  } else {
    forbid({"camera_model", "distortion_model", "intrinsics", "distortion_coeffs", "resolution"},
           "cameras");
  }
  if (s.type == SensorType::imu) {
    std::optional<double>* fields[] = {&s.imu.gyroscope_noise_density, &s.imu.gyroscope_random_walk,
                                       &s.imu.accelerometer_noise_density,
                                       &s.imu.accelerometer_random_walk};
    for (int i = 0; i < 4; ++i) {
      if (const YAML::Node n = node[kImuNoiseKeys[i]])
        *fields[i] = r.number(n, key_of(kImuNoiseKeys[i]));
    }
  } else {
    forbid({"gyroscope_noise_density", "gyroscope_random_walk", "accelerometer_noise_density",
            "accelerometer_random_walk"},
           "IMUs");
  }
  if (s.type == SensorType::gnss) {
    if (const YAML::Node n = node["frame"]) s.gnss_frame = r.text(n, key_of("frame"));
  } else {
    forbid({"frame"}, "GNSS/INS sensors");
  }
  for (auto it = node.begin(); it != node.end(); ++it) {
    const std::string key = it->first.Scalar();
    if (!kKnownKeys.count(key)) s.extra_keys.emplace_back(key, flow_text(it->second));
  }
  return s;
}

void read_metadata(Reader& r, const YAML::Node& node, Rig& rig) {
  if (!node.IsMap()) r.fail(node, "rigcal", "expected a map (format_version, base_frame, notes)");
  for (auto it = node.begin(); it != node.end(); ++it) {
    const std::string key = it->first.Scalar();
    const std::string full = "rigcal." + key;
    r.remember(full, it->second);
    if (key == "format_version") {
      const double v = r.number(it->second, full);
      if (v > kFormatVersion) {
        r.fail(it->second, full,
               fmt::format("format version {} is newer than this rigcal reads ({}); update rigcal",
                           v, kFormatVersion));
      }
    } else if (key == "base_frame") {
      rig.base_frame = r.text(it->second, full);
    } else if (key == "notes") {
      // A copy: the range of a range-for over it->second, a member reached through the temporary
      // proxy that operator-> returns, would outlive it (stack-use-after-scope under ASan).
      const YAML::Node notes = it->second;
      if (!notes.IsSequence()) r.fail(notes, full, "expected a list of text lines");
      for (const YAML::Node& n : notes) rig.notes.push_back(r.text(n, full));
    } else if (key != "written_by") {
      rig.extra_metadata.emplace_back(key, flow_text(it->second));
    }
  }
}

bool is_plain_word(const std::string& s) {
  static const std::regex word("[A-Za-z_][A-Za-z0-9_.\\-]*");
  static const std::set<std::string> reserved = {
      "true", "false", "yes",  "no",   "on",   "off",   "null", "True", "False", "Yes", "No",
      "On",   "Off",   "Null", "NULL", "TRUE", "FALSE", "y",    "n",    "Y",     "N"};
  return std::regex_match(s, word) && !reserved.count(s);
}

std::string yaml_string(const std::string& s) {
  if (is_plain_word(s)) return s;
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out + "\"";
}

// Maps and lists in block style for people (entries of a list stay on one line each), scalars
// and empty collections as they are.
void block_style(YAML::Node n, bool in_list) {
  if (n.IsMap() || n.IsSequence()) {
    if (n.size() == 0) return;
    n.SetStyle(in_list && n.IsMap() ? YAML::EmitterStyle::Flow : YAML::EmitterStyle::Block);
    if (n.IsMap()) {
      for (auto it = n.begin(); it != n.end(); ++it) block_style(it->second, false);
    } else {
      for (YAML::Node c : n) block_style(c, true);
    }
  }
}

// One key of the rigcal section, kept as flow text, written at indent 2.
std::string metadata_yaml(const std::string& key, const std::string& text) {
  YAML::Node n;
  try {
    n = YAML::Load(text);
  } catch (const YAML::Exception&) {
    return fmt::format("  {}: {}\n", yaml_string(key), text);
  }
  if (!(n.IsMap() || n.IsSequence()) || n.size() == 0)
    return fmt::format("  {}: {}\n", yaml_string(key), text);
  block_style(n, false);
  YAML::Emitter e;
  e.SetIndent(2);
  e << n;
  std::string out = fmt::format("  {}:\n", yaml_string(key));
  std::string_view body = e.c_str();
  while (!body.empty()) {
    const size_t eol = body.find('\n');
    out += fmt::format("    {}\n", body.substr(0, eol));
    body = eol == std::string_view::npos ? std::string_view() : body.substr(eol + 1);
  }
  return out;
}

constexpr const char* kHeader =
    "# Calibration of a sensor rig, written by rigcal (format: doc/calibration-yaml.md).\n"
    "# T_b: the sensor's pose in the base frame (p_base = T_b * p_sensor), 4x4, rows; metres.\n"
    "# T_cam_lidar = inv(cam.T_b) * lidar.T_b. time_offset: seconds added to the sensor's stamps\n"
    "# to put them on the base clock.\n";

// Writes the sensors; `full` adds rigcal's keys, else only the VBR ones.
std::string sensors_yaml(const Rig& rig, bool full) {
  std::string out;
  for (const Sensor& s : rig.sensors) {
    out += fmt::format("{}:\n", yaml_string(s.name));
    if (full) out += fmt::format("  sensor_type: {}\n", to_string(s.type));
    if (s.type == SensorType::camera) {
      const CameraModel& c = s.camera;
      if (full) {
        out += "  camera_model: pinhole\n";
        out += fmt::format("  distortion_model: {}\n", to_string(c.distortion_model));
      }
      out += fmt::format("  intrinsics: {}\n", yaml_list({c.fx, c.fy, c.cx, c.cy}));
      out += fmt::format("  distortion_coeffs: {}\n", yaml_list(c.distortion_coeffs));
      out += fmt::format("  resolution: [{}, {}]\n", c.width, c.height);
    }
    out += "  T_b:\n" + yaml_matrix4_rows(s.T_base_sensor, "    ");
    if (full) out += fmt::format("  time_offset: {}\n", yaml_number(s.time_offset));
    if (full && s.time_drift_ppm) {
      out += fmt::format("  time_drift_ppm: {}\n  time_drift_epoch: {}\n",
                         yaml_number(*s.time_drift_ppm), to_seconds_text(s.time_drift_epoch));
    }
    if (s.type == SensorType::imu) {
      const std::optional<double>* fields[] = {
          &s.imu.gyroscope_noise_density, &s.imu.gyroscope_random_walk,
          &s.imu.accelerometer_noise_density, &s.imu.accelerometer_random_walk};
      for (int i = 0; i < 4; ++i) {
        if (*fields[i])
          out += fmt::format("  {}: {}\n", kImuNoiseKeys[i], yaml_number(**fields[i]));
      }
    }
    if (s.update_rate && (full || s.type == SensorType::imu)) {
      out += fmt::format("  update_rate: {}\n", yaml_number(*s.update_rate));
    }
    if (full) {
      if (!s.model.empty()) out += fmt::format("  model: {}\n", yaml_string(s.model));
      if (s.type == SensorType::gnss)
        out += fmt::format("  frame: {}\n", yaml_string(s.gnss_frame));
      if (!s.attached_to.empty())
        out += fmt::format("  attached_to: {}\n", yaml_string(s.attached_to));
      for (const auto& [key, text] : s.extra_keys)
        out += fmt::format("  {}: {}\n", yaml_string(key), text);
    }
  }
  return out;
}

}  // namespace

std::string yaml_number(double value) { return format_double(value, /*keep_point=*/true); }

std::string yaml_list(const std::vector<double>& values) {
  std::vector<std::string> parts;
  for (double x : values) parts.push_back(yaml_number(x));
  return fmt::format("[{}]", fmt::join(parts, ", "));
}

std::string yaml_matrix4_rows(const SE3& T, std::string_view indent) {
  const Eigen::Matrix4d m = T.matrix();
  std::string out;
  for (int r = 0; r < 4; ++r) {
    out += fmt::format("{}- {}\n", indent, yaml_list({m(r, 0), m(r, 1), m(r, 2), m(r, 3)}));
  }
  return out;
}

Rig parse_rig_yaml(std::string_view text, std::string_view file_name) {
  Reader r(file_name);
  const YAML::Node root = io::load_yaml(text, r.file());
  if (!root || root.IsNull()) fail_at(r.file(), 0, "", "empty file: expected a map of sensors");
  if (!root.IsMap()) r.fail(root, "", "expected a map of sensors at the top level");

  Rig rig;
  const bool vbr_style = !root["rigcal"];
  std::set<std::string> seen;
  for (auto it = root.begin(); it != root.end(); ++it) {
    const std::string name = it->first.Scalar();
    if (name.empty() || printable(name, name.size()) != name) {
      r.fail(it->first, printable(name),
             "a sensor name must be printable text (no control characters or invalid UTF-8)");
    }
    if (!seen.insert(name).second) {
      r.fail(it->first, name,
             fmt::format("duplicate sensor '{}' (a sensor name appears twice)", name));
    }
    if (name == "rigcal") {
      read_metadata(r, it->second, rig);
      continue;
    }
    if (!it->second.IsMap()) {
      r.fail(it->second, name, "expected a sensor: a map with at least T_b");
    }
    rig.sensors.push_back(read_sensor(r, name, it->second, vbr_style, rig.notes));
  }
  if (vbr_style) {
    std::vector<std::string> kinds;
    for (const Sensor& s : rig.sensors)
      kinds.push_back(fmt::format("{} {}", s.name, to_string(s.type)));
    rig.notes.push_back(
        fmt::format("no 'rigcal' section (a VBR-style file): sensor types inferred "
                    "from names and keys: {}",
                    fmt::join(kinds, ", ")));
    if (!find_sensor(rig, rig.base_frame)) {
      for (const Sensor& s : rig.sensors) {
        if (s.type == SensorType::lidar) {
          rig.base_frame = s.name;
          break;
        }
      }
    }
  }
  for (const Problem& p : find_problems(rig)) {
    fail_at(r.file(), r.line_of_key(p.key), p.key, p.what);
  }
  return rig;
}

Rig read_rig_file(const std::filesystem::path& path) {
  return parse_rig_yaml(io::read_text_file(path, io::kMaxYamlBytes), path.string());
}

std::string rig_to_yaml(const Rig& rig) {
  validate(rig);
  std::string out = kHeader;
  out += sensors_yaml(rig, true);
  out += "rigcal:\n";
  out += fmt::format("  format_version: {}\n", kFormatVersion);
  out += fmt::format("  base_frame: {}\n", yaml_string(rig.base_frame));
  out += fmt::format("  written_by: {}\n", yaml_string(version_string()));
  if (!rig.notes.empty()) {
    out += "  notes:\n";
    for (const std::string& n : rig.notes) out += fmt::format("    - {}\n", yaml_string(n));
  }
  for (const auto& [key, text] : rig.extra_metadata) out += metadata_yaml(key, text);
  return out;
}

void write_rig_file(const Rig& rig, const std::filesystem::path& path) {
  io::write_file_atomic(path, rig_to_yaml(rig));
}

std::string rig_to_vbr_yaml(const Rig& rig) {
  validate(rig);
  for (const Sensor* cam : cameras(rig)) {
    if (cam->camera.distortion_model != DistortionModel::radtan) {
      throw Error(fmt::format(
          "{}: the VBR format has no distortion_model key and is read as radtan; this camera is "
          "{}. Export it with --to rigcal, kalibr or opencv instead",
          cam->name, to_string(cam->camera.distortion_model)));
    }
  }
  return sensors_yaml(rig, false);
}

}  // namespace rigcal::rig
