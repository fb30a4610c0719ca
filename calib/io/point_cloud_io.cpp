#include "rigcal/io/point_cloud_io.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <type_traits>

#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/io/files.h"
#include "rigcal/io/ros_messages.h"

namespace rigcal::io {
namespace {

// A point record is a few dozen bytes (the Ouster driver's: 48); a header claiming more is damaged.
constexpr size_t kMaxRecordBytes = 1 << 16;
// PCL counts points in 32 bits; what a file may hold is then bounded by its size.
constexpr long long kMaxPcdPoints = 4'294'967'295LL;
constexpr size_t kMaxPcdFields = 1024;

bool no_return(double x, double y, double z) {
  return !std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z) ||
         (x == 0 && y == 0 && z == 0);
}

void keep(std::vector<Eigen::Vector3d>& out, double x, double y, double z) {
  if (!no_return(x, y, z)) out.emplace_back(x, y, z);
}

using Field = PointField;

template <typename V>
double load(const char* p) {
  V v;
  std::memcpy(&v, p, sizeof v);
  return static_cast<double>(v);
}

double field_value(const char* record, const Field& f) {
  const char* p = record + f.offset;
  switch (f.datatype) {
    case 1:
      return load<int8_t>(p);
    case 2:
      return load<uint8_t>(p);
    case 3:
      return load<int16_t>(p);
    case 4:
      return load<uint16_t>(p);
    case 5:
      return load<int32_t>(p);
    case 6:
      return load<uint32_t>(p);
    case 7:
      return load<float>(p);
    default:
      return load<double>(p);
  }
}

// A non-negative integer of the metadata (a float, a negative or a string is refused: converting
// one would overflow or guess).
size_t whole_number(const nlohmann::json& v, const char* what) {
  if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<int64_t>() >= 0))
    throw Error(fmt::format("{} {} is not a non-negative integer", what, v.dump()));
  return v.get<size_t>();
}

// vbr-devkit writes a topic's fields in <topic>/.metadata.json beside data/; with
// --no-reduce-pcloud each point is the driver's whole record (point_step bytes), otherwise the
// four float32 x, y, z, intensity. Empty when there is no such file.
std::vector<Field> vbr_fields(const std::filesystem::path& bin, size_t& point_step) {
  const std::filesystem::path meta = bin.parent_path().parent_path() / ".metadata.json";
  if (!std::filesystem::exists(meta)) return {};
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(read_text_file(meta, kMaxMetadataBytes));
  } catch (const std::exception& e) {
    throw Error(fmt::format("{}: not JSON ({})", meta.string(), e.what()));
  }
  if (!j.contains("fields")) return {};
  std::vector<Field> fields;
  size_t extent = 0;
  try {
    for (const auto& f : j.at("fields")) {
      Field x{f.at("name").get<std::string>(), whole_number(f.at("offset"), "offset"),
              static_cast<int>(std::min<size_t>(whole_number(f.at("datatype"), "datatype"), 99)),
              f.contains("count") ? whole_number(f.at("count"), "count") : size_t{1}};
      if (point_field_size(static_cast<uint8_t>(x.datatype)) == 0)
        throw Error(fmt::format("field '{}': datatype {} unknown", x.name, x.datatype));
      if (x.offset > kMaxRecordBytes || x.count > kMaxRecordBytes)
        throw Error(fmt::format("field '{}': offset {} or count {} past any record", x.name,
                                x.offset, x.count));
      extent =
          std::max(extent, x.offset + point_field_size(static_cast<uint8_t>(x.datatype)) * x.count);
      fields.push_back(x);
    }
  } catch (const nlohmann::json::exception& e) {
    throw Error(fmt::format("{}: fields not read ({})", meta.string(), e.what()));
  } catch (const Error& e) {
    throw Error(fmt::format("{}: {}", meta.string(), e.what()));
  }
  // The record's size: "point_step" where given, else the fields' extent padded to 16 bytes
  // (the Ouster driver's and PCL's aligned point types: 48 bytes for x..range).
  try {
    point_step = j.contains("point_step") ? whole_number(j["point_step"], "point_step")
                                          : (extent + 15) / 16 * 16;
  } catch (const nlohmann::json::exception& e) {
    throw Error(fmt::format("{}: point_step not read ({})", meta.string(), e.what()));
  } catch (const Error& e) {
    throw Error(fmt::format("{}: {}", meta.string(), e.what()));
  }
  if (point_step < extent || point_step > kMaxRecordBytes) {
    throw Error(fmt::format("{}: point_step {} does not hold the fields ({} bytes)", meta.string(),
                            point_step, extent));
  }
  return fields;
}

