#pragma once
// The step covariances' honesty over seeds (test_odometry.cpp, tests/long/): simulated street
// drives, every sweep made as it is registered, each step's normalized squared error
// e^T C^-1 e against the chi-square with 6 degrees of freedom: within 20.06 (its 3-sigma level,
// 99.73 %) in at least 95 % of steps when C describes the errors. Steps whose covariance was
// widened along a degenerate direction (OdometryConfig::degenerate_sigma_m) are counted apart:
// the bar is held on the others, which the widening cannot help.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "rigcal/lidar/odometry.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/sim/session.h"

namespace rigcal::lidar {

struct HonestyFigures {
  size_t steps = 0, within = 0, within_without_floor = 0;
  size_t widened = 0, unwidened_within = 0;  // steps widened; of the others, those within
  double nees_mean = 0;
};

inline HonestyFigures odometry_honesty(const sim::LidarModel& sensor, const OdometryConfig& preset,
                                       uint64_t first_seed, uint64_t last_seed, int sweeps) {
  constexpr double kChi2_6_3sigma = 20.06;
  const rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  HonestyFigures h;
  for (uint64_t seed = first_seed; seed <= last_seed; ++seed) {
    sim::SimConfig config;
    config.seed = seed;
    config.scans = sweeps;
    config.lidar = sensor;
    sim::SweepDrive street = sim::street_drive(rig, config);
    Odometry odometry = start_odometry(preset);
    std::vector<SE3> T_world_lidar;
    std::printf("[ figures ] seed %d: step NEES", int(seed));
    for (int k = 0; k < sweeps; ++k) {
      const sim::Sweep sweep = sim::next_sweep(street);
      const Step step = register_scan(odometry, sim::scan_of(sweep.points, sweep.stamp));
      EXPECT_EQ(step.skipped, "");
      T_world_lidar.push_back(sweep.T_world_lidar);
      if (k == 0) continue;
      const std::vector<SE3>& est = odometry.T_odom_lidar.T_world_body;
      const SE3 T_prev_cur = est[k - 1].inverse() * est[k];
      const SE3 truth = T_world_lidar[k - 1].inverse() * T_world_lidar[k];
      Vector6d e;  // T_prev_cur = perturbed(truth, e), the covariance's tangent
      e.head<3>() = rotation_vector(T_prev_cur.R * truth.R.transpose());
      e.tail<3>() = T_prev_cur.t - truth.t;
      const double nees = e.dot(step.covariance_prev_cur.ldlt().solve(e));
      Matrix6d C = step.covariance_prev_cur;  // without the preset's floor
      for (int i = 0; i < 3; ++i) {
        C(i, i) -= std::pow(preset.step_sigma_floor_deg * M_PI / 180, 2);
        C(i + 3, i + 3) -= std::pow(preset.step_sigma_floor_m, 2);
      }
      h.within_without_floor += e.dot(C.ldlt().solve(e)) <= kChi2_6_3sigma;
      h.within += nees <= kChi2_6_3sigma;
      h.widened += step.degeneracy.translation_widened;
      h.unwidened_within += !step.degeneracy.translation_widened && nees <= kChi2_6_3sigma;
      h.nees_mean += nees;
      ++h.steps;
      std::printf(" %.1f", nees);
    }
    std::printf("\n");
  }
  h.nees_mean /= double(h.steps);
  std::printf(
      "[ figures ] seeds %d-%d: step errors within 3 sigma (NEES <= 20.06): %zu of %zu steps "
      "(%.1f %%), mean NEES %.1f; without the floor %zu of %zu; widened as degenerate %zu, of "
      "the others %zu of %zu within\n",
      int(first_seed), int(last_seed), h.within, h.steps, 100.0 * h.within / h.steps, h.nees_mean,
      h.within_without_floor, h.steps, h.widened, h.unwidened_within, h.steps - h.widened);
  return h;
}

}  // namespace rigcal::lidar
