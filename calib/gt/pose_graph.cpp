#include "rigcal/gt/pose_graph.h"

#include <ceres/ceres.h>
#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "rigcal/bench/metrics.h"
#include "rigcal/core/error.h"
#include "rigcal/gt/attitude_prior_error.h"
#include "rigcal/gt/fix_error_state.h"
#include "rigcal/gt/position_prior_error.h"
#include "rigcal/gt/relative_pose_error.h"

namespace rigcal::gt {
namespace {

Eigen::Matrix3d covariance_of(const Eigen::Vector2d& sigma_h_v) {
  return Eigen::Vector3d(sigma_h_v.x() * sigma_h_v.x(), sigma_h_v.x() * sigma_h_v.x(),
                         sigma_h_v.y() * sigma_h_v.y())
      .asDiagonal();
}

// A prior at scan `node`: the fix interpolated at its stamp.
struct Prior {
  size_t node = 0, fix = 0;
  Eigen::Vector3d p_enu = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  FixQuality quality = FixQuality::rtk_fixed;
};

// Each scan with a measurement at its stamp, or two around it at most `max_gap` apart: visit(k, a,
// b, f), scan k between measurements a and b (the same one when it is at the stamp) at fraction f
// of the way from a to b.
template <class Measurement, class Visit>
void around_scans(const Trajectory& scans, const std::vector<Measurement>& m, Time max_gap,
                  Visit visit) {
  size_t i = 0;  // m[i] is the last measurement at or before the scan
  for (size_t k = 0; k < scans.size(); ++k) {
    const Time t = scans.stamps[k];
    while (i + 1 < m.size() && m[i + 1].stamp <= t) ++i;
    if (m.empty() || m[i].stamp > t) continue;
    if (m[i].stamp == t) {
      visit(k, i, i, 0.0);
    } else if (i + 1 < m.size() && m[i + 1].stamp - m[i].stamp <= max_gap) {
      visit(k, i, i + 1, (t - m[i].stamp).seconds() / (m[i + 1].stamp - m[i].stamp).seconds());
    }
  }
}

std::vector<Prior> priors_at_scans(const Trajectory& scans, const std::vector<PositionFix>& fixes,
                                   const PoseGraphConfig& config, std::vector<bool>& fix_used) {
  std::vector<Prior> out;
  fix_used.assign(fixes.size(), false);
  around_scans(scans, fixes, Time::from_seconds(config.max_fix_gap_s),
               [&](size_t k, size_t i, size_t j, double f) {
                 const PositionFix &a = fixes[i], &b = fixes[j];
                 Prior p;
                 p.node = k;
                 p.fix = f < 0.5 ? i : j;
                 p.p_enu = (1 - f) * a.p_enu + f * b.p_enu;
                 // The less certain of the two (by the trace): a quality change is not averaged
                 // away.
                 const PositionFix& worse = a.covariance.trace() >= b.covariance.trace() ? a : b;
                 p.covariance = worse.covariance;
                 p.quality = worse.quality;
                 fix_used[p.fix] = true;
                 out.push_back(p);
               });
  return out;
}

// An attitude's prior at scan `node`: the attitude interpolated at its stamp.
struct AttitudePrior {
  size_t node = 0, fix = 0;
  Eigen::Quaterniond q_enu_lidar = Eigen::Quaterniond::Identity();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
};

// As priors_at_scans: the attitudes around a scan's stamp interpolated (slerp), the covariance
// the larger of the two.
std::vector<AttitudePrior> attitude_priors_at_scans(const Trajectory& scans,
                                                    const std::vector<AttitudeFix>& attitudes,
                                                    const PoseGraphConfig& config) {
  std::vector<AttitudePrior> out;
  around_scans(scans, attitudes, Time::from_seconds(config.max_fix_gap_s),
               [&](size_t k, size_t i, size_t j, double f) {
                 const AttitudeFix &a = attitudes[i], &b = attitudes[j];
                 AttitudePrior p;
                 p.node = k;
                 p.fix = f < 0.5 ? i : j;
                 p.q_enu_lidar = a.q_enu_lidar.slerp(f, b.q_enu_lidar);
                 p.covariance =
                     a.covariance.trace() >= b.covariance.trace() ? a.covariance : b.covariance;
                 out.push_back(p);
               });
  return out;
}

// The rotation taking the odometry's rotations onto the measured attitudes: the chordal mean of
// q_measured * q_odom^-1 over the priors.
Eigen::Matrix3d rotation_from_attitudes(const std::vector<AttitudePrior>& priors,
                                        const Trajectory& scans) {
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (const AttitudePrior& p : priors)
    sum += p.q_enu_lidar.toRotationMatrix() * scans.T_world_body[p.node].R.transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

// The rotation and translation taking odometry positions onto fix positions (least squares);
// `spread_axes`: how many axes of the fixes' spread exceed min_spread_m (0, 1 or 3: a point, a
// line, a plane or a volume). With fewer than 2 the rotation is the odometry's about the missing
// axes: with a line, the smallest rotation taking the odometry's line onto the fixes'.
SE3 initial_alignment(const std::vector<Eigen::Vector3d>& p_odom,
                      const std::vector<Eigen::Vector3d>& p_enu, double min_spread_m,
                      int& spread_axes) {
  const size_t n = p_enu.size();
  Eigen::Vector3d mean_odom = Eigen::Vector3d::Zero(), mean_enu = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) mean_odom += p_odom[i], mean_enu += p_enu[i];
  mean_odom /= double(n), mean_enu /= double(n);
  Eigen::Matrix3d scatter_enu = Eigen::Matrix3d::Zero(), scatter_odom = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    scatter_enu += (p_enu[i] - mean_enu) * (p_enu[i] - mean_enu).transpose();
    scatter_odom += (p_odom[i] - mean_odom) * (p_odom[i] - mean_odom).transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> enu(scatter_enu / double(n)),
      odom(scatter_odom / double(n));
  const double s2 = min_spread_m * min_spread_m;
  spread_axes = enu.eigenvalues()(1) >= s2 ? 2 : enu.eigenvalues()(2) >= s2 ? 1 : 0;
  SE3 T_enu_odom;
  if (spread_axes == 2) {
    std::vector<SE3> a(n), b(n);
    for (size_t i = 0; i < n; ++i) a[i].t = p_enu[i], b[i].t = p_odom[i];
    T_enu_odom = bench::align(a, b, bench::Alignment::se3).T_gt_est;
  } else if (spread_axes == 1) {
    Eigen::Vector3d d_enu = enu.eigenvectors().col(2), d_odom = odom.eigenvectors().col(2);
    // Same sense: from the first position to the last.
    if (d_enu.dot(p_enu.back() - p_enu.front()) < 0) d_enu = -d_enu;
    if (d_odom.dot(p_odom.back() - p_odom.front()) < 0) d_odom = -d_odom;
    T_enu_odom.R = Eigen::Quaterniond::FromTwoVectors(d_odom, d_enu).toRotationMatrix();
  }
  T_enu_odom.t = mean_enu - T_enu_odom.R * mean_odom;
  return T_enu_odom;
}

// Pose k's parameters, as Ceres' pose_graph_3d keeps them.
struct PoseBlock {
  Eigen::Quaterniond q;
  Eigen::Vector3d t;
};

struct Graph {
  std::vector<PoseBlock> poses;
  // The fixes' error state at every scan (in units of the fixes' sigmas), when they are states.
  std::vector<Eigen::Vector3d> fix_errors;
  std::vector<double> fix_error_a;  // each step's a (0 where the fixes' kind changes)
  ceres::Problem problem;
  std::vector<ceres::ResidualBlockId> prior_blocks;
};

ceres::LinearSolverType sparse_solver() {
  return ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE) ||
                 ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE)
             ? ceres::SPARSE_NORMAL_CHOLESKY
             : ceres::DENSE_QR;
}

