#pragma once
// The pose graph's GNSS term (doc/ground-truth.md): the antenna, at its lever arm on the rig,
// against the fix interpolated at the scan's time, weighted by the fix's information.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rigcal::gt {

struct PositionPriorError {
  Eigen::Vector3d p_enu_fix;
  Eigen::Vector3d p_lidar_antenna;   // the lever arm, in the LiDAR frame
  Eigen::Matrix3d sqrt_information;  // U with U' U the inverse of the fix's covariance

  template <class T>
  bool operator()(const T* q_enu_lidar, const T* t_enu_lidar, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_enu_lidar);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(t_enu_lidar);
    const Eigen::Matrix<T, 3, 1> p_enu_antenna = q * p_lidar_antenna.cast<T>() + t;
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residual);
    r = sqrt_information.cast<T>() * (p_enu_antenna - p_enu_fix.cast<T>());
    return true;
  }
};

}  // namespace rigcal::gt
