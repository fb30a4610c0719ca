#pragma once
// The GNSS fixes' correlated error as a state of the pose graph (doc/ground-truth.md, "Correlated
// fixes"): at every scan a 3-vector u, the fix's error in units of the fix's own sigmas, that
// follows a first-order Gauss-Markov process from scan to scan. A fix's error is then
// L u + w: L the correlated part of the fix's covariance (its Cholesky factor), w white.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace rigcal::gt {

// The antenna against the fix less its correlated error.
struct CorrelatedPositionPriorError {
  Eigen::Vector3d p_enu_fix;
  Eigen::Vector3d p_lidar_antenna;   // the lever arm, in the LiDAR frame
  Eigen::Matrix3d L_correlated;      // the correlated error is L_correlated u
  Eigen::Matrix3d sqrt_information;  // of the white part: U with U' U its inverse covariance

  template <class T>
  bool operator()(const T* q_enu_lidar, const T* t_enu_lidar, const T* u_fix, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_enu_lidar);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(t_enu_lidar), u(u_fix);
    const Eigen::Matrix<T, 3, 1> p_enu_antenna = q * p_lidar_antenna.cast<T>() + t;
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residual);
    r = sqrt_information.cast<T>() *
        (p_enu_antenna - p_enu_fix.cast<T>() - L_correlated.cast<T>() * u);
    return true;
  }
};

// One step of the process: u1 = a u0 + sqrt(1 - a^2) n, n ~ N(0, I), a = exp(-dt / tau), so
// that u keeps unit variance. The first state's own term is u0 ~ N(0, I) (`FixErrorStartError`).
struct FixErrorStepError {
  double a = 0.0;

  FixErrorStepError(double dt_s, double tau_s) : a(tau_s > 0 ? std::exp(-dt_s / tau_s) : 0.0) {}

  template <class T>
  bool operator()(const T* u0, const T* u1, T* residual) const {
    const double scale = 1.0 / std::sqrt(std::max(1.0 - a * a, 1e-12));
    for (int i = 0; i < 3; ++i) residual[i] = (u1[i] - a * u0[i]) * scale;
    return true;
  }
};

struct FixErrorStartError {
  template <class T>
  bool operator()(const T* u0, T* residual) const {
    for (int i = 0; i < 3; ++i) residual[i] = u0[i];
    return true;
  }
};

}  // namespace rigcal::gt
