#include "rigcal/io/ouster_metadata.h"

#include <fmt/format.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <regex>

#include "rigcal/core/error.h"
#include "rigcal/io/files.h"

namespace rigcal::io {
namespace {

using nlohmann::json;

constexpr int kMaxPixelsPerColumn = 256;
constexpr int kMaxColumnsPerFrame = 4096;
// Offsets between the sensor's frames are centimetres; 100 m is damage (and keeps points finite).
constexpr double kMaxOffsetMm = 1e5;

// The metadata in either form, looked up by (section of the nested form, key).
struct View {
  const json& root;
  bool nested = false;
  std::string_view source;

  // The flat form keeps lidar_data_format's keys under "data_format" and the rest at the top.
  const json* find(std::string_view section, std::string_view key) const {
    const json* parent = &root;
    if (nested) {
      const auto s = root.find(std::string(section));
      if (s == root.end() || !s->is_object()) return nullptr;
      parent = &*s;
    } else if (section == "lidar_data_format") {
      const auto s = root.find("data_format");
      if (s == root.end() || !s->is_object()) return nullptr;
      parent = &*s;
    }
    const auto it = parent->find(std::string(key));
    if (it == parent->end() || it->is_null()) return nullptr;
    return &*it;
  }
  std::string name(std::string_view section, std::string_view key) const {
    if (nested) return fmt::format("{}.{}", section, key);
    if (section == "lidar_data_format") return fmt::format("data_format.{}", key);
    return std::string(key);
  }
  [[noreturn]] void fail(std::string_view section, std::string_view key,
                         std::string_view what) const {
    fail_at(source, 0, name(section, key), what);
  }
  const json& need(std::string_view section, std::string_view key) const {
    const json* v = find(section, key);
    if (!v) fail(section, key, "missing");
    return *v;
  }
  std::string text(std::string_view section, std::string_view key,
                   std::string fallback = {}) const {
    const json* v = find(section, key);
    if (!v) return fallback;
    if (v->is_string()) return v->get<std::string>();
    if (v->is_number_unsigned() || v->is_number_integer()) return v->dump();
    fail(section, key, "expected a string");
  }
  long long integer(std::string_view section, std::string_view key, long long lo, long long hi,
                    const json* v = nullptr) const {
    if (!v) v = &need(section, key);
    if (!v->is_number_integer() && !v->is_number_unsigned())
      fail(section, key, fmt::format("expected an integer, got {}", v->dump()));
    if (v->is_number_unsigned() &&
        v->get<unsigned long long>() > static_cast<unsigned long long>(hi))
      fail(section, key, fmt::format("expected {} to {}, got {}", lo, hi, v->dump()));
    const long long x = v->get<long long>();
    if (x < lo || x > hi) fail(section, key, fmt::format("expected {} to {}, got {}", lo, hi, x));
    return x;
  }
  std::vector<double> numbers(std::string_view section, std::string_view key) const {
    const json& v = need(section, key);
    if (!v.is_array()) fail(section, key, "expected an array of numbers");
    std::vector<double> out;
    for (const json& x : v) {
      if (x.is_array()) {  // a 4x4 written as rows
        for (const json& y : x) {
          if (!y.is_number()) fail(section, key, "expected numbers");
          out.push_back(y.get<double>());
        }
        continue;
      }
      if (!x.is_number()) fail(section, key, "expected numbers");
      out.push_back(x.get<double>());
    }
    for (double x : out)
      if (!std::isfinite(x)) fail(section, key, "expected finite numbers");
    return out;
  }
  // A row-major 4x4 of 16 numbers, rigid (orthonormal rotation, last row 0 0 0 1).
  Eigen::Matrix4d transform(std::string_view section, std::string_view key) const {
    const std::vector<double> v = numbers(section, key);
    if (v.size() != 16)
      fail(section, key, fmt::format("expected 16 numbers (a row-major 4x4), got {}", v.size()));
    Eigen::Matrix4d m;
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) m(r, c) = v[4 * r + c];
    if (std::abs(m(3, 0)) > 1e-9 || std::abs(m(3, 1)) > 1e-9 || std::abs(m(3, 2)) > 1e-9 ||
        std::abs(m(3, 3) - 1) > 1e-9)
      fail(section, key, "last row must be 0 0 0 1");
    if (orthonormality_error(m.topLeftCorner<3, 3>()) > 1e-3 ||
        m.topLeftCorner<3, 3>().determinant() < 0)
      fail(section, key, "the rotation block is not a rotation");
    if (m.topRightCorner<3, 1>().cwiseAbs().maxCoeff() > kMaxOffsetMm)
      fail(section, key, fmt::format("translation beyond {} mm", kMaxOffsetMm));
    return m;
  }
};

SE3 metres(const Eigen::Matrix4d& m_mm) {
  SE3 T = SE3::from_matrix(m_mm);
  T.t *= 0.001;
  return T;
}

OusterLidarProfile profile_from(const View& v, std::string_view section, const std::string& s) {
  if (s == "LEGACY") return OusterLidarProfile::Legacy;
  if (s == "RNG19_RFL8_SIG16_NIR16") return OusterLidarProfile::Rng19Rfl8Sig16Nir16;
  if (s == "RNG19_RFL8_SIG16_NIR16_DUAL") return OusterLidarProfile::Rng19Rfl8Sig16Nir16Dual;
  if (s == "RNG15_RFL8_NIR8") return OusterLidarProfile::Rng15Rfl8Nir8;
  if (s == "RNG15_RFL8_NIR8_DUAL") return OusterLidarProfile::Rng15Rfl8Nir8Dual;
  if (s == "FUSA_RNG15_RFL8_NIR8_DUAL") return OusterLidarProfile::FusaRng15Rfl8Nir8Dual;
  v.fail(section, "udp_profile_lidar",
         fmt::format("unknown or unsupported profile '{}' (supported: LEGACY, "
                     "RNG19_RFL8_SIG16_NIR16[_DUAL], RNG15_RFL8_NIR8[_DUAL], "
                     "FUSA_RNG15_RFL8_NIR8_DUAL)",
                     s));
}

std::array<int, 3> firmware_of(const std::string& image_rev, const std::string& build_rev) {
  static const std::regex version(R"(v(\d{1,4})\.(\d{1,4})\.(\d{1,4}))");
  for (const std::string* s : {&image_rev, &build_rev}) {
    std::smatch m;
    if (std::regex_search(*s, m, version))
      return {std::stoi(m[1].str()), std::stoi(m[2].str()), std::stoi(m[3].str())};
  }
  return {0, 0, 0};
}

double default_beam_origin_mm(const std::string& prod_line) {
  if (prod_line.starts_with("OS-0")) return 27.67;
  if (prod_line.starts_with("OS-1")) return 15.806;
  if (prod_line.starts_with("OS-2")) return 13.762;
  return 12.163;
}

}  // namespace

