#include "rigcal/camera/lens.h"

#include <Eigen/LU>
#include <cmath>

namespace rigcal::camera {

std::vector<double> intrinsics_vector(const rig::CameraModel& c) {
  std::vector<double> k = {c.fx, c.fy, c.cx, c.cy};
  k.insert(k.end(), c.distortion_coeffs.begin(), c.distortion_coeffs.end());
  return k;
}

Eigen::Vector2d distort(const rig::CameraModel& c, const Eigen::Vector2d& xn) {
  const std::vector<double>& k = c.distortion_coeffs;
  const double x = xn.x(), y = xn.y();
  const double r2 = x * x + y * y;
  if (c.distortion_model == rig::DistortionModel::radtan) {
    const double k3 = k.size() > 4 ? k[4] : 0.0;
    const double radial = 1.0 + r2 * (k[0] + r2 * (k[1] + r2 * k3));
    return {x * radial + 2.0 * k[2] * x * y + k[3] * (r2 + 2.0 * x * x),
            y * radial + k[2] * (r2 + 2.0 * y * y) + 2.0 * k[3] * x * y};
  }
  const double r = std::sqrt(r2);
  if (r < 1e-12) return xn;
  const double theta = std::atan(r);
  const double t2 = theta * theta;
  const double theta_d = theta * (1.0 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3]))));
  return xn * (theta_d / r);
}

Eigen::Vector2d undistort(const rig::CameraModel& c, const Eigen::Vector2d& xd) {
  Eigen::Vector2d x = xd;
  for (int iter = 0; iter < 20; ++iter) {
    const Eigen::Vector2d f = distort(c, x) - xd;
    if (f.norm() < 1e-14) break;
    constexpr double h = 1e-7;
    Eigen::Matrix2d J;
    J.col(0) =
        (distort(c, x + Eigen::Vector2d(h, 0)) - distort(c, x - Eigen::Vector2d(h, 0))) / (2 * h);
    J.col(1) =
        (distort(c, x + Eigen::Vector2d(0, h)) - distort(c, x - Eigen::Vector2d(0, h))) / (2 * h);
    x -= J.inverse() * f;
  }
  return x;
}

std::optional<Eigen::Vector2d> project(const rig::CameraModel& c, const Eigen::Vector3d& p) {
  if (!(p.z() > 0)) return std::nullopt;
  const Eigen::Vector2d d = distort(c, p.head<2>() / p.z());
  return Eigen::Vector2d(c.fx * d.x() + c.cx, c.fy * d.y() + c.cy);
}

Eigen::Vector2d unproject(const rig::CameraModel& c, const Eigen::Vector2d& pixel) {
  return undistort(c, Eigen::Vector2d((pixel.x() - c.cx) / c.fx, (pixel.y() - c.cy) / c.fy));
}

}  // namespace rigcal::camera