// How the priors enter a solve: robust or not; their covariances scaled, or their correlated
// error a Gauss-Markov state (fix_correlation_s > 0 with g.fix_errors sized).
struct PriorModel {
  double robust_sigmas = 0.0;
  double scale = 1.0;
  double correlation_s = 0.0;
  double white_fraction = 0.1;
  double attitude_scale = 1.0;  // the attitudes' covariances scaled by their correlation
};

// The graph over the poses with the odometry's edges and the priors not rejected; the first
// pose's rotation held when the fixes do not determine it.
void build(Graph& g, const OdometryInput& odometry, const std::vector<Prior>& priors,
           const std::vector<PriorResidual>& state, const Eigen::Vector3d& p_lidar_antenna,
           const PriorModel& model, bool hold_rotation, const std::vector<AttitudePrior>& attitudes,
           const std::vector<AttitudeResidual>& attitude_state) {
  const bool states = !g.fix_errors.empty();
  const std::vector<SE3>& T_odom_lidar = odometry.T_odom_lidar.T_world_body;
  for (size_t k = 0; k + 1 < g.poses.size(); ++k) {
    const SE3 T_prev_cur = T_odom_lidar[k].inverse() * T_odom_lidar[k + 1];
    auto* cost = new ceres::AutoDiffCostFunction<RelativePoseError, 6, 4, 3, 4, 3>(
        new RelativePoseError{T_prev_cur.quaternion(), T_prev_cur.t,
                              sqrt_information<6>(odometry.step_covariance[k])});
    g.problem.AddResidualBlock(cost, nullptr, g.poses[k].q.coeffs().data(), g.poses[k].t.data(),
                               g.poses[k + 1].q.coeffs().data(), g.poses[k + 1].t.data());
  }
  for (size_t j = 0; j < priors.size(); ++j) {
    if (state[j].rejected) continue;
    const Prior& p = priors[j];
    ceres::LossFunction* loss =
        model.robust_sigmas > 0 ? new ceres::HuberLoss(model.robust_sigmas) : nullptr;
    if (states) {
      const Eigen::Matrix3d L = p.covariance.llt().matrixL();
      auto* cost = new ceres::AutoDiffCostFunction<CorrelatedPositionPriorError, 3, 4, 3, 3>(
          new CorrelatedPositionPriorError{
              p.p_enu, p_lidar_antenna, std::sqrt(1.0 - model.white_fraction) * L,
              sqrt_information<3>(model.white_fraction * p.covariance)});
      g.prior_blocks.push_back(
          g.problem.AddResidualBlock(cost, loss, g.poses[p.node].q.coeffs().data(),
                                     g.poses[p.node].t.data(), g.fix_errors[p.node].data()));
      continue;
    }
    auto* cost =
        new ceres::AutoDiffCostFunction<PositionPriorError, 3, 4, 3>(new PositionPriorError{
            p.p_enu, p_lidar_antenna, sqrt_information<3>(model.scale * p.covariance)});
    g.prior_blocks.push_back(g.problem.AddResidualBlock(
        cost, loss, g.poses[p.node].q.coeffs().data(), g.poses[p.node].t.data()));
  }
  for (size_t j = 0; j < attitudes.size(); ++j) {
    if (attitude_state[j].rejected) continue;
    const AttitudePrior& p = attitudes[j];
    auto* cost = new ceres::AutoDiffCostFunction<AttitudePriorError, 3, 4>(new AttitudePriorError{
        p.q_enu_lidar, sqrt_information<3>(model.attitude_scale * p.covariance)});
    g.problem.AddResidualBlock(
        cost, model.robust_sigmas > 0 ? new ceres::HuberLoss(model.robust_sigmas) : nullptr,
        g.poses[p.node].q.coeffs().data());
  }
  if (states) {
    // A receiver's error is one process while its solution keeps its kind: where the fixes'
    // quality changes (RTK fixed to float, float to single), the state starts afresh. Scans
    // without a prior keep the quality of the last one before them.
    const Trajectory& scans = odometry.T_odom_lidar;
    std::vector<FixQuality> quality(g.fix_errors.size(), priors.front().quality);
    for (size_t j = 0, k = 0; k < quality.size(); ++k) {
      if (k > 0) quality[k] = quality[k - 1];
      for (; j < priors.size() && priors[j].node == k; ++j) quality[k] = priors[j].quality;
    }
    g.problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<FixErrorStartError, 3, 3>(new FixErrorStartError), nullptr,
        g.fix_errors.front().data());
    for (size_t k = 0; k + 1 < g.fix_errors.size(); ++k) {
      const double dt = (scans.stamps[k + 1] - scans.stamps[k]).seconds();
      const double tau = quality[k] == quality[k + 1] ? model.correlation_s : 0.0;
      auto* step = new FixErrorStepError(dt, tau);
      g.fix_error_a.push_back(step->a);
      g.problem.AddResidualBlock(new ceres::AutoDiffCostFunction<FixErrorStepError, 3, 3, 3>(step),
                                 nullptr, g.fix_errors[k].data(), g.fix_errors[k + 1].data());
    }
  }
  for (PoseBlock& b : g.poses)
    g.problem.SetManifold(b.q.coeffs().data(), new ceres::EigenQuaternionManifold);
  if (hold_rotation) g.problem.SetParameterBlockConstant(g.poses.front().q.coeffs().data());
}

