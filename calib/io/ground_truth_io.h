#pragma once
// The ground truth's files (doc/ground-truth.md): the trajectory in VBR's ground-truth format
// (TUM with the header `#timestamp tx ty tz qx qy qz qw`, the LiDAR frame) and each pose's
// standard deviations.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "rigcal/core/trajectory.h"

namespace rigcal::io {

// VBR's <seq>_gt.txt: the header line, then one pose a line, stamps in seconds to the nanosecond.
std::string ground_truth_to_text(const Trajectory& T_world_lidar);

// One line a pose: the stamp, then the standard deviations of the position (x y z, m) and of
// the rotation (about x y z, deg) in the world frame, from each 6 x 6 covariance (rigcal's
// tangent: rotation first, left perturbation), after a header line naming the columns.
std::string pose_sigmas_to_text(const Trajectory& T_world_lidar,
                                const std::vector<Eigen::Matrix<double, 6, 6>>& covariance);

}  // namespace rigcal::io
