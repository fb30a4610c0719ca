// Point clouds (io::read_point_cloud and io::read_scan, a path), one target per extension: pcd,
// bin. For .bin, the part before a line "--bin--" is the topic's .metadata.json (vbr-devkit's
// full-field layout); without it the file is read as KITTI points.
#include "fuzz_common.h"
#include "rigcal/io/point_cloud_io.h"

static int fuzz_point_cloud(const std::string& kind, const uint8_t* data, size_t size) {
  using namespace rigcal;
  namespace fs = std::filesystem;
  const fs::path topic = fuzz::scratch() / "ouster_points";
  const fs::path file = topic / "data" / ("0000000000." + kind);
  std::string_view bytes = fuzz::as_text(data, size);
  std::error_code ec;
  fs::remove(topic / ".metadata.json", ec);
  if (kind == "bin") {
    const std::vector<std::string_view> parts = fuzz::split_parts(bytes, "--bin--");
    if (parts.size() > 1) {
      fuzz::write_file(topic / ".metadata.json", parts[0]);
      bytes = parts[1];
    }
  }
  fuzz::write_file(file, bytes);
  fuzz::expect_only_rigcal_errors([&] { io::read_point_cloud(file); });
  fuzz::expect_only_rigcal_errors([&] { io::read_scan(file); });
  return 0;
}
static int fuzz_point_cloud_pcd(const uint8_t* data, size_t size) {
  return fuzz_point_cloud("pcd", data, size);
}
static int fuzz_point_cloud_bin(const uint8_t* data, size_t size) {
  return fuzz_point_cloud("bin", data, size);
}
RIGCAL_FUZZ_TARGET(point_cloud_pcd, fuzz_point_cloud_pcd)
RIGCAL_FUZZ_TARGET(point_cloud_bin, fuzz_point_cloud_bin)
