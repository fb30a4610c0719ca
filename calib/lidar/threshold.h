#pragma once
// The adaptive correspondence threshold of KISS-ICP (Vizzo et al. 2023, sec. III-C): the
// deviation of each registration from its prediction, a point at max_range moved by it, gives
// sigma = sqrt(mean deviation^2) over the frames that moved more than min_motion; the ICP takes
// correspondences within 3 sigma and a kernel of scale sigma / 3. Before any such frame: the
// initial threshold.
#include "rigcal/core/se3.h"

namespace rigcal::lidar {

struct AdaptiveThreshold {
  double initial_m = 2.0, min_motion_m = 0.1, max_range_m = 100.0;
  double sum_squared = 0;
  size_t frames = 0;
};

double sigma_m(const AdaptiveThreshold& threshold);
// T_predicted_estimated: the estimate in the predicted pose's frame.
void update(AdaptiveThreshold& threshold, const SE3& T_predicted_estimated);

}  // namespace rigcal::lidar