ceres::Solver::Summary solve(Graph& g, int max_iterations) {
  ceres::Solver::Options options;
  options.linear_solver_type = sparse_solver();
  options.max_num_iterations = max_iterations;
  options.num_threads = 2;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &g.problem, &summary);
  return summary;
}

// The marginals of a block tridiagonal H; `log_det`, when given, receives log det H (the sum
// of the forward pivots' log determinants).
template <class Block>
std::vector<Block> block_chain_marginals(const std::vector<Block>& D, const std::vector<Block>& B,
                                         double* log_det = nullptr) {
  const size_t n = D.size();
  if (n == 0) return {};
  // Forward: S_k = D_k - B_{k-1}' S_{k-1}^-1 B_{k-1}; backward (as a smoother):
  // C_k = S_k^-1 + G_k C_{k+1} G_k', G_k = S_k^-1 B_k.
  std::vector<Block> S_inv(n);
  Block S = D[0];
  for (size_t k = 0;; ++k) {
    const Eigen::LDLT<Block> ldlt(S);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) return {};
    if (log_det) *log_det += ldlt.vectorD().array().log().sum();
    S_inv[k] = ldlt.solve(Block::Identity());
    if (k + 1 == n) break;
    S = D[k + 1] - B[k].transpose() * S_inv[k] * B[k];
  }
  std::vector<Block> C(n);
  C[n - 1] = S_inv[n - 1];
  for (size_t k = n - 1; k-- > 0;) {
    const Block G = S_inv[k] * B[k];
    C[k] = S_inv[k] + G * C[k + 1] * G.transpose();
    C[k] = 0.5 * (C[k] + C[k].transpose()).eval();
  }
  for (const Block& c : C)
    if (!c.allFinite()) return {};
  return C;
}

// The marginals of a chain whose node k has N parameters (the pose, and its fix error state when
// there is one), from the Jacobian: every row touches one node (a prior) or two consecutive ones
// (an edge, a step of the fix error).
template <int N>
std::vector<Eigen::Matrix<double, N, N>> node_marginals(const ceres::CRSMatrix& J, size_t n,
                                                        double* log_det) {
  using Block = Eigen::Matrix<double, N, N>;
  if (J.num_cols != int(N * n)) return {};
  std::vector<Block> D(n, Block::Zero()), B(n > 0 ? n - 1 : 0, Block::Zero());
  for (int r = 0; r < J.num_rows; ++r) {
    for (int a = J.rows[r]; a < J.rows[r + 1]; ++a) {
      for (int b = J.rows[r]; b < J.rows[r + 1]; ++b) {
        const int ca = J.cols[a], cb = J.cols[b];
        const size_t ka = size_t(ca) / N, kb = size_t(cb) / N;
        const double v = J.values[a] * J.values[b];
        if (ka == kb)
          D[ka](ca % N, cb % N) += v;
        else if (kb == ka + 1)
          B[ka](ca % N, cb % N) += v;
      }
    }
  }
  return block_chain_marginals(D, B, log_det);
}

