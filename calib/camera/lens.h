#pragma once
// The lens models of rigcal::rig::CameraModel, as OpenCV defines them (doc/conventions.md):
//   radtan       x' = x (1 + k1 r² + k2 r⁴ + k3 r⁶) + 2 p1 x y + p2 (r² + 2 x²), y' likewise
//   equidistant  θ = atan(r), θd = θ (1 + k1 θ² + k2 θ⁴ + k3 θ⁶ + k4 θ⁸), x' = (θd / r) x
// then u = fx x' + cx, v = fy y' + cy, pixel (0, 0) the centre of the top-left pixel.
#include <optional>
#include <vector>

#include "rigcal/rig/rig.h"

namespace rigcal::camera {

// Normalized pinhole coordinates (x/z, y/z) to distorted normalized coordinates.
Eigen::Vector2d distort(const rig::CameraModel& camera, const Eigen::Vector2d& xn);
// The inverse of distort by Gauss-Newton; converges inside the lens's valid field of view.
Eigen::Vector2d undistort(const rig::CameraModel& camera, const Eigen::Vector2d& xd);
// Pixel of a point in the camera frame; nullopt behind the camera (z <= 0).
std::optional<Eigen::Vector2d> project(const rig::CameraModel& camera,
                                       const Eigen::Vector3d& p_cam);
// Normalized pinhole coordinates of a pixel (the ray through it is (x, y, 1)).
Eigen::Vector2d unproject(const rig::CameraModel& camera, const Eigen::Vector2d& pixel);
// The intrinsics vector [fx fy cx cy k...] of a model, in the order of its distortion model.
std::vector<double> intrinsics_vector(const rig::CameraModel& camera);

}  // namespace rigcal::camera
