#include "rigcal/sim/imu.h"

#include <cmath>

namespace rigcal::sim {

std::pair<Eigen::Vector3d, Eigen::Vector3d> ideal_imu(const Motion& motion, const SE3& T_base_imu,
                                                      double t) {
  const MotionState s = evaluate(motion, t);
  const Eigen::Matrix3d& R_wb = s.T_world_base.R;
  const Eigen::Vector3d& r = T_base_imu.t;  // lever arm in the base frame
  const Eigen::Vector3d a_imu_world =
      s.a_world + R_wb * (s.alpha_base.cross(r) + s.omega_base.cross(s.omega_base.cross(r)));
  const Eigen::Matrix3d R_world_imu = R_wb * T_base_imu.R;
  return {T_base_imu.R.transpose() * s.omega_base,
          R_world_imu.transpose() * (a_imu_world - kGravityWorld)};
}

std::vector<ImuSample> simulate_imu(const Motion& motion, const SE3& T_base_imu,
                                    const rig::ImuSpec& spec, const ImuSimConfig& cfg,
                                    Time base_start, double duration, std::mt19937_64& rng) {
  const double gn = spec.gyroscope_noise_density.value_or(cfg.gyro_noise_density);
  const double gw = spec.gyroscope_random_walk.value_or(cfg.gyro_random_walk);
  const double an = spec.accelerometer_noise_density.value_or(cfg.accel_noise_density);
  const double aw = spec.accelerometer_random_walk.value_or(cfg.accel_random_walk);
  std::normal_distribution<double> N(0.0, 1.0);
  auto randn3 = [&] { return Eigen::Vector3d(N(rng), N(rng), N(rng)); };
  Eigen::Vector3d bg =
      cfg.noise ? Eigen::Vector3d(cfg.gyro_bias_sigma * randn3()) : Eigen::Vector3d::Zero();
  Eigen::Vector3d ba =
      cfg.noise ? Eigen::Vector3d(cfg.accel_bias_sigma * randn3()) : Eigen::Vector3d::Zero();

  const double dt = 1.0 / cfg.rate_hz;
  // The first stamp on the sensor's clock: base time base_start, minus the offset.
  const double first_stamp = base_start.seconds() - cfg.time_offset_s;
  std::vector<ImuSample> out;
  out.reserve(static_cast<size_t>(duration * cfg.rate_hz) + 2);
  double previous_t = -1.0;
  for (long k = 0;; ++k) {
    double stamp = first_stamp + k * dt;
    if (cfg.jitter_s > 0) stamp += cfg.jitter_s * N(rng);
    const double t_base = stamp + cfg.time_offset_s + cfg.drift_ppm * 1e-6 * (stamp - first_stamp);
    const double t = t_base - base_start.seconds();
    if (t > duration) break;
    if (t < 0) continue;
    bool in_gap = false;
    for (const auto& [from, to] : cfg.gaps) in_gap = in_gap || (t >= from && t < to);
    // Bias random walk over the real time since the previous sample.
    const double step = previous_t < 0 ? dt : t - previous_t;
    previous_t = t;
    if (cfg.noise) {
      bg += gw * std::sqrt(step) * randn3();
      ba += aw * std::sqrt(step) * randn3();
    }
    if (in_gap) continue;
    auto [w, f] = ideal_imu(motion, T_base_imu, t);
    if (cfg.noise) {
      w += bg + gn / std::sqrt(dt) * randn3();
      f += ba + an / std::sqrt(dt) * randn3();
    }
    out.push_back({Time::from_seconds(stamp), w, f});
  }
  return out;
}

}  // namespace rigcal::sim
