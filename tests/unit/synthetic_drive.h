#pragma once
// A long synthetic drive and an estimate of it, for the benchmark's tests and its benchmarks
// (tests/perf/bench_trajectory.cpp writes it to files for the peers): 10 m/s sampled at `hz`,
// the estimate 0.1 % off in heading, 0.2 % in scale, with 2 cm noise, on stamps 1 ms later, the
// first stamp at `epoch_s`. Deterministic: the same poses on every run of one build.
#include <cmath>
#include <random>
#include <utility>

#include "rigcal/core/trajectory.h"

namespace rigcal::testing {

inline std::pair<Trajectory, Trajectory> synthetic_drive(size_t n, double hz = 10,
                                                         int64_t epoch_s = 0) {
  const int64_t period_ns = static_cast<int64_t>(std::llround(1e9 / hz));
  const double step_m = 10.0 / hz;
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, 0.02);
  Trajectory gt, est;
  gt.stamps.reserve(n), gt.T_world_body.reserve(n), est.stamps.reserve(n),
      est.T_world_body.reserve(n);
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  double yaw = 0.0;
  for (size_t i = 0; i < n; ++i) {
    yaw += 0.02 * std::sin(1e-3 * static_cast<double>(i));
    p += step_m * Eigen::Vector3d(std::cos(yaw), std::sin(yaw),
                                  0.01 * std::sin(1e-2 * static_cast<double>(i)));
    const SE3 T = SE3::from_rotation_vector(Eigen::Vector3d(0, 0, yaw), p);
    const int64_t t_ns = epoch_s * 1'000'000'000 + static_cast<int64_t>(i) * period_ns;
    gt.stamps.push_back(Time::from_ns(t_ns));
    gt.T_world_body.push_back(T);
    est.stamps.push_back(Time::from_ns(t_ns + 1'000'000));
    est.T_world_body.push_back(
        SE3::from_rotation_vector(Eigen::Vector3d(0, 0, yaw * 1.001),
                                  p * 1.002 + Eigen::Vector3d(noise(rng), noise(rng), noise(rng))));
  }
  return {gt, est};
}

}  // namespace rigcal::testing
