#include "rigcal/lidar/threshold.h"

#include <cmath>

namespace rigcal::lidar {

double sigma_m(const AdaptiveThreshold& threshold) {
  return threshold.frames == 0
             ? threshold.initial_m
             : std::sqrt(threshold.sum_squared / static_cast<double>(threshold.frames));
}

void update(AdaptiveThreshold& threshold, const SE3& T_predicted_estimated) {
  const double angle = rotation_angle(T_predicted_estimated.R);
  const double deviation =
      T_predicted_estimated.t.norm() + 2.0 * threshold.max_range_m * std::sin(angle / 2.0);
  if (deviation > threshold.min_motion_m) {
    threshold.sum_squared += deviation * deviation;
    ++threshold.frames;
  }
}

}  // namespace rigcal::lidar
