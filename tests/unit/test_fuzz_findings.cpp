// Inputs the fuzz targets (tests/fuzz, doc/testing.md) found crashing a parser, each now a
// rigcal::Error naming the file: the same inputs are replayed from tests/fuzz/regressions/.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "fixtures.h"
#include "rigcal/core/error.h"
#include "rigcal/io/point_cloud_io.h"
#include "rigcal/io/target_yaml.h"
#include "rigcal/rig/rig_yaml.h"

namespace rigcal {
namespace {

namespace fs = std::filesystem;

using FuzzFindings = testing::ScratchTest;

constexpr const char* kPcdHeader =
    "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";

TEST_F(FuzzFindings, PcdPointsWithoutACount) {
  // Was std::out_of_range (POINTS with no value), and a negative count a std::length_error.
  for (auto [points, message] : {std::pair{"POINTS\n", "a.pcd:6: POINTS: expected one value"},
                                 std::pair{"POINTS -1\n", "a.pcd:6: POINTS: -1 is outside 0.."}}) {
    const fs::path f = write("a.pcd", std::string(kPcdHeader) + points + "DATA ascii\n1 2 3\n");
    const std::string e = error_of([&] { io::read_point_cloud(f); });
    EXPECT_NE(e.find(message), std::string::npos) << e;
  }
}

TEST_F(FuzzFindings, PcdHostileSizes) {
  // POINTS beyond what the file holds allocated it all first (48 GB binary, 24 GB ascii: out of
  // memory); SIZE times COUNT overflowed an int (undefined behaviour).
  const std::string binary =
      std::string(kPcdHeader) + "POINTS 4000000000\nDATA binary\n" + std::string(12, '\0');
  std::string e = error_of([&] { io::read_point_cloud(write("b.pcd", binary)); });
  EXPECT_NE(e.find("binary PCD of 12 data bytes does not hold its 4000000000 points"),
            std::string::npos)
      << e;
  // ASCII: the rows must be the header's POINTS (a PCD disagreeing with itself is damaged), and
  // nothing is reserved beyond what the bytes can hold.
  const fs::path ascii =
      write("c.pcd", std::string(kPcdHeader) + "POINTS 1000000000\nDATA ascii\n1 2 3\n");
  e = error_of([&] { io::read_point_cloud(ascii); });
  EXPECT_NE(e.find("1 points, the header's POINTS says 1000000000"), std::string::npos) << e;
  const fs::path big = write("d.pcd",
                             "VERSION 0.7\nFIELDS x y z pad\nSIZE 4 4 4 2147483647\nTYPE F F F "
                             "U\nCOUNT 1 1 1 2\nPOINTS 1\nDATA binary\n0123456789ab");
  e = error_of([&] { io::read_point_cloud(big); });
  EXPECT_NE(e.find("d.pcd:3: SIZE: 2147483647 is outside 1..8"), std::string::npos) << e;
}

TEST_F(FuzzFindings, RigNotesRead) {
  // rigcal.notes was read through a dangling reference (stack-use-after-scope under ASan).
  const rig::Rig rig = rig::parse_rig_yaml(
      "rigcal:\n  format_version: 1\n  notes: [first, second]\nlidar:\n  sensor_type: lidar\n"
      "  T_b: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n",
      "notes.yaml");
  ASSERT_EQ(rig.notes.size(), 2u);
  EXPECT_EQ(rig.notes[0], "first");
  EXPECT_EQ(rig.notes[1], "second");
}

TEST_F(FuzzFindings, TargetYamlTypeAndSizes) {
  // target_type as a map was YAML::BadConversion; targetCols 1e300 an int conversion out of range
  // (undefined behaviour).
  std::string e = error_of(
      [] { io::parse_target_yaml("target_type: {checkerboard: 1}\ntargetCols: 9\n", "t.yaml"); });
  EXPECT_NE(e.find("t.yaml:1: key 'target_type': expected a text value"), std::string::npos) << e;
  e = error_of([] {
    io::parse_target_yaml(
        "target_type: checkerboard\ntargetCols: 1e300\ntargetRows: 6\nrowSpacingMeters: "
        "0.025\ncolSpacingMeters: 0.025\n",
        "t.yaml");
  });
  EXPECT_NE(e.find("t.yaml:2: key 'targetCols': 1e+300 is outside 1..200"), std::string::npos) << e;
}

}  // namespace
}  // namespace rigcal
