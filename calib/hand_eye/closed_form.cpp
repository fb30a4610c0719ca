#include <fmt/format.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <random>

#include "rigcal/core/error.h"
#include "rigcal/core/stats.h"
#include "rigcal/hand_eye/covariance.h"
#include "rigcal/hand_eye/hand_eye.h"

namespace rigcal::hand_eye {
namespace {

// Which pairs disagree with the consensus (closed_form's first step).
std::vector<bool> consensus_outliers(const std::vector<MotionPair>& pairs) {
  const size_t n = pairs.size();
  std::vector<Eigen::Vector3d> a(n), b(n);
  for (size_t k = 0; k < n; ++k)
    a[k] = rotation_vector(pairs[k].A.R), b[k] = rotation_vector(pairs[k].B.R);
  // Medians on at most 2000 pairs spread over the whole set.
  const size_t step = std::max<size_t>(1, n / 2000);
  std::mt19937_64 rng(12345);
  std::uniform_int_distribution<size_t> pick(0, n - 1);
  Eigen::Matrix3d best_R = Eigen::Matrix3d::Identity();
  double best = INFINITY;
  std::vector<double> res;
  for (int it = 0, tried = 0; it < 300 && tried < 3000; ++tried) {
    const size_t i = pick(rng), j = pick(rng);
    const Eigen::Vector3d ai = a[i].normalized(), aj = a[j].normalized();
    if (i == j || ai.cross(aj).norm() < std::sin(10.0 * M_PI / 180.0)) continue;  // axes apart
    ++it;
    const Eigen::Matrix3d R = nearest_rotation(b[i] * a[i].transpose() + b[j] * a[j].transpose());
    res.clear();
    for (size_t k = 0; k < n; k += step) res.push_back((b[k] - R * a[k]).norm());
    const double m = median(res);
    if (m < best) best = m, best_R = R;
  }
  std::vector<bool> outlier(n, false);
  if (!std::isfinite(best)) return outlier;  // all axes parallel: no consensus to test against
  const double rot_cut = std::max(0.1 * M_PI / 180.0, 3.0 * 1.4826 * best);
  for (size_t k = 0; k < n; ++k) outlier[k] = (b[k] - best_R * a[k]).norm() > rot_cut;
  // Translation: least squares on the rotation inliers, then 3 robust sigmas of it.
  Eigen::Matrix3d MtM = Eigen::Matrix3d::Zero();
  Eigen::Vector3d Mty = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < n; ++k) {
    if (outlier[k]) continue;
    const Eigen::Matrix3d M = pairs[k].B.R - Eigen::Matrix3d::Identity();
    MtM += M.transpose() * M;
    Mty += M.transpose() * (best_R * pairs[k].A.t - pairs[k].B.t);
  }
  // Damped: a direction the motion does not determine stays near 0 instead of diverging.
  const Eigen::Vector3d t =
      (MtM + 1e-6 * MtM.trace() * Eigen::Matrix3d::Identity()).ldlt().solve(Mty);
  std::vector<double> e(n);
  std::vector<double> inlier_e;
  for (size_t k = 0; k < n; ++k) {
    e[k] =
        ((pairs[k].B.R - Eigen::Matrix3d::Identity()) * t - (best_R * pairs[k].A.t - pairs[k].B.t))
            .norm();
    if (!outlier[k]) inlier_e.push_back(e[k]);
  }
  const double trans_cut = std::max(0.01, 3.0 * 1.4826 * median(inlier_e));
  for (size_t k = 0; k < n; ++k) outlier[k] = outlier[k] || e[k] > trans_cut;
  return outlier;
}

}  // namespace

