#include "rigcal/gt/motion_fusion.h"

#include <Eigen/Cholesky>
#include <cmath>

#include "rigcal/core/error.h"

namespace rigcal::gt {
namespace {

// log det of a symmetric positive definite matrix; -inf when it is not one.
double log_det(const Matrix6d& M) {
  const Eigen::LLT<Matrix6d> llt(M);
  if (llt.info() != Eigen::Success) return -INFINITY;
  return 2.0 * llt.matrixL().toDenseMatrix().diagonal().array().log().sum();
}

// The motion d with perturbed(T_b, d) = T_a (types.h's tangent).
Eigen::Matrix<double, 6, 1> difference(const SE3& T_a, const SE3& T_b) {
  Eigen::Matrix<double, 6, 1> d;
  d << rotation_vector(T_a.R * T_b.R.transpose()), T_a.t - T_b.t;
  return d;
}

}  // namespace

FusedMotions fuse_motions(const OdometryInput& a, const OdometryInput& b, double max_disagreeing) {
  const double gate = 27.86;         // chi-square, 6 degrees of freedom, 99.99 %
  const double quantile_99 = 16.81;  // and its 99 % quantile
  const Trajectory& ta = a.T_odom_lidar;
  const Trajectory& tb = b.T_odom_lidar;
  if (ta.stamps != tb.stamps)
    throw Error("motion fusion: the two estimates are not of the same poses");
  if (a.step_covariance.size() + 1 != ta.size() || b.step_covariance.size() + 1 != tb.size())
    throw Error("motion fusion: one covariance a step is needed");
  FusedMotions out;
  out.motions.T_odom_lidar.stamps = tb.stamps;
  if (tb.size() == 0) return out;
  // Each step's two motions apart by their covariances: d' (C_a + C_b)^-1 d is chi-square with
  // 6 degrees of freedom when both are honest and independent (correlation only makes it
  // smaller). Over 1 % above its 99 % quantile by much, one of them claims more than it has.
  std::vector<double> mahalanobis2(tb.size() - 1, INFINITY);
  size_t above = 0;
  for (size_t k = 0; k + 1 < tb.size(); ++k) {
    const SE3 m_a = ta.T_world_body[k].inverse() * ta.T_world_body[k + 1];
    const SE3 m_b = tb.T_world_body[k].inverse() * tb.T_world_body[k + 1];
    const Eigen::Matrix<double, 6, 1> d = difference(m_a, m_b);
    const Eigen::LLT<Matrix6d> llt_ab(a.step_covariance[k] + b.step_covariance[k]);
    if (llt_ab.info() == Eigen::Success) mahalanobis2[k] = d.dot(llt_ab.solve(d));
    above += !(mahalanobis2[k] < quantile_99);
  }
  out.disagreeing_fraction = double(above) / double(mahalanobis2.size());
  out.fused = out.disagreeing_fraction <= max_disagreeing;
  if (!out.fused) {
    out.motions = b;
    out.weight_a.assign(mahalanobis2.size(), 0.0);
    return out;
  }
  out.motions.T_odom_lidar.T_world_body.push_back(tb.T_world_body[0]);
  for (size_t k = 0; k + 1 < tb.size(); ++k) {
    const SE3 m_a = ta.T_world_body[k].inverse() * ta.T_world_body[k + 1];
    const SE3 m_b = tb.T_world_body[k].inverse() * tb.T_world_body[k + 1];
    const Eigen::LLT<Matrix6d> llt_a(a.step_covariance[k]), llt_b(b.step_covariance[k]);
    SE3 fused = m_b;
    Matrix6d covariance = b.step_covariance[k];
    double w = 0;
    const Eigen::Matrix<double, 6, 1> d = difference(m_a, m_b);
    const bool agree =
        llt_a.info() == Eigen::Success && llt_b.info() == Eigen::Success && mahalanobis2[k] < gate;
    out.disagreeing += !agree;
    if (agree) {
      const Matrix6d I_a = llt_a.solve(Matrix6d::Identity());
      const Matrix6d I_b = llt_b.solve(Matrix6d::Identity());
      // log det of the information is concave in w: golden-section search for its maximum.
      auto f = [&](double x) { return log_det(x * I_a + (1 - x) * I_b); };
      const double g = (std::sqrt(5.0) - 1) / 2;
      double lo = 0, hi = 1, x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
      double f1 = f(x1), f2 = f(x2);
      for (int i = 0; i < 40; ++i) {
        if (f1 < f2) {
          lo = x1, x1 = x2, f1 = f2, x2 = lo + g * (hi - lo), f2 = f(x2);
        } else {
          hi = x2, x2 = x1, f2 = f1, x1 = hi - g * (hi - lo), f1 = f(x1);
        }
      }
      w = 0.5 * (lo + hi);
      // The ends themselves: one estimate alone may be the best.
      if (f(0.0) >= f(w)) w = 0;
      if (f(1.0) >= f(w)) w = 1;
      const Matrix6d I = w * I_a + (1 - w) * I_b;
      const Eigen::LLT<Matrix6d> llt(I);
      if (llt.info() == Eigen::Success) {
        covariance = llt.solve(Matrix6d::Identity());
        // The mean in b's tangent: b at 0, a at difference(m_a, m_b).
        fused = perturbed(m_b, covariance * (w * I_a * d));
      } else {
        w = 0;
      }
    }
    out.weight_a.push_back(w);
    out.motions.step_covariance.push_back(0.5 * (covariance + covariance.transpose()));
    out.motions.T_odom_lidar.T_world_body.push_back(out.motions.T_odom_lidar.T_world_body.back() *
                                                    fused);
  }
  return out;
}

}  // namespace rigcal::gt