// Each pose's covariance from the Jacobian at the solution, in rigcal's tangent: Ceres' quaternion
// tangent is half the rotation vector (Plus(q, d) = [cos |d|, sin |d| d / |d|] * q, left).
// `log_det`, when given, receives log det of the whole information (poses and fix error states,
// Ceres' tangent).
std::vector<Matrix6d> pose_covariances(Graph& g, double* log_det = nullptr) {
  const size_t n = g.poses.size();
  const bool states = !g.fix_errors.empty();
  ceres::Problem::EvaluateOptions eo;
  for (size_t k = 0; k < n; ++k) {
    eo.parameter_blocks.push_back(g.poses[k].q.coeffs().data());
    eo.parameter_blocks.push_back(g.poses[k].t.data());
    if (states) eo.parameter_blocks.push_back(g.fix_errors[k].data());
  }
  eo.apply_loss_function = false;
  eo.num_threads = 2;
  ceres::CRSMatrix J;
  if (!g.problem.Evaluate(eo, nullptr, nullptr, nullptr, &J)) return {};
  std::vector<Matrix6d> C;
  if (states) {
    for (const Matrix9d& c : node_marginals<9>(J, n, log_det)) C.push_back(c.topLeftCorner<6, 6>());
  } else {
    C = node_marginals<6>(J, n, log_det);
  }
  // From Ceres' tangent (d_rot, d_t) to rigcal's (2 d_rot, d_t).
  const Vector6d scale = (Vector6d() << 2, 2, 2, 1, 1, 1).finished();
  for (Matrix6d& c : C) c = scale.asDiagonal() * c * scale.asDiagonal();
  return C;
}

// The rotation's determination, from the marginals: none (singular) with fixes on a line, or a
// median sigma about some axis above config.max_rotation_sigma_deg, is said in `undetermined`.
void judge_rotation(PoseGraphResult& out, int spread_axes, const PoseGraphConfig& config) {
  const char* along_line =
      "The fixes lie on a line: the rotation about it moves no antenna position. A turn, or a "
      "lateral move, settles it.";
  if (out.covariance.empty()) {
    if (spread_axes == 1) {
      out.undetermined.push_back({"the rotation about the line of the fixes", along_line});
    }
    return;
  }
  // The largest rotation sigma of each pose and its axis; their median.
  std::vector<std::pair<double, Eigen::Vector3d>> weakest;
  for (const Matrix6d& c : out.covariance) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> e(c.topLeftCorner<3, 3>());
    weakest.emplace_back(std::sqrt(std::max(e.eigenvalues()(2), 0.0)), e.eigenvectors().col(2));
  }
  std::nth_element(weakest.begin(), weakest.begin() + std::ptrdiff_t(weakest.size() / 2),
                   weakest.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  const auto& [sigma, axis] = weakest[weakest.size() / 2];
  const double sigma_deg = sigma * 180.0 / M_PI;
  if (!(sigma_deg <= config.max_rotation_sigma_deg)) {
    const Eigen::Vector3d a = axis.z() < 0 ? Eigen::Vector3d(-axis) : axis;
    out.undetermined.push_back(
        {fmt::format("the rotation about ENU ({:.2f}, {:.2f}, {:.2f})", a.x(), a.y(), a.z()),
         fmt::format("its sigma is {:.2g} deg (the median over the poses; at most {} deg asked). "
                     "{}",
                     sigma_deg, config.max_rotation_sigma_deg,
                     spread_axes == 1 ? along_line
                                      : "The path and the fixes' accuracy do not fix it better.")});
  }
}

}  // namespace

std::string_view to_string(FixQuality quality) {
  switch (quality) {
    case FixQuality::rtk_fixed:
      return "rtk_fixed";
    case FixQuality::rtk_float:
      return "rtk_float";
    case FixQuality::single:
      return "single";
  }
  return "?";
}

std::vector<PositionFix> position_fixes(const Trajectory& T_enu_gnss,
                                        const std::vector<Eigen::Vector3d>& std_enu_m,
                                        const std::vector<int>& status, double time_offset_s,
                                        const PoseGraphConfig& config,
                                        const std::vector<FixQuality>& quality,
                                        const std::vector<Eigen::Matrix3d>& covariance_enu_m2) {
  if (!std_enu_m.empty() && std_enu_m.size() != T_enu_gnss.size())
    throw Error(
        fmt::format("{} standard deviations for {} fixes", std_enu_m.size(), T_enu_gnss.size()));
  if (!status.empty() && status.size() != T_enu_gnss.size())
    throw Error(fmt::format("{} fix states for {} fixes", status.size(), T_enu_gnss.size()));
  if (!quality.empty() && quality.size() != T_enu_gnss.size())
    throw Error(fmt::format("{} fix types for {} fixes", quality.size(), T_enu_gnss.size()));
  if (!covariance_enu_m2.empty() && covariance_enu_m2.size() != std_enu_m.size())
    throw Error(fmt::format("{} covariances for {} standard deviations", covariance_enu_m2.size(),
                            std_enu_m.size()));
  std::vector<PositionFix> out;
  out.reserve(T_enu_gnss.size());
  const Time offset = Time::from_seconds(time_offset_s);
  for (size_t i = 0; i < T_enu_gnss.size(); ++i) {
    if (!status.empty() && status[i] < 0) continue;  // no fix
    PositionFix f;
    f.stamp = T_enu_gnss.stamps[i] + offset;
    f.p_enu = T_enu_gnss.T_world_body[i].t;
    // NavSatFix's status cannot tell RTK float from fixed: the solution's type, when given.
    if (!quality.empty())
      f.quality = quality[i];
    else
      f.quality = status.empty() || status[i] == 2 ? FixQuality::rtk_fixed : FixQuality::single;
    // A receiver that does not know its accuracy reports zeros (NavSatFix's covariance type
    // unknown): its state's sigmas then.
    if (!std_enu_m.empty() && std_enu_m[i].minCoeff() > 0) {
      // The receiver's whole covariance when it gives one (NavSatFix's, type known): an
      // elongated error ellipse keeps its axes.
      if (!covariance_enu_m2.empty())
        f.covariance = covariance_enu_m2[i];
      else
        f.covariance = std_enu_m[i].cwiseProduct(std_enu_m[i]).asDiagonal();
    } else {
      f.covariance = covariance_of(f.quality == FixQuality::rtk_fixed   ? config.sigma_rtk_fixed
                                   : f.quality == FixQuality::rtk_float ? config.sigma_rtk_float
                                                                        : config.sigma_single);
    }
    out.push_back(f);
  }
  return out;
}

