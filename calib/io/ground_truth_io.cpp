#include "rigcal/io/ground_truth_io.h"

#include <fmt/format.h>

#include <cmath>

#include "rigcal/core/error.h"
#include "rigcal/core/time.h"
#include "rigcal/io/trajectory_io.h"

namespace rigcal::io {

std::string ground_truth_to_text(const Trajectory& T_world_lidar) {
  return "#timestamp tx ty tz qx qy qz qw\n" + trajectory_to_tum(T_world_lidar);
}

std::string pose_sigmas_to_text(const Trajectory& T_world_lidar,
                                const std::vector<Eigen::Matrix<double, 6, 6>>& covariance) {
  if (covariance.size() != T_world_lidar.size()) {
    throw Error(
        fmt::format("{} covariances for {} poses", covariance.size(), T_world_lidar.size()));
  }
  std::string out =
      "#timestamp sigma_x_m sigma_y_m sigma_z_m sigma_rx_deg sigma_ry_deg sigma_rz_deg\n";
  out.reserve(out.size() + T_world_lidar.size() * 90);
  const double deg = 180.0 / M_PI;
  for (size_t k = 0; k < T_world_lidar.size(); ++k) {
    const Eigen::Matrix<double, 6, 1> s = covariance[k].diagonal().cwiseMax(0.0).cwiseSqrt();
    out += fmt::format("{} {:.6g} {:.6g} {:.6g} {:.6g} {:.6g} {:.6g}\n",
                       to_seconds_text(T_world_lidar.stamps[k]), s(3), s(4), s(5), deg * s(0),
                       deg * s(1), deg * s(2));
  }
  return out;
}

}  // namespace rigcal::io
