#include "rigcal/lidar_camera/board_camera.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "rigcal/camera/lens.h"
#include "rigcal/core/error.h"

namespace rigcal::lidar_camera {

Eigen::Matrix<double, 3, 2> tangent(const Eigen::Vector3d& n) {
  const Eigen::Vector3d a =
      std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  Eigen::Matrix<double, 3, 2> B;
  B.col(0) = n.cross(a).normalized();
  B.col(1) = n.cross(B.col(0));
  return B;
}

namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;

// Reprojection residuals (pixels, 2 per corner); a point behind the camera gets a large residual.
Eigen::VectorXd residuals(const rig::CameraModel& camera, const SE3& T,
                          const std::vector<Eigen::Vector3d>& object,
                          const std::vector<Eigen::Vector2d>& corners) {
  Eigen::VectorXd r(2 * object.size());
  for (size_t i = 0; i < object.size(); ++i) {
    const auto px = camera::project(camera, T * object[i]);
    r.segment<2>(2 * i) = px ? Eigen::Vector2d(*px - corners[i]) : Eigen::Vector2d(1e3, 1e3);
  }
  return r;
}

Eigen::MatrixXd jacobian(const rig::CameraModel& camera, const SE3& T,
                         const std::vector<Eigen::Vector3d>& object,
                         const std::vector<Eigen::Vector2d>& corners) {
  Eigen::MatrixXd J(2 * object.size(), 6);
  const double h = 1e-7;
  for (int c = 0; c < 6; ++c) {
    Vec6 d = Vec6::Zero();
    d[c] = h;
    J.col(c) = (residuals(camera, perturbed(T, d), object, corners) -
                residuals(camera, perturbed(T, -d), object, corners)) /
               (2 * h);
  }
  return J;
}

}  // namespace

CameraBoard board_in_camera(const rig::CameraModel& camera, const camera::Target& target,
                            const std::vector<Eigen::Vector2d>& corners, double corner_sigma_px) {
  const std::vector<Eigen::Vector3d> object = camera::object_points(target);
  if (corners.size() != object.size() || corners.size() < 4) {
    throw Error(fmt::format("{} corners for a target of {}: a full board is needed", corners.size(),
                            object.size()));
  }
  // PnP on undistorted normalized coordinates (identity K): any lens model.
  std::vector<cv::Point3d> obj;
  std::vector<cv::Point2d> img;
  for (size_t i = 0; i < object.size(); ++i) {
    obj.emplace_back(object[i].x(), object[i].y(), object[i].z());
    const Eigen::Vector2d xn = camera::unproject(camera, corners[i]);
    img.emplace_back(xn.x(), xn.y());
  }
  cv::Mat rvec, tvec;
  if (!cv::solvePnP(obj, img, cv::Mat::eye(3, 3, CV_64F), cv::Mat(), rvec, tvec, false,
                    cv::SOLVEPNP_IPPE)) {
    throw Error("PnP failed on the board's corners");
  }
  Eigen::Vector3d rv, tv;
  cv::cv2eigen(rvec, rv);
  cv::cv2eigen(tvec, tv);
  SE3 T{rotation_from_vector(rv), tv};
  // Gauss-Newton in pixels through the lens.
  for (int it = 0; it < 20; ++it) {
    const Eigen::VectorXd r = residuals(camera, T, object, corners);
    const Eigen::MatrixXd J = jacobian(camera, T, object, corners);
    const Vec6 step = (J.transpose() * J).ldlt().solve(-J.transpose() * r);
    T = perturbed(T, step);
    if (step.norm() < 1e-12) break;
  }
  CameraBoard out;
  out.T_camera_board = T;
  const Eigen::VectorXd r = residuals(camera, T, object, corners);
  out.rms_px = std::sqrt(r.squaredNorm() / static_cast<double>(r.size()));
  const double dof = std::max(1.0, static_cast<double>(r.size()) - 6.0);
  const double sigma = std::max(corner_sigma_px, std::sqrt(r.squaredNorm() / dof));
  const Eigen::MatrixXd J = jacobian(camera, T, object, corners);
  out.covariance = sigma * sigma * (J.transpose() * J).inverse();
  // The plane: n = R e_z (towards the camera flipped so that d >= 0), d = n . t.
  Eigen::Vector3d n = T.R.col(2);
  double d = n.dot(T.t);
  if (d < 0) n = -n, d = -d;
  out.plane.n = n;
  out.plane.d = d;
  // Its covariance from the pose's: n' = exp(dθ) n, d' = n' . (t + dt).
  const Eigen::Matrix<double, 3, 2> B = tangent(n);
  Eigen::Matrix<double, 3, 6> Jp = Eigen::Matrix<double, 3, 6>::Zero();
  Jp.block<2, 3>(0, 0) = -B.transpose() * skew(n);  // d n = dθ x n = -[n]x dθ
  Jp.block<1, 3>(2, 0) = -(T.t.transpose() * skew(n));
  Jp.block<1, 3>(2, 3) = n.transpose();
  out.plane.covariance = Jp * out.covariance * Jp.transpose();
  const camera::Outline o = camera::outline(target);
  for (const auto& [x, y] : {std::pair{o.x_min, o.y_min}, std::pair{o.x_max, o.y_min},
                             std::pair{o.x_max, o.y_max}, std::pair{o.x_min, o.y_max}})
    out.outline_camera.push_back(T * Eigen::Vector3d(x, y, 0.0));
  return out;
}

}  // namespace rigcal::lidar_camera