std::vector<AttitudeFix> attitude_fixes(const Trajectory& T_enu_ins,
                                        const Eigen::Quaterniond& q_ins_lidar, double time_offset_s,
                                        const Eigen::Vector2d& sigma_rad) {
  if (!(sigma_rad.minCoeff() > 0))
    throw Error(
        fmt::format("the attitudes' sigmas must be above zero (tilt {} rad, heading {} rad)",
                    sigma_rad.x(), sigma_rad.y()));
  const bool all_identity =
      std::all_of(T_enu_ins.T_world_body.begin(), T_enu_ins.T_world_body.end(),
                  [](const SE3& T) { return T.R.isIdentity(1e-12); });
  if (all_identity && !T_enu_ins.empty())
    throw Error(
        "every rotation is the identity: positions written as poses carry no attitude (give the "
        "GNSS/INS's own poses, or no attitudes)");
  const Eigen::Matrix3d covariance = covariance_of(sigma_rad);  // tilt on two axes, as horizontal
  std::vector<AttitudeFix> out;
  out.reserve(T_enu_ins.size());
  const Time offset = Time::from_seconds(time_offset_s);
  for (size_t i = 0; i < T_enu_ins.size(); ++i) {
    AttitudeFix a;
    a.stamp = T_enu_ins.stamps[i] + offset;
    a.q_enu_lidar = (T_enu_ins.T_world_body[i].quaternion() * q_ins_lidar).normalized();
    a.covariance = covariance;
    out.push_back(a);
  }
  return out;
}

std::vector<Matrix6d> chain_marginals(const std::vector<Matrix6d>& D,
                                      const std::vector<Matrix6d>& B) {
  return block_chain_marginals(D, B);
}

std::vector<Matrix9d> chain_marginals(const std::vector<Matrix9d>& D,
                                      const std::vector<Matrix9d>& B) {
  return block_chain_marginals(D, B);
}