ClosedForm closed_form(const std::vector<MotionPair>& all_pairs, double max_sigma_m) {
  if (all_pairs.size() < 3)
    throw Error(fmt::format("{} motion pairs with enough rotation; at least 3 are needed",
                            all_pairs.size()));
  const std::vector<bool> outlier = consensus_outliers(all_pairs);
  std::vector<MotionPair> pairs;
  for (size_t k = 0; k < all_pairs.size(); ++k) {
    if (!outlier[k]) pairs.push_back(all_pairs[k]);
  }
  if (pairs.size() < 3) {
    throw Error(
        fmt::format("{} motion pairs, {} of them agreeing with each other: at least 3 are needed",
                    all_pairs.size(), pairs.size()));
  }
  ClosedForm out;
  out.pairs = all_pairs.size();
  out.outlier = outlier;
  out.rejected = all_pairs.size() - pairs.size();
  // Rotation: axis(B) = R_X axis(A), each axis scaled by its angle (rotation vectors), so that
  // small, noisy rotations weigh less.
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero(), S = Eigen::Matrix3d::Zero();
  for (const MotionPair& p : pairs) {
    const Eigen::Vector3d a = rotation_vector(p.A.R), b = rotation_vector(p.B.R);
    H += b * a.transpose();
    S += a * a.transpose();
  }
  const Eigen::Matrix3d R = nearest_rotation(H);  // Kabsch
  const Eigen::JacobiSVD<Eigen::Matrix3d> axes(S, Eigen::ComputeFullU);
  Observability& ob = out.observability;
  ob.rotation_singular_values = axes.singularValues().cwiseSqrt();
  ob.near_planar =
      ob.rotation_singular_values[2] < kNearPlanarRatio * ob.rotation_singular_values[0];
  ob.dominant_axis = R * axes.matrixU().col(0);
  if (ob.dominant_axis.z() < 0) ob.dominant_axis = -ob.dominant_axis;
  double sse = 0;
  for (const MotionPair& p : pairs) {
    sse += (rotation_vector(p.B.R) - R * rotation_vector(p.A.R)).squaredNorm();
  }
  out.rotation_residual_rms_deg = std::sqrt(sse / pairs.size()) * 180.0 / M_PI;
  // Translation: (R_B - I) t = R t_A - t_B, stacked, solved by SVD with the directions the
  // motion does not determine left at 0.
  Eigen::MatrixXd M(3 * pairs.size(), 3);
  Eigen::VectorXd y(3 * pairs.size());
  for (size_t k = 0; k < pairs.size(); ++k) {
    M.block<3, 3>(3 * k, 0) = pairs[k].B.R - Eigen::Matrix3d::Identity();
    y.segment<3>(3 * k) = R * pairs[k].A.t - pairs[k].B.t;
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> ts(M, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::Vector3d sv = ts.singularValues();
  out.observability.translation_singular_values = sv;
  out.observability.translation_directions = ts.matrixV();
  const Eigen::Vector3d t_full = ts.solve(y);
  // The 1-sigma along each right singular vector v_i: sqrt(v_i^T S v_i) / s_i^2, S the Bartlett
  // sum of the pairs' M_k^T e_k e_j^T M_j (e = residuals), as in the refinement: pairs sharing a
  // fix or overlapping are not counted as independent.
  std::vector<size_t> all(pairs.size());
  for (size_t k = 0; k < pairs.size(); ++k) all[k] = k;
  const size_t L = bartlett_window(pairs, all);
  std::vector<Eigen::Vector3d> g(pairs.size());
  for (size_t k = 0; k < pairs.size(); ++k) {
    const Eigen::Matrix3d Mk = M.block<3, 3>(3 * k, 0);
    g[k] = Mk.transpose() * (Mk * t_full - y.segment<3>(3 * k));
  }
  Eigen::Matrix3d Sg = Eigen::Matrix3d::Zero();
  for (size_t k = 0; k < pairs.size(); ++k) {
    Sg += g[k] * g[k].transpose();
    for (size_t m = k + 1; m < pairs.size() && m <= k + L; ++m) {
      const double w = 1.0 - static_cast<double>(m - k) / (L + 1);
      Sg += w * (g[k] * g[m].transpose() + g[m] * g[k].transpose());
    }
  }
  Sg *= static_cast<double>(pairs.size()) / std::max<double>(1.0, pairs.size() - 1.0);
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  const Eigen::VectorXd Uty = ts.matrixU().transpose() * y;
  // Near-planar motion: the direction closest to the dominant rotation axis is not estimated
  // whatever its formal sigma (the little it is constrained comes from the vehicle's pitch and
  // roll, which are not motions a calibration can trust).
  int normal = -1;
  if (ob.near_planar) {
    (ts.matrixV().transpose() * ob.dominant_axis).cwiseAbs().maxCoeff(&normal);
  }
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d v = ts.matrixV().col(i);
    out.observability.translation_sigma_m[i] =
        sv[i] > 0 ? std::sqrt(std::max(0.0, v.dot(Sg * v))) / (sv[i] * sv[i]) : INFINITY;
    if (i == normal || sv[i] < 1e-3 * sv[0] ||
        out.observability.translation_sigma_m[i] > max_sigma_m) {
      out.observability.unobservable.push_back(i);
      continue;
    }
    t += ts.matrixV().col(i) * (Uty[i] / sv[i]);
  }
  out.T_gnss_lidar = SE3{R, t};
  return out;
}

Held hold_unobservable(const Observability& ob, const std::optional<SE3>& prior,
                       std::vector<RefineOptions::Fixed>& fixed) {
  Held held;
  for (int i : ob.unobservable) {
    const Eigen::Vector3d d = ob.translation_directions.col(i);
    bool covered = false;
    for (const RefineOptions::Fixed& f : fixed) covered |= std::abs(f.direction.dot(d)) > 0.9;
    if (covered) continue;
    if (!prior) {
      held.uncovered.push_back(i);
      continue;
    }
    fixed.push_back({d, d.dot(prior->t)});
    held.from_prior.push_back(i);
  }
  return held;
}

}  // namespace rigcal::hand_eye