// v as a T, held to T's range (NaN: 0): a damaged record's values convert without overflow.
template <typename T>
T saturated(double v) {
  if (!(v == v)) return T{0};
  const double low = static_cast<double>(std::numeric_limits<T>::lowest());
  const double high = static_cast<double>(std::numeric_limits<T>::max());
  if (v <= low) return std::numeric_limits<T>::lowest();
  if (v >= high) return std::numeric_limits<T>::max();
  return static_cast<T>(std::is_integral_v<T> ? std::round(v) : v);
}

// KITTI points, or vbr-devkit's full records where its metadata describes them.
Scan read_bin(const std::filesystem::path& path, bool sidecar_times) {
  const std::string data = read_text_file(path);  // binary-safe: one read of the whole file
  size_t step = 16;
  const std::vector<Field> fields = vbr_fields(path, step);
  auto find = [&](const char* name) -> const Field* {
    for (const Field& f : fields)
      if (f.name == name) return &f;
    return nullptr;
  };
  const Field *fx = find("x"), *fy = find("y"), *fz = find("z"), *ring = find("ring");
  // Full records? Both layouts may divide the file's size; the wrong one shows itself: KITTI
  // records read from full ones hold the driver's integer fields as tiny non-zero floats, full
  // records read from KITTI ones have rings in the tens of thousands.
  bool full = false;
  if (!fields.empty() && step != 16 && data.size() % step == 0) {
    if (!fx || !fy || !fz)
      throw Error(fmt::format("{}: the metadata's fields lack x, y or z", path.string()));
    size_t tiny = 0, records = data.size() / 16;
    for (size_t k = 0; k + 16 <= data.size(); k += 16) {
      float v[3];
      std::memcpy(v, data.data() + k, 12);
      bool all_tiny = v[0] != 0 || v[1] != 0 || v[2] != 0;
      for (float x : v) all_tiny = all_tiny && std::abs(x) < 1e-20f;
      tiny += all_tiny;
    }
    const bool kitti_plausible = data.size() % 16 == 0 && tiny * 20 < records;
    bool rings_plausible = true;
    if (ring) {
      for (size_t k = 0; k < data.size(); k += step)
        rings_plausible = rings_plausible && field_value(data.data() + k, *ring) < 1024;
    }
    if (rings_plausible && !kitti_plausible) {
      full = true;
    } else if (rings_plausible && kitti_plausible) {
      throw Error(fmt::format(
          "{}: {} bytes fit both {}-byte full records ({}) and 16-byte KITTI points; convert "
          "with vbr-devkit's default (reduced) layout",
          path.string(), data.size(), step, "the metadata's fields"));
    } else if (!kitti_plausible) {
      throw Error(fmt::format(
          "{}: neither {}-byte records of the metadata's fields (rings >= 1024) nor KITTI points "
          "(tiny non-zero coordinates); is .metadata.json this topic's?",
          path.string(), step));
    }
  }
  if (full) return scan_from_records(data, step, fields, path.string());
  Scan scan;
  if (data.size() % 16 != 0) {
    throw Error(fmt::format(
        "{}: {} bytes is not a whole number of KITTI points (4 float32 each){}", path.string(),
        data.size(),
        fields.empty() ? ""
                       : fmt::format(" nor of {}-byte records of the metadata's fields", step)));
  }
  // rigcal's simulator: t and ring of every point in fields/ beside data/, 8 bytes a point.
  const std::filesystem::path sidecar =
      path.parent_path().parent_path() / "fields" / path.filename();
  std::string sidecar_data;
  if (sidecar_times && path.parent_path().filename() == "data" &&
      std::filesystem::exists(sidecar)) {
    sidecar_data = read_text_file(sidecar);
    if (sidecar_data.size() != data.size() / 2) {
      throw Error(fmt::format("{}: {} bytes for the {} points of {} (8 bytes a point)",
                              sidecar.string(), sidecar_data.size(), data.size() / 16,
                              path.string()));
    }
  }
  // Not LiDAR points: coordinates of 100 km and more, or all three below 1e-20 m (a record's
  // integer fields read as floats: full records without their .metadata.json, or random bytes).
  size_t implausible = 0;
  for (size_t k = 0; k + 16 <= data.size(); k += 16) {
    float v[3];
    std::memcpy(v, data.data() + k, 12);
    const float m = std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])});
    implausible += std::isfinite(m) && (m >= 1e5f || (m > 0 && m < 1e-20f));
  }
  if (implausible * 100 > data.size() / 16) {
    throw Error(fmt::format(
        "{}: {} of {} points lie 100 km away or within 1e-20 m of the sensor: not KITTI points "
        "(float32 x y z intensity){}",
        path.string(), implausible, data.size() / 16,
        fields.empty() ? "; full records need their topic's .metadata.json beside data/" : ""));
  }
  scan.point_times = !sidecar_data.empty();
  scan.points.reserve(data.size() / 16);
  for (size_t k = 0; k < data.size(); k += 16) {
    float v[4];
    std::memcpy(v, data.data() + k, 16);
    if (no_return(v[0], v[1], v[2])) continue;
    ScanPoint p;
    p.p = Eigen::Vector3f(v[0], v[1], v[2]);
    p.intensity = v[3];
    if (!sidecar_data.empty()) {
      uint32_t t;
      std::memcpy(&t, sidecar_data.data() + k / 2, 4);
      std::memcpy(&p.ring, sidecar_data.data() + k / 2 + 4, 2);
      p.t_ns = t;
    }
    scan.points.push_back(p);
  }
  return scan;
}

