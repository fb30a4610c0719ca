// Point cloud readers (doc/formats.md): KITTI .bin, vbr-devkit's full-field .bin described by its
// .metadata.json (both layouts under the same metadata, told apart by their content), binary PCD,
// and the errors.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "devkit_layout.h"
#include "rigcal/core/error.h"
#include "rigcal/io/point_cloud_io.h"

namespace rigcal::io {
namespace {

namespace fs = std::filesystem;

class PointCloudIo : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("rigcal_pcio_" + std::to_string(::getpid()));
    fs::create_directories(dir_ / "ouster_points" / "data");
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const fs::path& rel, const std::string& bytes) {
    std::ofstream(dir_ / rel, std::ios::binary) << bytes;
    return dir_ / rel;
  }
  // Point k of a synthetic organized scan: 128 rings; every 7th has no return (zeros).
  static Eigen::Vector3f point(int k) {
    if (k % 7 == 3) return Eigen::Vector3f::Zero();
    return {1.0f + 0.01f * k, -2.0f + 0.003f * k, 0.5f - 0.002f * k};
  }
  static std::string full_records(int n) {
    std::string out(48 * static_cast<size_t>(n), '\0');
    for (int k = 0; k < n; ++k) {
      char* r = out.data() + 48 * k;
      const Eigen::Vector3f p = point(k);
      std::memcpy(r, p.data(), 12);
      const float intensity = 100.0f + k;
      const uint32_t t = 48828u * static_cast<uint32_t>(k / 128), range = 3000u + k;
      const uint16_t refl = 40, ring = static_cast<uint16_t>(k % 128), ambient = 7;
      std::memcpy(r + 16, &intensity, 4);
      std::memcpy(r + 20, &t, 4);
      std::memcpy(r + 24, &refl, 2);
      std::memcpy(r + 26, &ring, 2);
      std::memcpy(r + 28, &ambient, 2);
      std::memcpy(r + 32, &range, 4);
    }
    return out;
  }
  static std::string kitti_records(int n) {
    std::string out(16 * static_cast<size_t>(n), '\0');
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector3f p = point(k);
      const float intensity = 100.0f + k;
      std::memcpy(out.data() + 16 * k, p.data(), 12);
      std::memcpy(out.data() + 16 * k + 12, &intensity, 4);
    }
    return out;
  }
  static void expect_points(const std::vector<Eigen::Vector3d>& got, int n) {
    size_t j = 0;
    for (int k = 0; k < n; ++k) {
      if (point(k).isZero()) continue;
      ASSERT_LT(j, got.size());
      EXPECT_LT((got[j++] - point(k).cast<double>()).norm(), 1e-9) << k;
    }
    EXPECT_EQ(j, got.size());
  }
  fs::path dir_;
};

TEST_F(PointCloudIo, KittiBinWithoutMetadata) {
  const fs::path f = write("ouster_points/data/0000000000.bin", kitti_records(384));
  expect_points(read_point_cloud(f), 384);
}

// 384 points: 16 x 384 bytes is also a whole number of 48-byte records, so the reader must tell
// the layouts apart by their content (rings), not by the size.
TEST_F(PointCloudIo, VbrDevkitMetadataReducedAndFullLayouts) {
  write("ouster_points/.metadata.json", testing::ouster_metadata_json("/os_cloud_node/points", 1));
  const fs::path reduced = write("ouster_points/data/0000000000.bin", kitti_records(384));
  const fs::path full = write("ouster_points/data/0000000001.bin", full_records(384));
  expect_points(read_point_cloud(reduced), 384);
  expect_points(read_point_cloud(full), 384);
  // 128 points: the full file's size is also a whole number of KITTI points; the driver's
  // integer fields read as floats give it away.
  const fs::path full_128 = write("ouster_points/data/0000000002.bin", full_records(128));
  expect_points(read_point_cloud(full_128), 128);
}

TEST_F(PointCloudIo, BinaryPcd) {
  std::string body = kitti_records(50);
  const std::string header =
      "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 "
      "1\nWIDTH 50\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 50\nDATA binary\n";
  expect_points(read_point_cloud(write("a.pcd", header + body)), 50);
}

TEST_F(PointCloudIo, ErrorsNameTheFile) {
  const fs::path odd = write("ouster_points/data/0000000000.bin", std::string(17, '\0'));
  try {
    read_point_cloud(odd);
    FAIL() << "17 bytes read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not a whole number of KITTI points"), std::string::npos)
        << e.what();
  }
  write("ouster_points/.metadata.json", "{\"fields\": [{\"name\": \"x\"}]}");
  EXPECT_THROW(read_point_cloud(odd), Error);
  EXPECT_THROW(read_point_cloud(write("b.xyz", "1 2 3\n")), Error);
  std::string pcd =
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 10\nHEIGHT 1\nPOINTS "
      "10\nDATA binary_compressed\n";
  try {
    read_point_cloud(write("c.pcd", pcd));
    FAIL() << "binary_compressed read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("binary_compressed"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rigcal::io
