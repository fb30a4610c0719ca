// Trajectory files: TUM, KITTI (+ times), EuRoC, detection, exact stamps, and malformed input whose
// messages name the file, the line and the field.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "fixtures.h"
#include "rigcal/core/error.h"
#include "rigcal/io/trajectory_io.h"

namespace rigcal::io {
namespace {

std::string error_of(std::string_view text, std::string_view name, TrajectoryReadOptions o = {}) {
  try {
    parse_trajectory(text, name, o);
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(TrajectoryIo, TumWithCommentsCommasAndSpaceRunsKeepsStampsExact) {
  const TrajectoryFile f = parse_trajectory(
      "# timestamp tx ty tz qx qy qz qw\n"
      "1403715529.112143517 1 2 3 0 0 0 1\n"
      "1.403715529212142944e+09,4,5,6,0,0,0.7071067811865476,0.7071067811865476\n"
      "\n"
      "1403715529.3  7   8\t9 0 0 0 1\r\n",
      "a.txt");
  EXPECT_EQ(f.format, TrajectoryFormat::tum);
  const Trajectory& t = f.trajectory;
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t.stamps[0].ns, 1403715529112143517LL);
  EXPECT_EQ(t.stamps[1].ns, 1403715529212142944LL);
  EXPECT_EQ(t.stamps[2].ns, 1403715529300000000LL);
  EXPECT_EQ(t.T_world_body[1].t, Eigen::Vector3d(4, 5, 6));
  EXPECT_TRUE(t.T_world_body[1].R.isApprox(
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix(), 1e-15));
  // Written back and read again: the same stamps and positions.
  const Trajectory back = parse_trajectory(trajectory_to_tum(t), "b.txt").trajectory;
  EXPECT_EQ(back.stamps, t.stamps);
  EXPECT_EQ(back.T_world_body[2].t, t.T_world_body[2].t);
}

TEST(TrajectoryIo, KittiWithAndWithoutTimes) {
  const std::string kitti = "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0.5 0 1 0 0 0 0 1 0\n";
  const TrajectoryFile f = parse_trajectory(kitti, "poses.txt");
  EXPECT_EQ(f.format, TrajectoryFormat::kitti);
  EXPECT_FALSE(f.trajectory.has_stamps);
  EXPECT_EQ(f.trajectory.T_world_body[1].t.x(), 0.5);
  const std::filesystem::path times = std::filesystem::temp_directory_path() / "rigcal_times.txt";
  std::ofstream(times) << "0.000000e+00\n1.037359e-01\n";
  TrajectoryReadOptions o;
  o.kitti_times = times;
  const TrajectoryFile g = parse_trajectory(kitti, "poses.txt", o);
  EXPECT_TRUE(g.trajectory.has_stamps);
  EXPECT_EQ(g.trajectory.stamps[1].ns, 103735900LL);
  std::ofstream(times) << "0.0\n";
  EXPECT_NE(error_of(kitti, "poses.txt", o).find("1 times for 2 poses"), std::string::npos);
  std::filesystem::remove(times);
}

// OpenCalib's lidar2imu pose files: the stamp (UTC, ms) then the row-major 3x4 [R | t].
TEST(TrajectoryIo, OpenCalibStampsAndMatrices) {
  const io::TrajectoryFile f = io::parse_trajectory(
      "2021-10-26-16-21-29-468 1 0 0 0.5 0 1 0 0 0 0 1 0\n"
      "2021-10-26-16-21-29-568 0 -1 0 1 1 0 0 2 0 0 1 3\n",
      "p.txt");
  EXPECT_EQ(f.format, io::TrajectoryFormat::opencalib);
  ASSERT_EQ(f.trajectory.size(), 2u);
  EXPECT_EQ(to_iso8601(f.trajectory.stamps[0]), "2021-10-26T16:21:29.468000000");
  EXPECT_EQ((f.trajectory.stamps[1] - f.trajectory.stamps[0]).ns, 100000000);
  EXPECT_EQ(f.trajectory.T_world_body[0].t, Eigen::Vector3d(0.5, 0, 0));
  EXPECT_EQ(f.trajectory.T_world_body[1].t, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(f.trajectory.T_world_body[1].R(1, 0), 1.0);
}

TEST(TrajectoryIo, EurocIsWFirstWithNanosecondStamps) {
  const std::string text =
      "#timestamp [ns], p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
      "q_RS_z []\n"
      "1403715524907143168,0.5,2.0,0.97,0.7071067811865476,0.7071067811865476,0,0\n";
  const TrajectoryFile f = parse_trajectory(text, "data.csv");
  EXPECT_EQ(f.format, TrajectoryFormat::euroc);
  EXPECT_EQ(f.trajectory.stamps[0].ns, 1403715524907143168LL);
  EXPECT_TRUE(f.trajectory.T_world_body[0].R.isApprox(
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix(), 1e-15));
}

TEST(TrajectoryIo, MalformedFilesNameFileLineAndField) {
  TrajectoryReadOptions tum;
  tum.format = TrajectoryFormat::tum;
  EXPECT_EQ(error_of("1 2 3 4 0 0 0 1\n2 2 3 4 0 0 1\n", "x.txt", tum),
            "x.txt:2: expected 8 fields 't tx ty tz qx qy qz qw' (TUM), got 7");
  EXPECT_EQ(error_of("1 2 3 4 0 0 0 1\n2 2 nan 4 0 0 0 1\n", "x.txt"),
            "x.txt:2: field 3 (ty): expected a finite number, got 'nan'");
  EXPECT_EQ(error_of("1 2 3 4 0 0 0 1\n2 2 3 4 0 0 0 1\n1.5 2 3 4 0 0 0 1\n", "x.txt"),
            "x.txt:3: stamp 1.5 is before the previous one (2.000000000 s, line 2); stamps must "
            "increase");
  EXPECT_EQ(error_of("# c\n1 2 3 4 0 0 0 1\n1.0 2 3 4 0 0 0 1\n", "x.txt"),
            "x.txt:3: stamp 1.0 is equal to the previous one (1.000000000 s, line 2); stamps must "
            "increase (--duplicate-stamps drop|keep)");
  EXPECT_EQ(error_of("", "x.txt"), "x.txt: no poses: the file is empty or all comments");
  EXPECT_EQ(error_of("# only a comment\n", "x.txt"),
            "x.txt: no poses: the file is empty or all comments");
  EXPECT_EQ(error_of("1 2 3 4 0 0 0 0\n", "x.txt"), "x.txt:1: zero quaternion");
  EXPECT_EQ(error_of("1 2 3 4 5\n", "x.txt"),
            "x.txt:1: cannot tell the trajectory format from 5 fields (TUM has 8, KITTI 12, EuRoC "
            "CSV 8 or more with integer ns stamps, OpenCalib 13 with a dashed date); give "
            "--format");
  // OpenCalib: a dashed stamp and 12 numbers; a bad stamp is named.
  EXPECT_EQ(error_of("2021-10-26-16-21-29-468 1 0 0 0 0 1 0 0 0 0 1 0\n"
                     "2021-10-26-16-21-29-56x 1 0 0 0 0 1 0 0 0 0 1 0\n",
                     "o.txt"),
            "o.txt:2: field 1 (stamp): expected YYYY-MM-DD-HH-MM-SS-mmm, got "
            "'2021-10-26-16-21-29-56x'");
  EXPECT_EQ(error_of("1s 2 3 4 0 0 0 1\n", "x.txt"),
            "x.txt:1: field 1 (t): expected seconds, got '1s'");
  EXPECT_EQ(error_of("1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 2 0\n", "k.txt"),
            "k.txt:2: the 3x3 block is not a rotation (max |R^T R - I| = 3)");
}

TEST(TrajectoryIo, DuplicateStampsCanBeDroppedOrKept) {
  const std::string text = "1 0 0 0 0 0 0 1\n1 5 0 0 0 0 0 1\n2 0 0 0 0 0 0 1\n";
  TrajectoryReadOptions o;
  o.duplicates = TrajectoryReadOptions::Duplicates::drop;
  TrajectoryFile f = parse_trajectory(text, "d.txt", o);
  EXPECT_EQ(f.trajectory.size(), 2u);
  EXPECT_EQ(f.duplicate_stamps, 1u);
  EXPECT_EQ(f.trajectory.T_world_body[0].t.x(), 0.0);  // the first one kept
  o.duplicates = TrajectoryReadOptions::Duplicates::keep;
  f = parse_trajectory(text, "d.txt", o);
  EXPECT_EQ(f.trajectory.size(), 3u);
}

TEST(TrajectoryIo, RealFilesOfEveryFormat) {
  RIGCAL_REQUIRE_FIXTURE(euroc, "trajectories/evo/V102_groundtruth.csv");
  const TrajectoryFile e = read_trajectory(euroc);
  EXPECT_EQ(e.format, TrajectoryFormat::euroc);
  EXPECT_EQ(e.trajectory.size(), 16702u);
  EXPECT_EQ(e.trajectory.stamps[0].ns, 1403715524907143168LL);
  // V102.txt (evo's VIO estimate) repeats four stamps with other poses, the first on line 433.
  const std::string v102 = testing::fixture("trajectories/evo/V102.txt");
  try {
    read_trajectory(v102);
    ADD_FAILURE() << "no error for the duplicate stamp";
  } catch (const Error& err) {
    EXPECT_NE(std::string(err.what()).find("V102.txt:433: stamp 1.403715572212143183e+09 is equal"),
              std::string::npos)
        << err.what();
  }
  TrajectoryReadOptions keep;
  keep.duplicates = TrajectoryReadOptions::Duplicates::keep;
  const TrajectoryFile tum = read_trajectory(v102, keep);
  EXPECT_EQ(tum.format, TrajectoryFormat::tum);
  EXPECT_EQ(tum.trajectory.size(), 807u);
  EXPECT_EQ(tum.duplicate_stamps, 4u);                            // awk: four stamps appear twice
  EXPECT_EQ(tum.trajectory.stamps[0].ns, 1403715529112143517LL);  // "%e" text, kept exactly
  TrajectoryReadOptions o;
  o.kitti_times = testing::fixture("trajectories/evo/KITTI_00_gt_times.txt");
  const TrajectoryFile k = read_trajectory(testing::fixture("trajectories/evo/KITTI_00_gt.txt"), o);
  EXPECT_EQ(k.format, TrajectoryFormat::kitti);
  EXPECT_EQ(k.trajectory.size(), 4541u);
  EXPECT_EQ(k.trajectory.stamps.back().ns, 470581600000LL);
  // fr2_desk's ground truth has one duplicate stamp: refused by default, named by line.
  const std::string desk = testing::fixture("trajectories/evo/fr2_desk_groundtruth.txt");
  try {
    read_trajectory(desk);
    ADD_FAILURE() << "no error for the duplicate stamp";
  } catch (const Error& err) {
    EXPECT_NE(std::string(err.what()).find("is equal to the previous one"), std::string::npos)
        << err.what();
  }
  o = {};
  o.duplicates = TrajectoryReadOptions::Duplicates::drop;
  const TrajectoryFile d = read_trajectory(desk, o);
  EXPECT_EQ(d.duplicate_stamps, 1u);
  EXPECT_EQ(d.trajectory.size(), 20956u);
  // The VBR benchmark files: runs of spaces; the ORB estimate's near-zero quaternion component.
  const TrajectoryFile v = read_trajectory(
      testing::fixture("trajectories/vbr/vbr_slam_benchmark/gt/colosseo_train_gt.txt"));
  EXPECT_EQ(v.trajectory.size(), 8824u);
}

}  // namespace
}  // namespace rigcal::io
