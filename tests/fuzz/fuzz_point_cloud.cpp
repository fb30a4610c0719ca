// Point clouds (io::read_point_cloud and io::read_scan, a path): RIGCAL_FUZZ_CLOUD is pcd or bin. For .bin, the
// part before a line "--bin--" is the topic's .metadata.json (vbr-devkit's full-field layout);
// without it the file is read as KITTI points.
#include "fuzz_common.h"
#include "rigcal/io/point_cloud_io.h"

#define RIGCAL_STR2(x) #x
#define RIGCAL_STR(x) RIGCAL_STR2(x)

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rigcal;
  namespace fs = std::filesystem;
  static const std::string kind = RIGCAL_STR(RIGCAL_FUZZ_CLOUD);
  static const fs::path topic = fuzz::scratch() / "ouster_points";
  static const fs::path file = topic / "data" / ("0000000000." + kind);
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
