#include "rigcal/core/se3.h"

#include <fmt/format.h>

#include <Eigen/SVD>
#include <cmath>

#include "rigcal/core/error.h"
#include "rigcal/core/text.h"

namespace rigcal {

SE3 SE3::from_matrix(const Eigen::Matrix4d& m) {
  SE3 T;
  T.R = m.topLeftCorner<3, 3>();
  T.t = m.topRightCorner<3, 1>();
  return T;
}

SE3 SE3::from_quaternion(const Eigen::Quaterniond& q_a_b, const Eigen::Vector3d& t_a_b) {
  SE3 T;
  T.R = q_a_b.normalized().toRotationMatrix();
  T.t = t_a_b;
  return T;
}

SE3 SE3::from_rotation_vector(const Eigen::Vector3d& phi, const Eigen::Vector3d& t_a_b) {
  SE3 T;
  T.R = rotation_from_vector(phi);
  T.t = t_a_b;
  return T;
}

Eigen::Matrix4d SE3::matrix() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = R;
  m.topRightCorner<3, 1>() = t;
  return m;
}

Eigen::Quaterniond SE3::quaternion() const {
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0) q.coeffs() *= -1.0;
  return q;
}

SE3 SE3::inverse() const {
  SE3 T;
  T.R = R.transpose();
  T.t = -(T.R * t);
  return T;
}

SE3 SE3::operator*(const SE3& T_b_c) const {
  SE3 T_a_c;
  T_a_c.R = R * T_b_c.R;
  T_a_c.t = R * T_b_c.t + t;
  return T_a_c;
}

Eigen::Vector3d SE3::operator*(const Eigen::Vector3d& p_b) const { return R * p_b + t; }

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

Eigen::Vector3d rotation_vector(const Eigen::Matrix3d& R) {
  // Through the quaternion: stable at small angles and near pi alike.
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0) q.coeffs() *= -1.0;
  const double s = q.vec().norm();
  if (s < 1e-12) return 2.0 * q.vec();  // first order: angle ~ 2 s
  const double angle = 2.0 * std::atan2(s, q.w());
  return q.vec() * (angle / s);
}

Eigen::Matrix3d rotation_from_vector(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  if (angle < 1e-12) return Eigen::Matrix3d::Identity() + skew(phi);
  return Eigen::AngleAxisd(angle, phi / angle).toRotationMatrix();
}

double rotation_angle(const Eigen::Matrix3d& R) { return rotation_vector(R).norm(); }

Eigen::Vector3d roll_pitch_yaw(const Eigen::Matrix3d& R) {
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double roll = std::atan2(R(2, 1), R(2, 2));
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  return {roll, pitch, yaw};
}

Eigen::Matrix3d from_roll_pitch_yaw(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

double orthonormality_error(const Eigen::Matrix3d& R) {
  return (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
}

SE3 perturbed(const SE3& T, const Eigen::Matrix<double, 6, 1>& d) {
  return SE3{rotation_from_vector(d.head<3>()) * T.R, T.t + d.tail<3>()};
}

Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& M) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

Eigen::Matrix3d nearest_rotation_near(const Eigen::Matrix3d& M) {
  if (!(orthonormality_error(M) <= 1e-3) || !(M.determinant() > 0)) return nearest_rotation(M);
  Eigen::Matrix3d R = M;
  // Until orthonormal to rounding, or no better (rounding's floor can lie above 1e-15).
  for (double error = orthonormality_error(R); error > 1e-15;) {
    const Eigen::Matrix3d next = 0.5 * R * (3.0 * Eigen::Matrix3d::Identity() - R.transpose() * R);
    const double next_error = orthonormality_error(next);
    if (!(next_error < error)) break;
    R = next, error = next_error;
  }
  return R;
}

std::string to_text(const SE3& T_a_b) {
  const Eigen::Quaterniond q = T_a_b.quaternion();
  return fmt::format("{} {} {} {} {} {} {}", T_a_b.t.x(), T_a_b.t.y(), T_a_b.t.z(), q.x(), q.y(),
                     q.z(), q.w());
}

SE3 se3_from_text(std::string_view text) {
  const std::vector<std::string_view> fields = split_fields(text);
  if (fields.size() != 7) {
    throw Error(fmt::format("expected 7 numbers 'tx ty tz qx qy qz qw', got {} in '{}'",
                            fields.size(), text));
  }
  double v[7];
  for (int i = 0; i < 7; ++i) v[i] = parse_double(fields[i], "pose");
  const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
  if (!(q.norm() > 1e-9)) throw Error(fmt::format("zero quaternion in '{}'", text));
  return SE3::from_quaternion(q, Eigen::Vector3d(v[0], v[1], v[2]));
}

Eigen::Matrix3d so3_right_jacobian(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d W = skew(phi);
  if (theta < 1e-5) return Eigen::Matrix3d::Identity() - 0.5 * W + W * W / 6.0;
  const double t2 = theta * theta;
  return Eigen::Matrix3d::Identity() - (1 - std::cos(theta)) / t2 * W +
         (theta - std::sin(theta)) / (t2 * theta) * W * W;
}

Eigen::Matrix3d so3_right_jacobian_inverse(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d W = skew(phi);
  if (theta < 1e-5) return Eigen::Matrix3d::Identity() + 0.5 * W + W * W / 12.0;
  const double t2 = theta * theta;
  return Eigen::Matrix3d::Identity() + 0.5 * W +
         (1 / t2 - (1 + std::cos(theta)) / (2 * theta * std::sin(theta))) * W * W;
}

}  // namespace rigcal
