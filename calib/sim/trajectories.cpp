#include "rigcal/sim/trajectories.h"

#include <algorithm>
#include <cmath>

#include "rigcal/core/error.h"
#include "rigcal/core/trajectory.h"

namespace rigcal::sim {

PoseSource pose_source(const Motion& motion) {
  return [motion](double t) { return evaluate(motion, t).T_world_base; };
}

std::pair<PoseSource, double> pose_source(const Trajectory& replay) {
  if (replay.size() < 2 || !replay.has_stamps)
    throw Error("replaying needs a stamped trajectory of 2 poses or more");
  const Trajectory* traj = &replay;
  const double duration = (replay.stamps.back() - replay.stamps.front()).seconds();
  PoseSource source = [traj](double t) {
    const Time at = traj->stamps.front() + Time::from_seconds(t);
    auto it = std::lower_bound(traj->stamps.begin(), traj->stamps.end(), at);
    if (it == traj->stamps.begin()) return traj->T_world_body.front();
    if (it == traj->stamps.end()) return traj->T_world_body.back();
    const size_t j = it - traj->stamps.begin();
    const double f = static_cast<double>((at - traj->stamps[j - 1]).ns) /
                     static_cast<double>((traj->stamps[j] - traj->stamps[j - 1]).ns);
    return interpolate(traj->T_world_body[j - 1], traj->T_world_body[j], f);
  };
  return {source, duration};
}

Trajectory sample_poses(const PoseSource& source, double rate_hz, double duration,
                        Time base_start) {
  Trajectory out;
  const long n = static_cast<long>(std::floor(duration * rate_hz + 1e-9)) + 1;
  for (long k = 0; k < n; ++k) {
    const double t = k / rate_hz;
    out.stamps.push_back(base_start + Time::from_seconds(t));
    out.T_world_body.push_back(source(t));
  }
  return out;
}

Trajectory simulate_odometry(const Trajectory& truth, const OdometryNoise& noise,
                             std::mt19937_64& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  Trajectory out;
  out.stamps = truth.stamps;
  SE3 T_odom_base;
  for (size_t k = 0; k < truth.size(); ++k) {
    if (k > 0) {
      SE3 step = truth.T_world_body[k - 1].inverse() * truth.T_world_body[k];
      step.t *= 1.0 + noise.scale_error;
      step.t += noise.trans_sigma_m * Eigen::Vector3d(N(rng), N(rng), N(rng));
      step.R = step.R * rotation_from_vector(noise.rot_sigma_deg * M_PI / 180.0 *
                                             Eigen::Vector3d(N(rng), N(rng), N(rng)));
      T_odom_base = T_odom_base * step;
    }
    out.T_world_body.push_back(T_odom_base);
  }
  return out;
}

FixState fix_state_at(const GnssNoise& noise, double t) {
  auto within = [t](const std::vector<std::pair<double, double>>& spans) {
    for (const auto& [from, to] : spans)
      if (t >= from && t < to) return true;
    return false;
  };
  if (within(noise.single_spans)) return FixState::single;
  if (within(noise.float_spans)) return FixState::rtk_float;
  return FixState::rtk_fixed;
}

std::pair<double, double> fix_sigmas(const GnssNoise& noise, FixState state) {
  switch (state) {
    case FixState::rtk_float:
      return {noise.float_horizontal_sigma_m, noise.float_vertical_sigma_m};
    case FixState::single:
      return {noise.single_horizontal_sigma_m, noise.single_vertical_sigma_m};
    case FixState::rtk_fixed:
      break;
  }
  return {noise.horizontal_sigma_m, noise.vertical_sigma_m};
}

Trajectory simulate_gnss(const PoseSource& source, double duration, Time base_start,
                         const SE3& T_base_gnss, const SE3& T_enu_world, const GnssNoise& noise,
                         std::mt19937_64& rng, std::vector<size_t>* outliers,
                         std::vector<FixState>* states) {
  std::normal_distribution<double> N(0.0, 1.0);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  Trajectory out;
  const double first_stamp = base_start.seconds() - noise.time_offset_s;
  const double a = noise.correlation_time_s > 0
                       ? std::exp(-1.0 / (noise.rate_hz * noise.correlation_time_s))
                       : 0.0;
  Eigen::Vector3d n_state = Eigen::Vector3d::Zero(), r_state = Eigen::Vector3d::Zero();
  bool first = true;
  for (long k = 0;; ++k) {
    const double stamp = first_stamp + k / noise.rate_hz;
    const double t = stamp + noise.time_offset_s - base_start.seconds();
    if (t > duration) break;
    if (t < 0) continue;
    bool outage = false;
    for (const auto& [from, to] : noise.outages) outage = outage || (t >= from && t < to);
    const bool outlier = U(rng) < noise.outlier_probability;
    const Eigen::Vector3d w3(N(rng), N(rng), N(rng)), v3(N(rng), N(rng), N(rng));
    const double b = first ? 1.0 : std::sqrt(1.0 - a * a);
    n_state = (first ? 0.0 : a) * n_state + b * w3;
    r_state = (first ? 0.0 : a) * r_state + b * v3;
    first = false;
    const Eigen::Vector3d &n3 = n_state, &r3 = r_state;
    const Eigen::Vector3d jump(N(rng), N(rng), 0.3 * N(rng));
    if (outage) continue;
    SE3 T_enu_gnss = T_enu_world * source(t) * T_base_gnss;
    const FixState state = fix_state_at(noise, t);
    const auto [sigma_h, sigma_v] = fix_sigmas(noise, state);
    T_enu_gnss.t += Eigen::Vector3d(sigma_h * n3.x(), sigma_h * n3.y(), sigma_v * n3.z());
    T_enu_gnss.R = T_enu_gnss.R * rotation_from_vector(noise.rot_sigma_deg * M_PI / 180.0 * r3);
    if (outlier) {
      T_enu_gnss.t += noise.outlier_jump_m * jump.normalized() * (0.5 + U(rng));
      if (outliers) outliers->push_back(out.size());
    }
    out.stamps.push_back(Time::from_seconds(stamp));
    out.T_world_body.push_back(T_enu_gnss);
    if (states) states->push_back(state);
  }
  return out;
}

}  // namespace rigcal::sim
