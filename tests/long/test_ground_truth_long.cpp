// The ground truth's acceptance on simulated recordings (doc/ground-truth.md, "Measured"): three
// seeds each of the ground-truth part's walk (60 s, a 15 s outage) and of a drive (60 s at about
// 8 m/s, the same outage: about 120 m without a fix), through `rigcal ground-truth` with its
// defaults, scored against the truth in ENU without alignment; the markers' distances against
// the survey's. The short version is GroundTruthSim in the unit tests.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include "ground_truth_sim.h"
#include "rigcal/io/trajectory_io.h"

namespace rigcal {
namespace {

// `odometry_rpe_factor`: the ground truth's RPE over 10 m at most this times the odometry's (1:
// better than it, the acceptance's bar).
// RIGCAL_GT_ARGS, when set, is given to every `rigcal ground-truth` of the acceptance (the bound
// with the true motions included), to measure an option's effect on the same recordings:
// RIGCAL_GT_ARGS='--fix-correlation 5' (doc/ground-truth.md).
void acceptance(const std::string& name, const std::string& config, double odometry_rpe_factor,
                uint64_t seeds = 3) {
  namespace fs = std::filesystem;
  const char* extra = std::getenv("RIGCAL_GT_ARGS");
  const std::string extra_args = extra ? extra : "";
  for (uint64_t seed = 1; seed <= seeds; ++seed) {
    const fs::path dir =
        fs::temp_directory_path() / fmt::format("rigcal_gt_long_{}_{}_{}", name, seed, ::getpid());
    const testing::GroundTruthScore s =
        testing::simulated_ground_truth(dir, seed, config, extra_args, /*stages=*/true);
    ASSERT_EQ(s.status, 0) << s.out << s.err;
    const nlohmann::json& summary = s.report["summary"];
    std::printf(
        "[ figures ] %s seed %d: %zu poses, %.0f m; ATE in ENU %.1f mm rms (max %.1f; horizontal "
        "%.1f, vertical %.1f); %.1f %% of the position components within 3 sigma; fixes' "
        "correlation %.1f s; markers %zu of %zu, distances %.1f mm rms (max %.1f); "
        "ground-truth %.0f s\n",
        name.c_str(), int(seed), s.poses, summary["path_length_m"].get<double>(), 1e3 * s.ate_rms_m,
        1e3 * s.ate_max_m, 1e3 * s.ate_horizontal_rms_m, 1e3 * s.ate_vertical_rms_m,
        100 * s.within_3_sigma, summary["fix_correlation_s"].get<double>(), s.markers_found,
        s.markers, 1e3 * s.marker_rms_m, 1e3 * s.marker_max_m, s.gt_seconds);
    std::printf(
        "[ figures ] %s seed %d, by stage: ATE in ENU after stage 1 %.1f mm rms (max %.1f), after "
        "the bundle adjustment %.1f (max %.1f), with the true motions %.1f; RPE over 10 m: "
        "odometry %.1f mm, GNSS/INS %.1f, stage 1 %.1f, ground truth %.1f\n",
        name.c_str(), int(seed), 1e3 * s.ate_stage1_rms_m, 1e3 * s.ate_stage1_max_m,
        1e3 * s.ate_rms_m, 1e3 * s.ate_max_m, 1e3 * s.ate_exact_motions_rms_m,
        1e3 * s.rpe10_odometry_m, 1e3 * s.rpe10_gnss_m, 1e3 * s.rpe10_stage1_m, 1e3 * s.rpe10_m);
    std::fflush(stdout);
    // 2 cm, or, where the fixes themselves do not anchor the true motions that well (their
    // vertical error, 2 cm correlated over 5 s, over a minute), within 15 % of what they do.
    EXPECT_LT(s.ate_rms_m, std::max(0.02, 1.15 * s.ate_exact_motions_rms_m))
        << name << " seed " << seed;
    EXPECT_LT(s.ate_max_m, 0.05) << name << " seed " << seed;
    EXPECT_EQ(s.markers_found, 6u) << name << " seed " << seed;
    EXPECT_LT(s.marker_max_m, 0.01) << name << " seed " << seed;
    EXPECT_GE(s.within_3_sigma, 0.95) << name << " seed " << seed;
    EXPECT_LT(s.rpe10_m, odometry_rpe_factor * s.rpe10_odometry_m) << name << " seed " << seed;
    EXPECT_LT(s.rpe10_m, s.rpe10_gnss_m) << name << " seed " << seed;
    fs::remove_all(dir);
  }
}

// The walk goes through the simulator's building (a bare corridor, stairs up and down, no GNSS)
// and reads the fixes with their states: its ATE misses the bar on seed 1 (23.0 mm against 20.0;
// doc/ground-truth.md says where and why), every other bar holds.
TEST(GroundTruthSimLong, AWalkOfAMinuteThreeSeeds) { acceptance("walk", "{}\n", 1.0); }

TEST(GroundTruthSimLong, ADriveOfAMinuteWithA120mOutageThreeSeeds) {
  // rigcal's odometry of the car (smooth, at 8 m/s between boxes) drifts 0.009 %, the bundle
  // adjustment's motions alone about twice that: the ground truth's RPE over 10 m beats the
  // odometry's through the fusion of the two a step (motion_fusion.h; doc/ground-truth.md).
  // Seed 1's ATE misses its bar (23.6 mm against 22.5, mostly vertical; doc/ground-truth.md).
  acceptance("drive", "trajectories:\n  motion: car\n", 1.0);
}

// The acceptance's walk of a kilometre (13 minutes at the walk's 1.3 m/s, the building and its
// outage in its first minute, the markers along its longest stretch outdoors), one seed: about
// 7,800 sweeps, 7 GB of scans on disk while it runs, 40 minutes on 2 cores. Measured
// (doc/ground-truth.md): 1025 m, ATE in ENU 11.4 mm rms (max 37.1), markers 1.3 mm rms, RPE over
// 10 m 5.8 mm against the odometry's 69.3; every bar met.
TEST(GroundTruthSimLong, AWalkOfAKilometreOneSeed) {
  acceptance("walk_1km", "trajectories:\n  duration_s: 780\n", 1.0, 1);
}

// What the photometric term adds (`--photometric`): three seeds each of the walk and the drive
// through `rigcal ground-truth` without it and with it, the same recordings. It makes the ground
// truth worse (RPE over 10 m: the walks 2.2-3.0 -> 14.8-21.3 mm, the drives 1.2-1.4 -> 2.7-3.1;
// doc/ground-truth.md, "The photometric term"), so what is checked is that it runs through and
// stays honest (the sigmas, which come from the GNSS and the motions' covariances, still cover
// the errors); the figures are the measurement.
TEST(GroundTruthSimLong, WhatThePhotometricTermAdds) {
  namespace fs = std::filesystem;
  for (const auto& [name, config] : {std::pair<std::string, std::string>{"walk", "{}\n"},
                                     {"drive", "trajectories:\n  motion: car\n"}}) {
    for (uint64_t seed = 1; seed <= 3; ++seed) {
      testing::GroundTruthScore s[2];
      double rpe10[2] = {0, 0};
      for (int photometric = 0; photometric < 2; ++photometric) {
        const fs::path dir =
            fs::temp_directory_path() /
            fmt::format("rigcal_gt_photometric_{}_{}_{}_{}", name, seed, photometric, ::getpid());
        s[photometric] =
            testing::simulated_ground_truth(dir, seed, config, photometric ? "--photometric" : "");
        ASSERT_EQ(s[photometric].status, 0) << s[photometric].out << s[photometric].err;
        rpe10[photometric] = testing::rpe_10m(
            io::read_trajectory(dir / "rec/trajectories/truth_lidar.tum").trajectory,
            io::read_trajectory(dir / "gt.txt").trajectory);
        fs::remove_all(dir);
      }
      std::printf(
          "[ figures ] %s seed %d: ATE in ENU %.2f -> %.2f mm rms (max %.1f -> %.1f), RPE over 10 "
          "m %.2f -> %.2f mm, within 3 sigma %.1f -> %.1f %%, markers %.2f -> %.2f mm rms; "
          "ground-truth %.0f -> %.0f s (without -> with the photometric term)\n",
          name.c_str(), int(seed), 1e3 * s[0].ate_rms_m, 1e3 * s[1].ate_rms_m, 1e3 * s[0].ate_max_m,
          1e3 * s[1].ate_max_m, 1e3 * rpe10[0], 1e3 * rpe10[1], 100 * s[0].within_3_sigma,
          100 * s[1].within_3_sigma, 1e3 * s[0].marker_rms_m, 1e3 * s[1].marker_rms_m,
          s[0].gt_seconds, s[1].gt_seconds);
      std::fflush(stdout);
      EXPECT_EQ(s[1].markers_found, 6u) << name << " seed " << seed;
      EXPECT_GE(s[1].within_3_sigma, 0.95) << name << " seed " << seed;
    }
  }
}

}  // namespace
}  // namespace rigcal
