// The point-to-plane terms' Jacobians (point_to_plane_error.h, sweep_point_to_plane_error.h).
#include <ceres/manifold.h>

#include "rigcal/core/se3.h"
#include "rigcal/gt/point_to_plane_error.h"
#include "rigcal/gt/sweep_point_to_plane_error.h"

namespace rigcal::gt {
namespace {

using Row3 = Eigen::Matrix<double, 1, 3>;

// The ambient Jacobian (1 x 4, x y z w) of a residual whose Jacobian in the world-frame rotation
// theta of the quaternion q is `d_theta`: Ceres' tangent is theta / 2.
void quaternion_jacobian(const double* q, const Row3& d_theta, double* out) {
  Eigen::Matrix<double, 4, 3, Eigen::RowMajor> plus;
  ceres::EigenQuaternionManifold().PlusJacobian(q, plus.data());
  Eigen::Map<Eigen::Matrix<double, 1, 4>> J(out);
  J = 2.0 * d_theta * plus.transpose();
}

Eigen::Quaterniond unit(const double* q) {
  return Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized();
}

}  // namespace

bool PointToPlaneCost::Evaluate(double const* const* parameters, double* residuals,
                                double** jacobians) const {
  const Eigen::Matrix3d R = unit(parameters[0]).toRotationMatrix();
  const Eigen::Map<const Eigen::Vector3d> t(parameters[1]), n(parameters[2]);
  const Eigen::Vector3d Rp = R * e_.p_lidar;
  const Eigen::Vector3d x = Rp + t - e_.c_world;
  const double w = e_.inv_sigma;
  residuals[0] = w * (n.dot(x) - parameters[2][3]);
  if (!jacobians) return true;
  const Row3 wn = w * n.transpose();
  if (jacobians[0]) quaternion_jacobian(parameters[0], -wn * skew(Rp), jacobians[0]);
  if (jacobians[1]) Row3::Map(jacobians[1]) = wn;
  if (jacobians[2]) {
    Eigen::Map<Eigen::Matrix<double, 1, 4>> J(jacobians[2]);
    J << w * x.transpose(), -w;
  }
  return true;
}

bool SweepPointToPlaneCost::Evaluate(double const* const* parameters, double* residuals,
                                     double** jacobians) const {
  const double f = e_.fraction;
  const Eigen::Matrix3d Ra = unit(parameters[0]).toRotationMatrix();
  const Eigen::Matrix3d Rb = unit(parameters[2]).toRotationMatrix();
  const Eigen::Map<const Eigen::Vector3d> ta(parameters[1]), tb(parameters[3]), n(parameters[4]);
  const Eigen::Vector3d phi = rotation_vector(Ra.transpose() * Rb);
  const Eigen::Matrix3d Rf = Ra * rotation_from_vector(f * phi);
  const Eigen::Vector3d Rfp = Rf * e_.p_lidar;
  const Eigen::Vector3d x = Rfp + ta + f * (tb - ta) - e_.c_world;
  const double w = e_.inv_sigma;
  residuals[0] = w * (n.dot(x) - parameters[4][3]);
  if (!jacobians) return true;
  const Row3 wn = w * n.transpose();
  const Eigen::Matrix3d A = f * so3_right_jacobian(f * phi) * so3_right_jacobian_inverse(phi);
  const Row3 through_b = -wn * Rf * skew(e_.p_lidar) * A * Rb.transpose();  // d r / d theta_b
  if (jacobians[0]) quaternion_jacobian(parameters[0], -wn * skew(Rfp) - through_b, jacobians[0]);
  if (jacobians[1]) Row3::Map(jacobians[1]) = (1 - f) * wn;
  if (jacobians[2]) quaternion_jacobian(parameters[2], through_b, jacobians[2]);
  if (jacobians[3]) Row3::Map(jacobians[3]) = f * wn;
  if (jacobians[4]) {
    Eigen::Map<Eigen::Matrix<double, 1, 4>> J(jacobians[4]);
    J << w * x.transpose(), -w;
  }
  return true;
}

}  // namespace rigcal::gt
