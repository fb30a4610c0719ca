#include "rigcal/core/trajectory.h"

#include <algorithm>

namespace rigcal {

double path_length(const Trajectory& trajectory) {
  double length = 0.0;
  for (size_t i = 1; i < trajectory.size(); ++i) {
    length += (trajectory.T_world_body[i].t - trajectory.T_world_body[i - 1].t).norm();
  }
  return length;
}

SE3 interpolate(const SE3& T_a, const SE3& T_b, double fraction) {
  const Eigen::Quaterniond q = T_a.quaternion().slerp(fraction, T_b.quaternion());
  return SE3::from_quaternion(q, (1.0 - fraction) * T_a.t + fraction * T_b.t);
}

std::optional<SE3> pose_at(const Trajectory& traj, Time t, Time max_gap) {
  const auto it = std::lower_bound(traj.stamps.begin(), traj.stamps.end(), t);
  if (it == traj.stamps.end()) return std::nullopt;
  const size_t j = static_cast<size_t>(it - traj.stamps.begin());
  if (*it == t) return traj.T_world_body[j];
  if (j == 0) return std::nullopt;
  const Time a = traj.stamps[j - 1], b = traj.stamps[j];
  if (b - a > max_gap) return std::nullopt;
  return interpolate(traj.T_world_body[j - 1], traj.T_world_body[j],
                     (t - a).seconds() / (b - a).seconds());
}

}  // namespace rigcal
