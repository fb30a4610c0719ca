#pragma once
// Point clouds (doc/formats.md): KITTI-style .bin (float32 x, y, z, intensity per point);
// vbr-devkit's full-field .bin (the driver's whole point record, described by the fields in the
// topic's .metadata.json beside data/; told from the reduced layout by content, not size); PCD
// v0.7 (DATA ascii or binary; fields x, y, z required, others skipped; binary_compressed is
// refused with a message). Points with no return, stored as (0, 0, 0) or NaN, are dropped.
// rigcal reads PCD itself rather than through PCL: the two layouts are a page of code, and PCL's
// io pulls 300 Debian packages into a clean install.
#include <Eigen/Core>
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "rigcal/core/scan.h"

namespace rigcal::io {

// A topic's .metadata.json is a few hundred bytes (the fields of one message type); a larger one
// is refused before it is parsed.
inline constexpr size_t kMaxMetadataBytes = 1 << 20;

// By extension: .bin (KITTI) or .pcd. Throws rigcal::Error naming the file and what is wrong.
std::vector<Eigen::Vector3d> read_point_cloud(const std::filesystem::path& path);

// The same files as scans with what they hold per point: full records give `t` (the Ouster
// driver's uint32 ns since the sweep's start; a float `t` is seconds), `ring`, `intensity`,
// `reflectivity`, `range` (mm) where their fields exist; KITTI points give intensity, and the
// times and rings of rigcal's simulator where its fields/ sidecar (doc/simulator.md) is beside
// data/; PCD gives x y z. Without times, Scan::point_times is false. The stamp is left 0 (the
// caller knows it from timestamps.txt). Points with no return are dropped as above.
Scan read_scan(const std::filesystem::path& path);

// A field of a point record, as sensor_msgs/PointField and vbr-devkit's .metadata.json list it:
// datatype 1 int8 .. 6 uint32, 7 float32, 8 float64.
struct PointField {
  std::string name;
  size_t offset = 0;
  int datatype = 0;
  size_t count = 1;
};
// Whole records of `point_step` bytes described by `fields` (x, y and z needed; t, intensity,
// ring, reflectivity and range taken where present, as read_scan takes them from a full-record
// .bin) as a scan, points with no return dropped; the stamp is left 0. Throws rigcal::Error
// saying what is wrong (`what` names the source): x, y or z missing, a field past the record,
// or data not a whole number of records.
Scan scan_from_records(std::string_view data, size_t point_step,
                       const std::vector<PointField>& fields, const std::string& what);

}  // namespace rigcal::io
