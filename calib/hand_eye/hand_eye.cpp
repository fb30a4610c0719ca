#include "rigcal/hand_eye/hand_eye.h"

#include <fmt/format.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <optional>

#include "rigcal/bench/metrics.h"
#include "rigcal/core/error.h"

namespace rigcal::hand_eye {
namespace {

// The pose of `traj` at t, interpolated inside an interval no longer than max_gap.
std::optional<SE3> pose_at(const Trajectory& traj, Time t, Time max_gap) {
  const auto it = std::lower_bound(traj.stamps.begin(), traj.stamps.end(), t);
  if (it == traj.stamps.end()) return std::nullopt;
  const size_t j = static_cast<size_t>(it - traj.stamps.begin());
  if (*it == t) return traj.T_world_body[j];
  if (j == 0) return std::nullopt;
  const Time a = traj.stamps[j - 1], b = traj.stamps[j];
  if (b - a > max_gap) return std::nullopt;
  return bench::interpolate(traj.T_world_body[j - 1], traj.T_world_body[j],
                            (t - a).seconds() / (b - a).seconds());
}

}  // namespace

std::vector<MotionPair> motion_pairs(const Trajectory& lidar, const Trajectory& gnss,
                                     const PairOptions& o) {
  std::vector<MotionPair> pairs;
  const Time offset = Time::from_seconds(o.time_offset_s);
  const Time spacing = Time::from_seconds(o.spacing_s), max_gap = Time::from_seconds(o.max_gap_s);
  const double min_rotation = o.min_rotation_deg * M_PI / 180.0;
  size_t i = 0;
  while (i < gnss.size()) {
    const auto it =
        std::lower_bound(gnss.stamps.begin() + i, gnss.stamps.end(), gnss.stamps[i] + spacing);
    if (it == gnss.stamps.end()) break;
    const size_t j = static_cast<size_t>(it - gnss.stamps.begin());
    const Time t0 = gnss.stamps[i] + offset, t1 = gnss.stamps[j] + offset;
    const auto L0 = pose_at(lidar, t0, max_gap), L1 = pose_at(lidar, t1, max_gap);
    const SE3 B = gnss.T_world_body[i].inverse() * gnss.T_world_body[j];
    // A pair much longer than asked spans a GNSS/INS outage: skipped.
    if (L0 && L1 && (gnss.stamps[j] - gnss.stamps[i]) < spacing + spacing &&
        rotation_angle(B.R) >= min_rotation) {
      pairs.push_back({t0, t1, L0->inverse() * *L1, B});
    }
    i = j;
  }
  return pairs;
}

ClosedForm closed_form(const std::vector<MotionPair>& pairs, double max_sigma_m) {
  if (pairs.size() < 3)
    throw Error(
        fmt::format("{} motion pairs with enough rotation; at least 3 are needed", pairs.size()));
  ClosedForm out;
  out.pairs = pairs.size();
  // Rotation: axis(B) = R_X axis(A), each axis scaled by its angle (rotation vectors), so that
  // small, noisy rotations weigh less.
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero(), S = Eigen::Matrix3d::Zero();
  for (const MotionPair& p : pairs) {
    const Eigen::Vector3d a = rotation_vector(p.A.R), b = rotation_vector(p.B.R);
    H += b * a.transpose();
    S += a * a.transpose();
  }
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  const Eigen::Matrix3d R = svd.matrixU() * D * svd.matrixV().transpose();
  out.observability.rotation_singular_values =
      Eigen::JacobiSVD<Eigen::Matrix3d>(S).singularValues().cwiseSqrt();
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
  const double dof = std::max(1.0, static_cast<double>(y.size()) - 3.0);
  const double sigma_r = std::sqrt((M * t_full - y).squaredNorm() / dof);
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  const Eigen::VectorXd Uty = ts.matrixU().transpose() * y;
  for (int i = 0; i < 3; ++i) {
    out.observability.translation_sigma_m[i] = sv[i] > 0 ? sigma_r / sv[i] : INFINITY;
    if (sv[i] < 1e-3 * sv[0] || out.observability.translation_sigma_m[i] > max_sigma_m) {
      out.observability.unobservable.push_back(i);
      continue;
    }
    t += ts.matrixV().col(i) * (Uty[i] / sv[i]);
  }
  out.T_gnss_lidar = SE3{R, t};
  return out;
}

}  // namespace rigcal::hand_eye