PoseGraphResult solve_pose_graph(const OdometryInput& odometry,
                                 const std::vector<PositionFix>& fixes,
                                 const Eigen::Vector3d& p_lidar_antenna,
                                 const PoseGraphConfig& config,
                                 const std::vector<AttitudeFix>& attitudes) {
  const Trajectory& scans = odometry.T_odom_lidar;
  const size_t n = scans.size();
  if (n == 0) throw Error("the odometry has no poses");
  if (odometry.step_covariance.size() + 1 != n) {
    throw Error(fmt::format("{} step covariances for {} odometry poses ({} expected)",
                            odometry.step_covariance.size(), n, n - 1));
  }
  if (config.fix_error_states && !(config.fix_white_fraction > 0 && config.fix_white_fraction <= 1))
    throw Error(fmt::format("the fixes' white share of variance is {}: it must be in (0, 1]",
                            config.fix_white_fraction));
  PoseGraphResult out;
  std::vector<bool> fix_used;
  const std::vector<Prior> priors = priors_at_scans(scans, fixes, config, fix_used);
  const std::vector<AttitudePrior> attitude_priors =
      attitude_priors_at_scans(scans, attitudes, config);
  out.fixes_unused = size_t(std::count(fix_used.begin(), fix_used.end(), false));
  if (priors.empty()) {
    out.undetermined.push_back(
        {"every pose", fixes.empty() ? "there is no GNSS fix"
                                     : "no GNSS fix falls within the scans' time (check the "
                                       "clocks and the GNSS time_offset)"});
    return out;
  }
  // The spans of scans without a prior, longer than the interpolation gap.
  {
    Time last = scans.stamps.front();
    bool open = true;  // from the first scan
    size_t j = 0;
    for (size_t k = 0; k < n; ++k) {
      if (j < priors.size() && priors[j].node == k) {
        ++j;
        if (open && scans.stamps[k] - last > Time::from_seconds(config.max_fix_gap_s))
          out.outages.emplace_back(last, scans.stamps[k]);
        open = false;
        last = scans.stamps[k];
      } else {
        open = true;
      }
    }
    if (open && scans.stamps.back() - last > Time::from_seconds(config.max_fix_gap_s))
      out.outages.emplace_back(last, scans.stamps.back());
  }

  // The starting guess: the odometry moved onto the fixes.
  std::vector<Eigen::Vector3d> p_odom, p_enu;
  for (const Prior& p : priors) {
    p_odom.push_back(scans.T_world_body[p.node] * p_lidar_antenna);
    p_enu.push_back(p.p_enu);
  }
  int spread_axes = 0;
  const SE3 T_enu_odom_by_fixes =
      initial_alignment(p_odom, p_enu, config.min_spread_m, spread_axes);
  SE3 T_enu_odom = T_enu_odom_by_fixes;
  // Fixes that do not turn the odometry by themselves (a point, a line): the attitudes do.
  if (spread_axes < 2 && !attitude_priors.empty()) {
    Eigen::Vector3d mean_odom = Eigen::Vector3d::Zero(), mean_enu = Eigen::Vector3d::Zero();
    for (size_t j = 0; j < p_odom.size(); ++j) mean_odom += p_odom[j], mean_enu += p_enu[j];
    T_enu_odom.R = rotation_from_attitudes(attitude_priors, scans);
    T_enu_odom.t = (mean_enu - T_enu_odom.R * mean_odom) / double(p_odom.size());
  }
  // A standing rig without attitudes: its rotation is the odometry's, held. Fixes along a line:
  // solved, and the rotation about the line judged by its marginal sigma below.
  bool hold_rotation = spread_axes == 0 && attitude_priors.empty();
  // Priors closer in time than the fixes' correlation share their error.
  // A first-order Gauss-Markov error of correlation time tau averages over a span T as
  // T / (2 tau) independent samples would: each prior's covariance scaled by the scans in 2 tau.
  const double scan_rate =
      n >= 2 ? double(n - 1) / (scans.stamps.back() - scans.stamps.front()).seconds() : 0.0;
  auto correlation_scale = [&](double tau_s) {
    return tau_s > 0 && n >= 2 ? std::max(1.0, 2.0 * tau_s * scan_rate) : 1.0;
  };
  const double prior_scale = correlation_scale(config.fix_correlation_s);
  const double attitude_scale = correlation_scale(config.attitude_correlation_s);
  out.attitude_priors.resize(attitude_priors.size());
  for (size_t j = 0; j < attitude_priors.size(); ++j) {
    out.attitude_priors[j].fix = attitude_priors[j].fix;
    out.attitude_priors[j].node = attitude_priors[j].node;
    out.attitude_priors[j].stamp = scans.stamps[attitude_priors[j].node];
  }

  out.priors.resize(priors.size());
  for (size_t j = 0; j < priors.size(); ++j) {
    out.priors[j].fix = priors[j].fix;
    out.priors[j].node = priors[j].node;
    out.priors[j].stamp = scans.stamps[priors[j].node];
  }
  std::vector<PoseBlock> poses(n);
  for (size_t k = 0; k < n; ++k) {
    const SE3 T_enu_lidar = T_enu_odom * scans.T_world_body[k];
    poses[k] = {T_enu_lidar.quaternion(), T_enu_lidar.t};
  }
  // Each prior's residual at `poses`, against its fix's own covariance (not the
  // correlation-scaled weight).
  auto prior_residuals = [&](const std::vector<PoseBlock>& at) {
    for (size_t j = 0; j < priors.size(); ++j) {
      PriorResidual& r = out.priors[j];
      const PoseBlock& b = at[priors[j].node];
      r.residual_enu = b.q * p_lidar_antenna + b.t - priors[j].p_enu;
      r.mahalanobis2 = r.residual_enu.dot(priors[j].covariance.ldlt().solve(r.residual_enu));
    }
    for (size_t j = 0; j < attitude_priors.size(); ++j) {
      AttitudeResidual& r = out.attitude_priors[j];
      r.residual_enu =
          rotation_vector(at[attitude_priors[j].node].q.toRotationMatrix() *
                          attitude_priors[j].q_enu_lidar.toRotationMatrix().transpose());
      r.mahalanobis2 =
          r.residual_enu.dot(attitude_priors[j].covariance.ldlt().solve(r.residual_enu));
    }
  };
  // Solve 1, robust, its priors' covariances scaled by the correlation; the gate.
  {
    Graph g;
    g.poses = poses;
    PriorModel model{config.robust_sigmas, prior_scale, 0.0, config.fix_white_fraction};
    model.attitude_scale = attitude_scale;
    build(g, odometry, priors, out.priors, p_lidar_antenna, model, hold_rotation, attitude_priors,
          out.attitude_priors);
    const ceres::Solver::Summary summary = solve(g, config.max_iterations);
    if (!summary.IsSolutionUsable())
      throw Error("the pose graph's solve failed: " + summary.message);
    out.iterations += int(summary.iterations.size());
    out.initial_cost = summary.initial_cost;
    poses = g.poses;
    prior_residuals(poses);
    for (PriorResidual& r : out.priors) r.rejected = r.mahalanobis2 > config.gate_chi2;
    for (AttitudeResidual& r : out.attitude_priors) r.rejected = r.mahalanobis2 > config.gate_chi2;
  }
  out.attitudes_rejected =
      size_t(std::count_if(out.attitude_priors.begin(), out.attitude_priors.end(),
                           [](const AttitudeResidual& r) { return r.rejected; }));
  // A standing rig whose attitudes the gate rejected, every one: held as without them.
  // A standing rig whose attitudes the gate rejected, every one: held as without them, from the
  // odometry moved onto the fixes alone.
  if (spread_axes == 0 && !hold_rotation && out.attitudes_rejected == out.attitude_priors.size()) {
    hold_rotation = true;
    for (size_t k = 0; k < n; ++k) {
      const SE3 T_enu_lidar = T_enu_odom_by_fixes * scans.T_world_body[k];
      poses[k] = {T_enu_lidar.quaternion(), T_enu_lidar.t};
    }
  }
  if (hold_rotation) {
    out.undetermined.push_back(
        {"the rotation (heading, roll and pitch)",
         fmt::format("the fixes spread less than {} m: the rig stood still; the odometry's "
                     "rotation is kept. {}",
                     config.min_spread_m,
                     attitude_priors.empty()
                         ? "Move the rig over a few metres in two directions, or give the "
                           "GNSS/INS's attitudes."
                         : "Every GNSS/INS attitude was rejected by the gate: check the rig's "
                           "rotation between the INS and the LiDAR.")});
  }
  const auto kept = std::count_if(out.priors.begin(), out.priors.end(),
                                  [](const PriorResidual& r) { return !r.rejected; });
  // Solve 2 on the priors kept, from solve 1's poses: plain least squares, the fixes' error a
  // state (their covariances not scaled) or their covariances scaled as in solve 1.
  const bool states = config.fix_error_states &&
                      (config.fix_correlation_s > 0 || config.fix_correlation_by_likelihood);
  struct Final {
    std::vector<PoseBlock> poses;
    std::vector<Eigen::Vector3d> fix_errors;
    std::vector<Matrix6d> covariance;
    int iterations = 0;
    double cost = 0;
    double minus_2_log_likelihood = std::numeric_limits<double>::infinity();
  };
  // From solve 1's poses, or (`start`) from a solution with other parameters: the search's
  // solves start from the best so far, a step or two away.
  auto final_solve = [&](double tau_s, double white_fraction, const Final* start = nullptr) {
    Graph g;
    g.poses = start ? start->poses : poses;
    PriorModel model{0.0, prior_scale, 0.0, white_fraction};
    model.attitude_scale = attitude_scale;
    if (states) {
      g.fix_errors =
          start ? start->fix_errors : std::vector<Eigen::Vector3d>(n, Eigen::Vector3d::Zero());
      model.scale = 1.0;
      model.correlation_s = tau_s;
    }
    build(g, odometry, priors, out.priors, p_lidar_antenna, model, hold_rotation, attitude_priors,
          out.attitude_priors);
    const ceres::Solver::Summary summary = solve(g, config.max_iterations);
    if (!summary.IsSolutionUsable())
      throw Error("the pose graph's solve failed: " + summary.message);
    Final f;
    f.iterations = int(summary.iterations.size());
    f.cost = summary.final_cost;
    if (!hold_rotation) {
      double log_det = 0;
      f.covariance = pose_covariances(g, &log_det);
      // The marginal likelihood of the fixes and motions given the time and the white share
      // (the poses and states integrated out, Laplace): -2 log p = 2 cost + log det H -
      // sum log det W, W the information of each factor that depends on them: a Gauss-Markov
      // step's I / (1 - a^2), a kept prior's (white C)^-1 (up to log det C, constant).
      if (!f.covariance.empty() && states) {
        f.minus_2_log_likelihood = 2.0 * summary.final_cost + log_det;
        for (const double a : g.fix_error_a)
          f.minus_2_log_likelihood += 3.0 * std::log(std::max(1.0 - a * a, 1e-12));
        f.minus_2_log_likelihood += 3.0 * double(kept) * std::log(white_fraction);
      }
    }
    f.poses = std::move(g.poses);
    f.fix_errors = std::move(g.fix_errors);
    return f;
  };
  double tau_s = config.fix_correlation_s, white_fraction = config.fix_white_fraction;
  Final best;
  if (states && config.fix_correlation_by_likelihood && !hold_rotation) {
    // Each evaluation a solve; the most likely of all kept.
    auto evaluate = [&](double tau, double white) {
      Final f = final_solve(tau, white, best.poses.empty() ? nullptr : &best);
      out.iterations += f.iterations;
      const double m = f.minus_2_log_likelihood;
      if (m < best.minus_2_log_likelihood) {
        best = std::move(f);
        tau_s = tau, white_fraction = white;
      }
      return m;
    };
    // Nelder-Mead over (log tau, log white share), both clamped to their ranges (tau 0.2-120 s,
    // the share 1e-4-0.5): the two trade against each other (a white share taken too large
    // makes the errors look smoother than they are, and the time comes out long: measured,
    // 0.1 for none gives 14-17 s for a true 5 s), so they are searched together; to 5 % in
    // each (or as alike as the data can tell), at most 60 solves.
    using Point = Eigen::Vector2d;
    const Point lower(std::log(0.2), std::log(1e-4)), upper(std::log(120.0), std::log(0.5));
    auto f = [&](const Point& x) {
      const Point c = x.cwiseMax(lower).cwiseMin(upper);
      return evaluate(std::exp(c.x()), std::exp(c.y()));
    };
    const Point start(std::log(config.fix_correlation_s > 0 ? config.fix_correlation_s : 2.0),
                      std::log(white_fraction));
    std::array<Point, 3> x{start, start + Point(0.7, 0.0), start + Point(0.0, 1.5)};
    std::array<double, 3> fx{f(x[0]), f(x[1]), f(x[2])};
    for (int evaluations = 3; evaluations < 60;) {
      std::array<int, 3> order{0, 1, 2};
      std::sort(order.begin(), order.end(), [&](int i, int j) { return fx[i] < fx[j]; });
      const int lo = order[0], mid = order[1], hi = order[2];
      // Done when the simplex is 5 % wide, or when its likelihoods differ by less than 0.5 in
      // -2 log p (a quarter of the 1.96^2 / 2 that a 95 % interval of one parameter spans: the
      // data cannot tell them apart).
      const double size =
          std::max((x[hi] - x[lo]).cwiseAbs().maxCoeff(), (x[mid] - x[lo]).cwiseAbs().maxCoeff());
      if (size < 0.05 || fx[hi] - fx[lo] < 0.5) break;
      const Point centre = 0.5 * (x[lo] + x[mid]);
      const Point reflected = centre + (centre - x[hi]);
      const double f_reflected = f(reflected);
      ++evaluations;
      if (f_reflected < fx[lo]) {
        const Point expanded = centre + 2.0 * (centre - x[hi]);
        const double f_expanded = f(expanded);
        ++evaluations;
        if (f_expanded < f_reflected)
          x[hi] = expanded, fx[hi] = f_expanded;
        else
          x[hi] = reflected, fx[hi] = f_reflected;
      } else if (f_reflected < fx[mid]) {
        x[hi] = reflected, fx[hi] = f_reflected;
      } else {
        const Point contracted = centre + 0.5 * (x[hi] - centre);
        const double f_contracted = f(contracted);
        ++evaluations;
        if (f_contracted < fx[hi]) {
          x[hi] = contracted, fx[hi] = f_contracted;
        } else {  // shrink towards the best
          for (int i : {mid, hi}) {
            x[i] = x[lo] + 0.5 * (x[i] - x[lo]);
            fx[i] = f(x[i]);
            ++evaluations;
          }
        }
      }
    }
  }
  if (best.poses.empty()) {  // not searched, or no likelihood (singular information)
    tau_s = config.fix_correlation_s, white_fraction = config.fix_white_fraction;
    best = final_solve(tau_s, white_fraction);
    out.iterations += best.iterations;
  }
  out.fix_correlation_s = std::max(tau_s, 0.0);
  out.fix_white_fraction = states ? white_fraction : 0.0;
  out.final_cost = best.cost;
  poses = std::move(best.poses);
  prior_residuals(poses);
  out.covariance = std::move(best.covariance);
  if (!hold_rotation) judge_rotation(out, spread_axes, config);
  if (!config.covariances) out.covariance.clear();
  out.rejected = out.priors.size() - size_t(kept);
  out.T_enu_lidar.stamps = scans.stamps;
  out.T_enu_lidar.has_stamps = scans.has_stamps;
  for (const PoseBlock& b : poses)
    out.T_enu_lidar.T_world_body.push_back(SE3::from_quaternion(b.q, b.t));
  if (config.covariances && out.covariance.empty()) {
    out.notes.push_back(hold_rotation || spread_axes == 1
                            ? "no pose covariances: the rotation is not determined"
                            : "no pose covariances: the graph's information is singular");
  }
  return out;
}

