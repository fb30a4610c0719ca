#pragma once
// The board seen by the camera (issue 8; doc/lidar-camera.md): its pose by PnP on the detected
// corners through the calibrated lens, refined in pixels, and its plane with a covariance from
// the corner noise.
#include <Eigen/Core>
#include <vector>

#include "rigcal/camera/target.h"
#include "rigcal/core/se3.h"
#include "rigcal/rig/rig.h"

namespace rigcal::lidar_camera {

// A plane n . x = d in a sensor's frame: n unit, d >= 0 (n points from the sensor towards it).
struct Plane {
  Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  double d = 0.0;
  // Covariance of (two tangent angles of n, rad; d, m): n perturbed as n + a u + b v, (u, v) the
  // basis of tangent(n).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

// An orthonormal basis (u, v) of the plane orthogonal to n, as the columns of a 3 x 2 matrix.
Eigen::Matrix<double, 3, 2> tangent(const Eigen::Vector3d& n);

struct CameraBoard {
  SE3 T_camera_board;
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();  // rot, t
  Plane plane;                                  // the board's front face, camera frame
  double rms_px = 0.0;                          // reprojection RMS per coordinate
  std::vector<Eigen::Vector3d> outline_camera;  // the physical board's 4 corners, camera frame
};

// Throws rigcal::Error with fewer than 4 corners or when PnP fails. `corner_sigma_px`: the
// corner noise for the covariance (the larger of it and the residual RMS is used).
CameraBoard board_in_camera(const rig::CameraModel& camera, const camera::Target& target,
                            const std::vector<Eigen::Vector2d>& corners,
                            double corner_sigma_px = 0.1);

}  // namespace rigcal::lidar_camera
