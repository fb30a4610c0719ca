#pragma once
// The pose graph's GNSS/INS attitude term (doc/ground-truth.md): the LiDAR's rotation against the
// attitude the INS measured at the scan's time (through the rig's rotation between the two),
// weighted by the attitude's information. The residual is the rotation vector of
// q_enu_lidar * q_measured^-1, in the ENU frame (tilt about east and north, heading about up).
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rigcal::gt {

struct AttitudePriorError {
  Eigen::Quaterniond q_enu_lidar_measured;
  Eigen::Matrix3d sqrt_information;  // U with U' U the inverse of the attitude's covariance

  template <class T>
  bool operator()(const T* q_enu_lidar, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_enu_lidar);
    Eigen::Quaternion<T> q_error = q * q_enu_lidar_measured.conjugate().cast<T>();
    if (q_error.w() < T(0)) q_error.coeffs() = -q_error.coeffs();  // the shorter way round
    const T wxyz[4] = {q_error.w(), q_error.x(), q_error.y(), q_error.z()};
    Eigen::Matrix<T, 3, 1> e;
    ceres::QuaternionToAngleAxis(wxyz, e.data());
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residual);
    r = sqrt_information.cast<T>() * e;
    return true;
  }
};

}  // namespace rigcal::gt