double estimate_fix_correlation(const std::vector<PriorResidual>& priors,
                                const std::vector<PositionFix>& fixes, double max_s) {
  // Each kept prior's stamp and its residual in its fix's sigmas (L^-1 r, C = L L').
  struct Whitened {
    Time stamp;
    Eigen::Vector3d residual_enu;
  };
  std::vector<Whitened> white;
  for (const PriorResidual& p : priors) {
    if (p.rejected || p.fix >= fixes.size()) continue;
    const Eigen::LLT<Eigen::Matrix3d> llt(fixes[p.fix].covariance);
    if (llt.info() != Eigen::Success) continue;
    white.push_back({p.stamp, llt.matrixL().solve(p.residual_enu)});
  }
  std::vector<const Whitened*> kept;
  for (const Whitened& w : white) kept.push_back(&w);
  if (kept.size() < 20) return 0.0;
  std::sort(kept.begin(), kept.end(),
            [](const Whitened* a, const Whitened* b) { return a->stamp < b->stamp; });
  // The typical spacing of consecutive priors (their median).
  std::vector<double> gaps;
  for (size_t k = 1; k < kept.size(); ++k)
    gaps.push_back((kept[k]->stamp - kept[k - 1]->stamp).seconds());
  std::nth_element(gaps.begin(), gaps.begin() + long(gaps.size() / 2), gaps.end());
  const double dt = gaps[gaps.size() / 2];
  if (!(dt > 0)) return 0.0;
  double energy = 0;
  for (const Whitened* p : kept) energy += p->residual_enu.squaredNorm();
  if (!(energy > 0)) return 0.0;
  const size_t max_lag = std::min(kept.size() / 2, size_t(std::ceil(max_s / dt)));
  for (size_t lag = 1; lag <= max_lag; ++lag) {
    double sum = 0, norm = 0;
    for (size_t k = 0; k + lag < kept.size(); ++k) {
      if ((kept[k + lag]->stamp - kept[k]->stamp).seconds() > 1.5 * dt * double(lag)) continue;
      sum += kept[k]->residual_enu.dot(kept[k + lag]->residual_enu);
      norm +=
          0.5 * (kept[k]->residual_enu.squaredNorm() + kept[k + lag]->residual_enu.squaredNorm());
    }
    if (norm > 0 && sum / norm < std::exp(-1.0)) return lag == 1 ? 0.0 : dt * double(lag);
  }
  return dt * double(max_lag);
}

}  // namespace rigcal::gt
