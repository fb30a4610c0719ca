#pragma once
// Simulated IMU streams (doc/simulator.md): gyroscope and accelerometer of an IMU rigidly mounted
// on the rig (T_base_imu), from an analytic motion, with white noise and bias random walks
// (Kalibr's continuous-time densities), on the sensor's own clock (offset and linear drift),
// with optional stamp jitter and gaps.
#include <random>
#include <utility>
#include <vector>

#include "rigcal/core/time.h"
#include "rigcal/rig/rig.h"
#include "rigcal/sim/motion.h"

namespace rigcal::sim {

struct ImuSample {
  Time stamp;             // the sensor's clock
  Eigen::Vector3d gyro;   // rad/s, IMU frame
  Eigen::Vector3d accel;  // specific force, m/s^2, IMU frame
};

struct ImuSimConfig {
  double rate_hz = 100.0;
  double jitter_s = 0.0;  // std of the stamp jitter
  // The sensor's clock: t_base = t_stamp + time_offset + drift_ppm * 1e-6 * (t_stamp - t_first).
  double time_offset_s = 0.0;
  double drift_ppm = 0.0;
  std::vector<std::pair<double, double>> gaps;  // [from, to) s of motion time with no samples
  // Noise where the rig gives none (Kalibr units). Initial biases: N(0, bias_sigma).
  double gyro_noise_density = 1.6e-4, gyro_random_walk = 2e-5;
  double accel_noise_density = 1.4e-3, accel_random_walk = 1.2e-4;
  double gyro_bias_sigma = 2e-3, accel_bias_sigma = 2e-2;
  bool noise = true;
};

// Samples whose base-clock time falls in [base_start, base_start + duration]; the motion's time 0
// is base_start.
std::vector<ImuSample> simulate_imu(const Motion& motion, const SE3& T_base_imu,
                                    const rig::ImuSpec& noise, const ImuSimConfig& config,
                                    Time base_start, double duration, std::mt19937_64& rng);

// The exact angular velocity and specific force of an IMU at motion time t (no noise, no bias).
std::pair<Eigen::Vector3d, Eigen::Vector3d> ideal_imu(const Motion& motion, const SE3& T_base_imu,
                                                      double t);

}  // namespace rigcal::sim
