#pragma once
// The per-step covariances of the LiDAR odometry (doc/odometry.md), as text: '#' comments, then
// one line a step, "t_prev t_cur" (seconds, 9 decimals) and the 21 entries of the upper
// triangle of the 6 x 6 covariance of T_prev_cur, row by row, in rigcal's tangent (rotation
// x y z in rad first, then translation x y z in m; left perturbation in the previous sensor
// frame), numbers in shortest round-trip form.
#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "rigcal/core/time.h"

namespace rigcal::io {

struct StepCovariance {
  Time prev, cur;
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
};

std::string step_covariances_to_text(const std::vector<StepCovariance>& steps);
// Where a trajectory's step covariances go and are looked for by default: the trajectory's path
// without its extension, + "_covariances.txt" (what `rigcal odometry` writes beside OUT).
std::filesystem::path step_covariances_beside(const std::filesystem::path& trajectory);
// Throws rigcal::Error naming the file and line on bad input (a count other than 23, a number
// not read, a matrix not symmetric positive semi-definite on its diagonal).
std::vector<StepCovariance> read_step_covariances(const std::filesystem::path& path);

}  // namespace rigcal::io
