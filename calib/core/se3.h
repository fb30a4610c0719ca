#pragma once
// The one rigid-transform type of rigcal, and the rotation helpers around it.
//
// Convention (doc/conventions.md): `T_a_b` maps a point from frame b into frame a,
// p_a = T_a_b * p_b, and composes as T_a_c = T_a_b * T_b_c. Name every variable with its frames.
// The rotation is stored as a matrix, not a quaternion, so that a 4x4 matrix read from a file
// is written back bit-identical.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <string_view>

namespace rigcal {

using Vector6d = Eigen::Matrix<double, 6, 1>;

struct SE3 {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // R_a_b
  Eigen::Vector3d t = Eigen::Vector3d::Zero();      // origin of frame b, expressed in frame a

  static SE3 identity() { return {}; }
  // Takes the upper 3x4 block as it is; the last row is not checked (see is_rigid_matrix).
  static SE3 from_matrix(const Eigen::Matrix4d& m);
  static SE3 from_quaternion(const Eigen::Quaterniond& q_a_b, const Eigen::Vector3d& t_a_b);
  // exp of a twist [rotation vector (rad); translation] with translation applied after rotation:
  // R = exp(phi), t = translation. (Not the coupled SE(3) exponential; see doc/conventions.md.)
  static SE3 from_rotation_vector(const Eigen::Vector3d& phi, const Eigen::Vector3d& t_a_b);

  Eigen::Matrix4d matrix() const;
  Eigen::Quaterniond quaternion() const;  // normalized, w >= 0
  SE3 inverse() const;
  SE3 operator*(const SE3& T_b_c) const;
  Eigen::Vector3d operator*(const Eigen::Vector3d& p_b) const;
  bool operator==(const SE3& other) const { return R == other.R && t == other.t; }
};

// Rotation vector (axis * angle, rad) of a rotation matrix, angle in [0, pi].
Eigen::Vector3d rotation_vector(const Eigen::Matrix3d& R);
Eigen::Matrix3d rotation_from_vector(const Eigen::Vector3d& phi);
// Angle of a rotation in rad, in [0, pi]; accurate for small angles too.
double rotation_angle(const Eigen::Matrix3d& R);
// Roll, pitch, yaw (rad) with R = Rz(yaw) * Ry(pitch) * Rx(roll) (aerospace Z-Y-X order).
Eigen::Vector3d roll_pitch_yaw(const Eigen::Matrix3d& R);
Eigen::Matrix3d from_roll_pitch_yaw(double roll, double pitch, double yaw);
// max |R^T R - I| over the entries: 0 for an exact rotation.
double orthonormality_error(const Eigen::Matrix3d& R);
// The rotation closest to M in the Frobenius norm (SVD projection).
Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& M);
// The same for a matrix already near a rotation (a rotation written with few digits): Newton-
// Schulz steps R <- R (3 I - R'R) / 2 to orthonormality at rounding, which converge to the SVD's
// answer (the polar factor) quadratically, six times faster; the SVD itself when M is far
// (max |M'M - I| > 1e-3) or its determinant is not positive.
Eigen::Matrix3d nearest_rotation_near(const Eigen::Matrix3d& M);
Eigen::Matrix3d skew(const Eigen::Vector3d& v);
// SO(3)'s right Jacobian J_r(phi): Exp(phi + d) = Exp(phi) Exp(J_r(phi) d) to first order; and
// its inverse: Log(Exp(phi) Exp(d)) = phi + J_r(phi)^-1 d.
Eigen::Matrix3d so3_right_jacobian(const Eigen::Vector3d& phi);
Eigen::Matrix3d so3_right_jacobian_inverse(const Eigen::Vector3d& phi);
// T moved by d = (rotation vector, translation): R' = exp(d_rot) R, t' = t + d_t. The tangent
// every 6 x 6 covariance of a pose in rigcal is expressed in (rotation first, left perturbation).
SE3 perturbed(const SE3& T, const Eigen::Matrix<double, 6, 1>& d);

// Text form "tx ty tz qx qy qz qw" (the TUM order), numbers in shortest round-trip form.
std::string to_text(const SE3& T_a_b);
// Parses that form (whitespace or commas between numbers). Throws rigcal::Error on bad text.
SE3 se3_from_text(std::string_view text);

}  // namespace rigcal