std::string_view to_string(OusterLidarProfile profile) {
  switch (profile) {
    case OusterLidarProfile::Legacy:
      return "LEGACY";
    case OusterLidarProfile::Rng19Rfl8Sig16Nir16:
      return "RNG19_RFL8_SIG16_NIR16";
    case OusterLidarProfile::Rng19Rfl8Sig16Nir16Dual:
      return "RNG19_RFL8_SIG16_NIR16_DUAL";
    case OusterLidarProfile::Rng15Rfl8Nir8:
      return "RNG15_RFL8_NIR8";
    case OusterLidarProfile::Rng15Rfl8Nir8Dual:
      return "RNG15_RFL8_NIR8_DUAL";
    case OusterLidarProfile::FusaRng15Rfl8Nir8Dual:
      return "FUSA_RNG15_RFL8_NIR8_DUAL";
  }
  return "?";
}

OusterMetadata parse_ouster_metadata(std::string_view json_text, std::string_view source) {
  json root;
  try {
    root = json::parse(json_text);
  } catch (const json::exception& e) {
    fail_at(source, 0, "", fmt::format("not valid JSON: {}", e.what()));
  }
  if (!root.is_object()) fail_at(source, 0, "", "expected a JSON object");
  bool nested = true;
  for (const char* k : {"sensor_info", "beam_intrinsics", "imu_intrinsics", "lidar_intrinsics",
                        "config_params", "lidar_data_format", "calibration_status"})
    nested = nested && root.contains(k) && root[k].is_object();
  const View v{root, nested, source};

  OusterMetadata m;
  m.source = std::string(source);
  m.prod_line = v.text("sensor_info", "prod_line");
  m.prod_sn = v.text("sensor_info", "prod_sn");
  if (!m.prod_sn.empty() && m.prod_sn.size() <= 19 &&
      m.prod_sn.find_first_not_of("0123456789") == std::string::npos)
    m.prod_sn_number = std::stoull(m.prod_sn);
  if (const json* id = v.find("sensor_info", "initialization_id"))
    m.init_id = static_cast<uint32_t>(
        v.integer("sensor_info", "initialization_id", 0, (1LL << 24) - 1, id));
  m.build_rev = v.text("sensor_info", "build_rev");
  m.image_rev = v.text("sensor_info", "image_rev");
  m.fw_version = firmware_of(m.image_rev, m.build_rev);

  // The mode: "COLUMNSxHZ".
  m.lidar_mode = v.text("config_params", "lidar_mode");
  {
    static const std::regex mode(R"((\d{1,5})x(\d{1,3}))");
    std::smatch mm;
    if (!std::regex_match(m.lidar_mode, mm, mode))
      v.fail("config_params", "lidar_mode",
             fmt::format("expected COLUMNSxHZ such as 1024x10, got '{}'", m.lidar_mode));
    m.mode_columns = std::stoi(mm[1].str());
    m.mode_hz = std::stoi(mm[2].str());
    if (m.mode_columns < 1 || m.mode_columns > kMaxColumnsPerFrame || m.mode_hz < 1)
      v.fail("config_params", "lidar_mode",
             fmt::format("expected 1 to {} columns and a rate > 0, got '{}'", kMaxColumnsPerFrame,
                         m.lidar_mode));
  }

  const std::string_view df = "lidar_data_format";
  m.pixels_per_column =
      static_cast<int>(v.integer(df, "pixels_per_column", 1, kMaxPixelsPerColumn));
  m.columns_per_frame = static_cast<int>(
      v.find(df, "columns_per_frame") ? v.integer(df, "columns_per_frame", 1, kMaxColumnsPerFrame)
                                      : m.mode_columns);
  if (m.columns_per_frame != m.mode_columns)
    v.fail(df, "columns_per_frame",
           fmt::format("{} does not match lidar_mode '{}'", m.columns_per_frame, m.lidar_mode));
  const int w = m.columns_per_frame, h = m.pixels_per_column;
  m.columns_per_packet =
      static_cast<int>(v.find(df, "columns_per_packet") ? v.integer(df, "columns_per_packet", 1, w)
                                                        : std::min(16, w));
  if (w % m.columns_per_packet != 0)
    v.fail(df, "columns_per_packet",
           fmt::format("{} does not divide columns_per_frame {}", m.columns_per_packet, w));
  m.column_window = {0, w - 1};
  if (const json* cw = v.find(df, "column_window")) {
    if (!cw->is_array() || cw->size() != 2) v.fail(df, "column_window", "expected [first, last]");
    for (int i = 0; i < 2; ++i)
      m.column_window[i] = static_cast<int>(v.integer(df, "column_window", 0, w - 1, &(*cw)[i]));
  }
  if (const json* ps = v.find(df, "pixel_shift_by_row")) {
    if (!ps->is_array()) v.fail(df, "pixel_shift_by_row", "expected an array of integers");
    if (ps->size() > static_cast<size_t>(h))
      v.fail(df, "pixel_shift_by_row",
             fmt::format("{} entries for {} pixels_per_column", ps->size(), h));
    for (const json& x : *ps)
      m.pixel_shift_by_row.push_back(
          static_cast<int>(v.integer(df, "pixel_shift_by_row", -w, w, &x)));
  }
  m.pixel_shift_by_row.resize(h, 0);

  const std::string profile = v.text(df, "udp_profile_lidar", "LEGACY");
  m.udp_profile_lidar = profile_from(v, df, profile);
  m.udp_profile_imu = v.text(df, "udp_profile_imu", "LEGACY");
  m.header_type = m.udp_profile_lidar == OusterLidarProfile::FusaRng15Rfl8Nir8Dual
                      ? OusterHeaderType::Fusa
                      : OusterHeaderType::Standard;
  if (v.find(df, "header_type")) {
    const std::string ht = v.text(df, "header_type");
    if (ht == "STANDARD")
      m.header_type = OusterHeaderType::Standard;
    else if (ht == "FUSA")
      m.header_type = OusterHeaderType::Fusa;
    else
      v.fail(df, "header_type", fmt::format("expected STANDARD or FUSA, got '{}'", ht));
  }
  for (auto [key, port] : {std::pair{"udp_port_lidar", &m.udp_port_lidar},
                           std::pair{"udp_port_imu", &m.udp_port_imu}}) {
    const json* p = v.find("config_params", key);
    if (p && !(p->is_string() && p->get<std::string>().empty()))
      *port = static_cast<int>(v.integer("config_params", key, 0, 65535, p));
  }

  const std::string_view bi = "beam_intrinsics";
  m.beam_altitude_deg = v.numbers(bi, "beam_altitude_angles");
  m.beam_azimuth_deg = v.numbers(bi, "beam_azimuth_angles");
  for (auto [key, angles] : {std::pair{"beam_altitude_angles", &m.beam_altitude_deg},
                             std::pair{"beam_azimuth_angles", &m.beam_azimuth_deg}}) {
    if (angles->size() != static_cast<size_t>(h))
      v.fail(bi, key, fmt::format("{} angles for {} pixels_per_column", angles->size(), h));
    for (double a : *angles)
      if (std::abs(a) > 360) v.fail(bi, key, fmt::format("angle {} deg out of range", a));
  }
  m.lidar_origin_to_beam_origin_mm = default_beam_origin_mm(m.prod_line);
  if (const json* o = v.find(bi, "lidar_origin_to_beam_origin_mm")) {
    if (!o->is_number() || !(std::abs(o->get<double>()) <= kMaxOffsetMm))
      v.fail(bi, "lidar_origin_to_beam_origin_mm",
             fmt::format("expected a number of at most {} mm", kMaxOffsetMm));
    m.lidar_origin_to_beam_origin_mm = o->get<double>();
  }
  m.beam_to_lidar_mm = Eigen::Matrix4d::Identity();
  m.beam_to_lidar_mm(0, 3) = m.lidar_origin_to_beam_origin_mm;
  if (v.find(bi, "beam_to_lidar_transform"))
    m.beam_to_lidar_mm = v.transform(bi, "beam_to_lidar_transform");

  Eigen::Matrix4d lidar_to_sensor = Eigen::Matrix4d::Identity();
  lidar_to_sensor(0, 0) = lidar_to_sensor(1, 1) = -1;
  lidar_to_sensor(2, 3) = 36.18;
  if (v.find("lidar_intrinsics", "lidar_to_sensor_transform"))
    lidar_to_sensor = v.transform("lidar_intrinsics", "lidar_to_sensor_transform");
  m.T_sensor_lidar = metres(lidar_to_sensor);
  Eigen::Matrix4d imu_to_sensor = Eigen::Matrix4d::Identity();
  imu_to_sensor.topRightCorner<3, 1>() = Eigen::Vector3d(6.253, -11.775, 7.645);
  if (v.find("imu_intrinsics", "imu_to_sensor_transform"))
    imu_to_sensor = v.transform("imu_intrinsics", "imu_to_sensor_transform");
  m.T_sensor_imu = metres(imu_to_sensor);
  return m;
}

