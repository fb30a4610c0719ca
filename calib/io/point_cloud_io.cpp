#include "rigcal/io/point_cloud_io.h"

#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

#include "rigcal/core/error.h"
#include "rigcal/core/text.h"

namespace rigcal::io {
namespace {

void keep(std::vector<Eigen::Vector3d>& out, double x, double y, double z) {
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) return;
  if (x == 0 && y == 0 && z == 0) return;
  out.emplace_back(x, y, z);
}

std::vector<Eigen::Vector3d> read_kitti_bin(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(fmt::format("{}: cannot open", path.string()));
  const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (data.size() % 16 != 0) {
    throw Error(fmt::format("{}: {} bytes is not a whole number of KITTI points (4 float32 each)",
                            path.string(), data.size()));
  }
  std::vector<Eigen::Vector3d> out;
  out.reserve(data.size() / 16);
  for (size_t k = 0; k < data.size(); k += 16) {
    float v[4];
    std::memcpy(v, data.data() + k, 16);
    keep(out, v[0], v[1], v[2]);
  }
  return out;
}

std::vector<Eigen::Vector3d> read_pcd(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(fmt::format("{}: cannot open", path.string()));
  const std::string name = path.string();
  std::vector<std::string> fields, types;
  std::vector<int> sizes, counts;
  size_t points = 0;
  std::string data_kind, line;
  int line_no = 0;
  while (data_kind.empty() && std::getline(in, line)) {
    ++line_no;
    const std::vector<std::string_view> f = split_fields(line);
    if (f.empty() || f[0].front() == '#') continue;
    const std::string key(f[0]);
    std::vector<std::string> rest(f.begin() + 1, f.end());
    if (key == "FIELDS") fields = rest;
    if (key == "TYPE") types = rest;
    if (key == "SIZE" || key == "COUNT") {
      std::vector<int>& v = key == "SIZE" ? sizes : counts;
      for (const std::string& s : rest) v.push_back(static_cast<int>(parse_int(s, key)));
    }
    if (key == "POINTS") points = static_cast<size_t>(parse_int(rest.at(0), "POINTS"));
    if (key == "DATA") data_kind = rest.empty() ? "" : rest[0];
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
  std::vector<Eigen::Vector3d> out;
  out.reserve(points);
  if (data_kind == "ascii") {
    while (std::getline(in, line)) {
      ++line_no;
      const std::vector<std::string_view> f = split_fields(line);
      if (f.empty()) continue;
      if (static_cast<int>(f.size()) < columns) {
        throw Error(
            fmt::format("{}:{}: {} values, the header says {}", name, line_no, f.size(), columns));
      }
      auto val = [&](int i) {
        return f[column[i]] == "nan" ? NAN : parse_double(f[column[i]], fields[i]);
      };
      keep(out, val(ix), val(iy), val(iz));
    }
  } else if (data_kind == "binary") {
    std::string buf(static_cast<size_t>(stride) * points, '\0');
    in.read(buf.data(), static_cast<std::streamsize>(buf.size()));
    if (static_cast<size_t>(in.gcount()) != buf.size()) {
      throw Error(fmt::format("{}: binary PCD shorter than its {} points", name, points));
    }
    auto val = [&](size_t k, int i) {
      const char* p = buf.data() + k * stride + offset[i];
      if (sizes[i] == 4) {
        float v;
        std::memcpy(&v, p, 4);
        return static_cast<double>(v);
      }
      double v;
      std::memcpy(&v, p, 8);
      return v;
    };
    for (size_t k = 0; k < points; ++k) keep(out, val(k, ix), val(k, iy), val(k, iz));
  } else {
    throw Error(
        fmt::format("{}: PCD DATA '{}' not read (ascii or binary; convert with "
                    "pcl_convert_pcd_ascii_binary)",
                    name, data_kind));
  }
  return out;
}

}  // namespace

std::vector<Eigen::Vector3d> read_point_cloud(const std::filesystem::path& path) {
  const std::string ext = path.extension().string();
  if (ext == ".bin") return read_kitti_bin(path);
  if (ext == ".pcd") return read_pcd(path);
  throw Error(fmt::format("{}: unknown point cloud extension (.bin or .pcd)", path.string()));
}

}  // namespace rigcal::io