std::vector<Eigen::Vector3d> read_pcd(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(fmt::format("{}: cannot open", path.string()));
  const std::string name = path.string();
  std::vector<std::string> fields, types;
  std::vector<int> sizes, counts;
  long long points = -1, width = -1, height = -1;
  std::string data_kind, line;
  int line_no = 0;
  while (data_kind.empty() && std::getline(in, line)) {
    ++line_no;
    const std::vector<std::string_view> f = split_fields(line);
    if (f.empty() || f[0].front() == '#') continue;
    const std::string key(f[0]);
    const std::string where = fmt::format("{}:{}: {}", name, line_no, key);
    std::vector<std::string> rest(f.begin() + 1, f.end());
    auto count = [&](std::string_view text, long long low, long long high) {
      const long long v = parse_int(text, where);
      if (v < low || v > high) {
        throw Error(fmt::format("{}: {} is outside {}..{}", where, v, low, high));
      }
      return v;
    };
    auto one = [&]() -> const std::string& {
      if (rest.size() != 1) throw Error(fmt::format("{}: expected one value", where));
      return rest[0];
    };
    if (rest.size() > kMaxPcdFields) {
      throw Error(
          fmt::format("{}: {} values (at most {} fields)", where, rest.size(), kMaxPcdFields));
    }
    if (key == "FIELDS") fields = rest;
    if (key == "TYPE") types = rest;
    if (key == "SIZE" || key == "COUNT") {
      std::vector<int>& v = key == "SIZE" ? sizes : counts;
      v.clear();
      for (const std::string& x : rest) {
        const long long n = key == "SIZE" ? count(x, 1, 8) : count(x, 1, 1 << 16);
        if (key == "SIZE" && n != 1 && n != 2 && n != 4 && n != 8)
          throw Error(fmt::format("{}: {} bytes (1, 2, 4 or 8)", where, n));
        v.push_back(static_cast<int>(n));
      }
    }
    if (key == "WIDTH") width = count(one(), 0, kMaxPcdPoints);
    if (key == "HEIGHT") height = count(one(), 0, kMaxPcdPoints);
    if (key == "POINTS") points = count(one(), 0, kMaxPcdPoints);
    if (key == "DATA") data_kind = rest.empty() ? "(none)" : rest[0];
  }
  if (data_kind.empty()) throw Error(fmt::format("{}: PCD header without a DATA line", name));
  if (points < 0 && width >= 0 && height >= 0) points = width * height;
  if (points < 0) throw Error(fmt::format("{}: PCD header without POINTS", name));
  if (width >= 0 && height >= 0 && width * height != points) {
    throw Error(fmt::format("{}: PCD header says WIDTH x HEIGHT = {} x {} but POINTS {}", name,
                            width, height, points));
  }
  if (counts.empty()) counts.assign(fields.size(), 1);
  if (fields.empty() || sizes.size() != fields.size() || types.size() != fields.size() ||
      counts.size() != fields.size()) {
    throw Error(
        fmt::format("{}: PCD header incomplete (FIELDS, SIZE, TYPE, COUNT disagree)", name));
  }
  int ix = -1, iy = -1, iz = -1;
  std::vector<int> offset(fields.size()), column(fields.size());
  int stride = 0, columns = 0;
  for (size_t i = 0; i < fields.size(); ++i) {
    if (fields[i] == "x") ix = static_cast<int>(i);
    if (fields[i] == "y") iy = static_cast<int>(i);
    if (fields[i] == "z") iz = static_cast<int>(i);
    offset[i] = stride, column[i] = columns;
    stride += sizes[i] * counts[i];
    columns += counts[i];
  }
  if (ix < 0 || iy < 0 || iz < 0) throw Error(fmt::format("{}: PCD without x, y, z fields", name));
  for (int i : {ix, iy, iz}) {
    if (types[i] != "F" || (sizes[i] != 4 && sizes[i] != 8)) {
      throw Error(fmt::format("{}: PCD field {} is not float32 or float64", name, fields[i]));
    }
  }
  // What the file holds after its header bounds every allocation, whatever POINTS claims.
  const auto header_end = static_cast<long long>(in.tellg());
  const auto remaining = static_cast<long long>(std::filesystem::file_size(path)) - header_end;
  std::vector<Eigen::Vector3d> out;
  if (data_kind == "ascii") {
    out.reserve(static_cast<size_t>(std::min(points, remaining / (2LL * columns) + 1)));
    long long rows = 0;
    while (std::getline(in, line)) {
      ++line_no;
      const std::vector<std::string_view> f = split_fields(line);
      if (f.empty()) continue;
      if (static_cast<int>(f.size()) < columns) {
        throw Error(
            fmt::format("{}:{}: {} values, the header says {}", name, line_no, f.size(), columns));
      }
      if (++rows > points) {
        throw Error(
            fmt::format("{}:{}: more points than the header's POINTS {}", name, line_no, points));
      }
      auto val = [&](int i) {
        return f[column[i]] == "nan"
                   ? NAN
                   : parse_double(f[column[i]], fmt::format("{}:{}: {}", name, line_no, fields[i]));
      };
      keep(out, val(ix), val(iy), val(iz));
    }
    if (rows != points) {
      throw Error(fmt::format("{}: {} points, the header's POINTS says {}", name, rows, points));
    }
  } else if (data_kind == "binary") {
    if (remaining < 0 || points > remaining / stride || points * stride != remaining) {
      throw Error(
          fmt::format("{}: binary PCD of {} data bytes does not hold its {} points of {} bytes",
                      name, std::max(remaining, 0LL), points, stride));
    }
    std::string buf(static_cast<size_t>(stride * points), '\0');
    in.read(buf.data(), static_cast<std::streamsize>(buf.size()));
    if (static_cast<size_t>(in.gcount()) != buf.size()) {
      throw Error(fmt::format("{}: binary PCD shorter than its {} points", name, points));
    }
    auto val = [&](size_t k, int i) {
      const char* p = buf.data() + k * stride + offset[i];
      return sizes[i] == 4 ? load<float>(p) : load<double>(p);
    };
    out.reserve(static_cast<size_t>(points));
    for (size_t k = 0; k < static_cast<size_t>(points); ++k)
      keep(out, val(k, ix), val(k, iy), val(k, iz));
  } else {
    throw Error(
        fmt::format("{}: PCD DATA '{}' not read (ascii or binary; convert with "
                    "pcl_convert_pcd_ascii_binary)",
                    name, data_kind));
  }
  return out;
}

}  // namespace

