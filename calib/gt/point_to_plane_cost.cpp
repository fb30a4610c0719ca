// The point-to-plane terms' Jacobians (point_to_plane_error.h, sweep_point_to_plane_error.h).
#include <ceres/manifold.h>

#include <cmath>
#include <utility>

#include "rigcal/core/se3.h"
#include "rigcal/gt/point_to_plane_error.h"
#include "rigcal/gt/sweep_point_to_plane_error.h"

namespace rigcal::gt {
namespace {

using Row3 = Eigen::Matrix<double, 1, 3>;

// The point's residual through Huber's loss at `huber` (in the residual's units): r' with
// r'^2 = rho(r^2), and dr'/dr, so that the block's squared norm is the sum of each point's loss.
std::pair<double, double> huberized(double r, double huber) {
  if (!(huber > 0) || std::abs(r) <= huber) return {r, 1.0};
  const double robust = std::copysign(std::sqrt(2.0 * huber * std::abs(r) - huber * huber), r);
  return {robust, huber / std::abs(robust)};
}

Eigen::Quaterniond unit(const double* q) {
  return Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized();
}

}  // namespace

PlanePointsCost::PlanePointsCost(std::vector<Eigen::Vector3d> p_lidar,
                                 const Eigen::Vector3d& c_world, double inv_sigma, double huber)
    : p_lidar_(std::move(p_lidar)), c_world_(c_world), inv_sigma_(inv_sigma), huber_(huber) {
  set_num_residuals(static_cast<int>(p_lidar_.size()));
  *mutable_parameter_block_sizes() = {7, 4};
}

bool PlanePointsCost::Evaluate(double const* const* parameters, double* residuals,
                               double** jacobians) const {
  const double* knot = parameters[0];
  const Eigen::Matrix3d R = unit(knot).toRotationMatrix();
  const Eigen::Map<const Eigen::Vector3d> t(knot + 4), n(parameters[1]);
  const double w = inv_sigma_;
  const Row3 wn = w * n.transpose();
  Eigen::Matrix<double, 4, 3, Eigen::RowMajor> plus;
  if (jacobians && jacobians[0]) ceres::EigenQuaternionManifold().PlusJacobian(knot, plus.data());
  for (size_t i = 0; i < p_lidar_.size(); ++i) {
    const Eigen::Vector3d Rp = R * p_lidar_[i];
    const Eigen::Vector3d x = Rp + t - c_world_;
    const auto [r, slope] = huberized(w * (n.dot(x) - parameters[1][3]), huber_);
    residuals[i] = r;
    if (!jacobians) continue;
    const Row3 sn = slope * wn;
    if (jacobians[0]) {
      Eigen::Map<Eigen::Matrix<double, 1, 7>> J(jacobians[0] + 7 * i);
      J.head<4>() = 2.0 * (-sn * skew(Rp)) * plus.transpose();
      J.tail<3>() = sn;
    }
    if (jacobians[1]) {
      Eigen::Map<Eigen::Matrix<double, 1, 4>>(jacobians[1] + 4 * i) << slope * w * x.transpose(),
          -slope * w;
    }
  }
  return true;
}

SweepPlanePointsCost::SweepPlanePointsCost(std::vector<Point> points,
                                           const Eigen::Vector3d& c_world, double inv_sigma,
                                           double huber)
    : points_(std::move(points)), c_world_(c_world), inv_sigma_(inv_sigma), huber_(huber) {
  set_num_residuals(static_cast<int>(points_.size()));
  *mutable_parameter_block_sizes() = {7, 7, 4};
}

bool SweepPlanePointsCost::Evaluate(double const* const* parameters, double* residuals,
                                    double** jacobians) const {
  const double *a = parameters[0], *b = parameters[1];
  const Eigen::Matrix3d Ra = unit(a).toRotationMatrix();
  const Eigen::Matrix3d Rb = unit(b).toRotationMatrix();
  const Eigen::Map<const Eigen::Vector3d> ta(a + 4), tb(b + 4), n(parameters[2]);
  const Eigen::Vector3d phi = rotation_vector(Ra.transpose() * Rb);
  const double w = inv_sigma_;
  const Row3 wn = w * n.transpose();
  const bool want = jacobians && (jacobians[0] || jacobians[1] || jacobians[2]);
  Eigen::Matrix<double, 4, 3, Eigen::RowMajor> plus_a, plus_b;
  Eigen::Matrix3d Jr_inv = Eigen::Matrix3d::Identity();
  if (want) {
    ceres::EigenQuaternionManifold().PlusJacobian(a, plus_a.data());
    ceres::EigenQuaternionManifold().PlusJacobian(b, plus_b.data());
    Jr_inv = so3_right_jacobian_inverse(phi);
  }
  for (size_t i = 0; i < points_.size(); ++i) {
    const double f = points_[i].fraction;
    const Eigen::Vector3d& p = points_[i].p_lidar;
    const Eigen::Matrix3d Rf = f == 0 ? Ra : Ra * rotation_from_vector(f * phi);
    const Eigen::Vector3d Rfp = Rf * p;
    const Eigen::Vector3d x = Rfp + ta + f * (tb - ta) - c_world_;
    const auto [r, slope] = huberized(w * (n.dot(x) - parameters[2][3]), huber_);
    residuals[i] = r;
    if (!want) continue;
    const Row3 sn = slope * wn;
    const Eigen::Matrix3d A = f * so3_right_jacobian(f * phi) * Jr_inv;
    const Row3 through_b = -sn * Rf * skew(p) * A * Rb.transpose();  // d r / d theta_b
    if (jacobians[0]) {
      Eigen::Map<Eigen::Matrix<double, 1, 7>> J(jacobians[0] + 7 * i);
      J.head<4>() = 2.0 * (-sn * skew(Rfp) - through_b) * plus_a.transpose();
      J.tail<3>() = (1 - f) * sn;
    }
    if (jacobians[1]) {
      Eigen::Map<Eigen::Matrix<double, 1, 7>> J(jacobians[1] + 7 * i);
      J.head<4>() = 2.0 * through_b * plus_b.transpose();
      J.tail<3>() = f * sn;
    }
    if (jacobians[2]) {
      Eigen::Map<Eigen::Matrix<double, 1, 4>>(jacobians[2] + 4 * i) << slope * w * x.transpose(),
          -slope * w;
    }
  }
  return true;
}

}  // namespace rigcal::gt
