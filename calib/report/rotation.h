#pragma once
// Rotations as a person reads them: the angle about one axis, never roll/pitch/yaw (which lose an
// axis at gimbal lock: a camera looking along a LiDAR's x is at pitch 90 deg), and their 1-sigmas
// as what they are, small rotations about a named frame's axes.
#include <fmt/format.h>

#include <Eigen/Core>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <utility>

#include "rigcal/core/se3.h"

namespace rigcal::report {

// The angle (deg) and unit axis of R = Exp(angle * axis); the axis is zero at angle 0.
inline std::pair<double, Eigen::Vector3d> angle_axis_deg(const Eigen::Matrix3d& R) {
  const Eigen::Vector3d phi = rotation_vector(R);
  const double angle = phi.norm();
  return {angle * 180.0 / M_PI,
          angle > 0 ? Eigen::Vector3d(phi / angle) : Eigen::Vector3d(Eigen::Vector3d::Zero())};
}

// {"angle_deg": a, "axis": [x, y, z]}, as angle_axis_deg.
inline nlohmann::json axis_angle_json(const Eigen::Matrix3d& R) {
  const auto [angle_deg, axis] = angle_axis_deg(R);
  return {{"angle_deg", angle_deg}, {"axis", {axis.x(), axis.y(), axis.z()}}};
}

// "rotation 119.998 deg about [0.5774 -0.5774 0.5774], 1-sigma 0.012 0.010 0.015 deg about
// cam_r's x y z": `sigma_deg` the left-tangent sigmas (R = Exp(d) R_estimate, d about `frame`'s
// axes).
inline std::string rotation_text(const Eigen::Matrix3d& R, const Eigen::Vector3d& sigma_deg,
                                 std::string_view frame) {
  const auto [angle_deg, axis] = angle_axis_deg(R);
  return fmt::format(
      "rotation {:.4f} deg about [{:.4f} {:.4f} {:.4f}], 1-sigma {:.4f} {:.4f} {:.4f} deg about "
      "{}'s x y z",
      angle_deg, axis.x(), axis.y(), axis.z(), sigma_deg.x(), sigma_deg.y(), sigma_deg.z(), frame);
}

}  // namespace rigcal::report