OusterMetadata read_ouster_metadata(const std::filesystem::path& path) {
  return parse_ouster_metadata(read_text_file(path, kMaxOusterMetadataBytes), path.string());
}

size_t ouster_lidar_packet_bytes(const OusterMetadata& m) {
  const size_t h = m.pixels_per_column, cpp = m.columns_per_packet;
  size_t block = 0;
  switch (m.udp_profile_lidar) {
    case OusterLidarProfile::Legacy:
      return cpp * (16 + 12 * h + 4);
    case OusterLidarProfile::Rng19Rfl8Sig16Nir16:
      block = 12;
      break;
    case OusterLidarProfile::Rng19Rfl8Sig16Nir16Dual:
      block = 16;
      break;
    case OusterLidarProfile::Rng15Rfl8Nir8:
      block = 4;
      break;
    case OusterLidarProfile::Rng15Rfl8Nir8Dual:
    case OusterLidarProfile::FusaRng15Rfl8Nir8Dual:
      block = 8;
      break;
  }
  return 32 + cpp * (12 + block * h) + 32;
}

bool ouster_packets_have_crc(const OusterMetadata& m) {
  return m.udp_profile_lidar != OusterLidarProfile::Legacy &&
         m.header_type == OusterHeaderType::Standard && m.fw_version[0] >= 3;
}

int ouster_expected_packets(const OusterMetadata& m) {
  const int w = m.columns_per_frame, cpp = m.columns_per_packet;
  // Plain ints: clang 14 (the sanitizer build) cannot capture structured bindings.
  const int first = m.column_window[0], last = m.column_window[1];
  const auto inside = [&](int c) {
    return first <= last ? (c >= first && c <= last) : (c >= first || c <= last);
  };
  int n = 0;
  for (int slot = 0; slot < w / cpp; ++slot) {
    bool touches = false;
    for (int c = slot * cpp; c < (slot + 1) * cpp && !touches; ++c) touches = inside(c);
    n += touches;
  }
  return n;
}

}  // namespace rigcal::io