Scan scan_from_records(std::string_view data, size_t point_step,
                       const std::vector<PointField>& fields, const std::string& what) {
  auto find = [&](const char* name) -> const Field* {
    for (const Field& f : fields)
      if (f.name == name) return &f;
    return nullptr;
  };
  const Field *fx = find("x"), *fy = find("y"), *fz = find("z"), *ring = find("ring"),
              *ft = find("t"), *fi = find("intensity"), *fr = find("reflectivity"),
              *frange = find("range");
  if (!fx || !fy || !fz) throw Error(fmt::format("{}: the fields lack x, y or z", what));
  for (const Field& f : fields) {
    const size_t size =
        f.datatype >= 1 && f.datatype <= 8 ? point_field_size(static_cast<uint8_t>(f.datatype)) : 0;
    if (size == 0 || f.offset + size > point_step) {
      throw Error(
          fmt::format("{}: field '{}' (datatype {}, offset {}) is not inside the {}-byte "
                      "record",
                      what, f.name, f.datatype, f.offset, point_step));
    }
  }
  if (point_step == 0 || data.size() % point_step != 0) {
    throw Error(fmt::format("{}: {} bytes is not a whole number of {}-byte records", what,
                            data.size(), point_step));
  }
  Scan scan;
  scan.point_times = ft != nullptr;
  scan.points.reserve(data.size() / point_step);
  for (size_t k = 0; k < data.size(); k += point_step) {
    const char* r = data.data() + k;
    const double x = field_value(r, *fx), y = field_value(r, *fy), z = field_value(r, *fz);
    if (no_return(x, y, z)) continue;
    ScanPoint p;
    p.p = Eigen::Vector3f(saturated<float>(x), saturated<float>(y), saturated<float>(z));
    if (ft) {
      const double t = field_value(r, *ft);
      p.t_ns = saturated<int64_t>(ft->datatype >= 7 ? t * 1e9 : t);
    }
    if (fi) p.intensity = saturated<float>(field_value(r, *fi));
    if (ring) p.ring = saturated<uint16_t>(field_value(r, *ring));
    if (fr) p.reflectivity = saturated<uint16_t>(field_value(r, *fr));
    if (frange) p.range_mm = saturated<uint32_t>(field_value(r, *frange));
    scan.points.push_back(p);
  }
  return scan;
}

Scan read_scan(const std::filesystem::path& path) {
  const std::string ext = path.extension().string();
  if (ext == ".bin") return read_bin(path, true);
  if (ext == ".pcd") {
    Scan scan;
    scan.point_times = false;
    for (const Eigen::Vector3d& p : read_pcd(path)) scan.points.push_back({.p = p.cast<float>()});
    return scan;
  }
  throw Error(fmt::format("{}: unknown point cloud extension (.bin or .pcd)", path.string()));
}

std::vector<Eigen::Vector3d> read_point_cloud(const std::filesystem::path& path) {
  const std::string ext = path.extension().string();
  if (ext == ".pcd") return read_pcd(path);
  if (ext != ".bin")
    throw Error(fmt::format("{}: unknown point cloud extension (.bin or .pcd)", path.string()));
  const Scan scan = read_bin(path, false);
  std::vector<Eigen::Vector3d> out;
  out.reserve(scan.points.size());
  for (const ScanPoint& p : scan.points) out.push_back(p.p.cast<double>());
  return out;
}

}  // namespace rigcal::io
