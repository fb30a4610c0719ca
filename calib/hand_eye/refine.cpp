#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "rigcal/core/error.h"
#include "rigcal/core/stats.h"
#include "rigcal/hand_eye/covariance.h"
#include "rigcal/hand_eye/hand_eye.h"

namespace rigcal::hand_eye {
namespace {

// A pair's LiDAR motion with the clock moved by dt: A(dt) = exp(-dt xi0) A exp(dt xi1), to first
// order in dt (xi: the LiDAR's body velocities at the pair's ends, MotionPair).
template <typename T>
void shifted(const Eigen::Quaterniond& q_A, const Eigen::Vector3d& t_A, const Eigen::Vector3d& w0,
             const Eigen::Vector3d& v0, const Eigen::Vector3d& w1, const Eigen::Vector3d& v1,
             const T& dt, Eigen::Quaternion<T>& qA, Eigen::Matrix<T, 3, 1>& tA) {
  const Eigen::Matrix<T, 3, 1> a0 = -dt * w0.cast<T>(), a1 = dt * w1.cast<T>();
  T c0[4], c1[4];  // w x y z
  ceres::AngleAxisToQuaternion(a0.data(), c0);
  ceres::AngleAxisToQuaternion(a1.data(), c1);
  const Eigen::Quaternion<T> q0(c0[0], c0[1], c0[2], c0[3]), q1(c1[0], c1[1], c1[2], c1[3]);
  qA = q0 * q_A.cast<T>() * q1;
  tA = q0 * (t_A.cast<T>() + q_A.cast<T>() * (dt * v1.cast<T>())) - dt * v0.cast<T>();
}

// One pair: rotation 2 vec(q_B^-1 q_X q_A q_X^-1) and translation R_B t_X + t_B - R_X s t_A - t_X
// (s: the odometry's scale correction; A moved with the clock correction dt), each over its sigma.
struct PairError {
  Eigen::Quaterniond q_A, q_B;
  Eigen::Vector3d t_A, t_B;
  Eigen::Vector3d w0, v0, w1, v1;  // the LiDAR's velocities at t0, t1 (MotionPair)
  double rot_sigma, trans_sigma;
  template <typename T>
  bool operator()(const T* q_x, const T* t_x, const T* scale, const T* dt, T* r) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> tX(t_x);
    const Eigen::Map<const Eigen::Quaternion<T>> qX(q_x);
    Eigen::Quaternion<T> qA;
    Eigen::Matrix<T, 3, 1> tA;
    shifted(q_A, t_A, w0, v0, w1, v1, dt[0], qA, tA);
    const Eigen::Quaternion<T> qB = q_B.cast<T>();
    const Eigen::Quaternion<T> e = qB.conjugate() * qX * qA * qX.conjugate();
    const T sign = e.w() < T(0) ? T(-1) : T(1);
    for (int i = 0; i < 3; ++i) r[i] = sign * T(2) * e.vec()[i] / T(rot_sigma);
    const Eigen::Matrix<T, 3, 1> et = qB * tX + t_B.cast<T>() - qX * (scale[0] * tA) - tX;
    for (int i = 0; i < 3; ++i) r[3 + i] = et[i] / T(trans_sigma);
    return true;
  }
};

PairError pair_error(const MotionPair& p, double rot_sigma, double trans_sigma) {
  return {p.A.quaternion(), p.B.quaternion(), p.A.t, p.B.t, p.w0, p.v0, p.w1, p.v1,
          rot_sigma,        trans_sigma};
}

// The LiDAR's motion of a pair with the clock moved by dt, in double: shifted's formula on
// rotation matrices, so that dt = 0 gives A exactly (a quaternion round trip would put 1e-6 deg of
// rounding into the residuals of poses that agree to rounding, and move the outlier flags there).
SE3 shifted_motion(const MotionPair& p, double dt) {
  const Eigen::Matrix3d R0 = rotation_from_vector(-dt * p.w0), R1 = rotation_from_vector(dt * p.w1);
  return SE3{R0 * p.A.R * R1, R0 * (p.A.t + p.A.R * (dt * p.v1)) - dt * p.v0};
}

// A held component (sigma 1e-6 m: stiff) or a prior with its sigma.
struct FixedError {
  Eigen::Vector3d direction;
  double value, sigma;
  template <typename T>
  bool operator()(const T* t_x, T* r) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> tX(t_x);
    r[0] = (direction.cast<T>().dot(tX) - T(value)) / T(sigma);
    return true;
  }
};

double fixed_sigma(const RefineOptions::Fixed& f) { return f.sigma_m > 0 ? f.sigma_m : 1e-6; }

}  // namespace

size_t bartlett_window(const std::vector<MotionPair>& pairs, const std::vector<size_t>& in) {
  constexpr size_t kMaxLag = 128;
  size_t max_lag = 1;
  for (size_t n = 0; n < in.size() && max_lag < kMaxLag; ++n) {
    size_t lag = 0;
    for (size_t m = n + 1; m < in.size() && lag < kMaxLag && pairs[in[m]].t0 <= pairs[in[n]].t1;
         ++m)
      ++lag;
    max_lag = std::max(max_lag, lag);
  }
  return 2 * max_lag;
}

namespace {

// The covariance of X's 6 parameters (rotation as a left perturbation, rad; then translation, m),
// the odometry's scale and the clock offset correction (s)
// by the sandwich H^-1 S H^-1 over the inlier pairs (normalized residuals r_k, Jacobians J_k by
// central differences): H = sum J_k^T J_k (plus the held directions), S = sum over pairs k, j
// whose time intervals touch or overlap (they share GNSS/INS fixes or odometry steps, so their
// errors are correlated) of w_kj J_k^T r_k r_j^T J_j, Bartlett weights w = 1 - lag / (L + 1)
// with L twice the largest such lag (Newey and West's estimator, generous in the window). With
// independent pairs it is the usual covariance scaled by the residuals' level; with correlated
// ones it does not count the same noise twice.
Eigen::Matrix<double, 8, 8> sandwich_covariance(const std::vector<MotionPair>& pairs, const SE3& X,
                                                double scale, double dt,
                                                const std::vector<bool>& outlier,
                                                const RefineOptions& o,
                                                const std::vector<double>& rot_sigma,
                                                const std::vector<double>& trans_sigma) {
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  using Vec8 = Eigen::Matrix<double, 8, 1>;
  using Mat68 = Eigen::Matrix<double, 6, 8>;
  using Mat8 = Eigen::Matrix<double, 8, 8>;
  auto residual = [&](size_t k, const Vec8& d) {
    const SE3 Xd = perturbed(X, d.head<6>());
    const double sd = scale + d[6], dtd = dt + d[7];
    const PairError e = pair_error(pairs[k], rot_sigma[k], trans_sigma[k]);
    const Eigen::Quaterniond q = Xd.quaternion();
    Vec6 r;
    e(q.coeffs().data(), Xd.t.data(), &sd, &dtd, r.data());
    return r;
  };
  std::vector<size_t> in;
  for (size_t k = 0; k < pairs.size(); ++k) {
    if (!outlier[k]) in.push_back(k);
  }
  std::vector<Vec6> r(in.size());
  std::vector<Mat68> J(in.size());
  const double h = 1e-6;
  tbb::parallel_for(size_t{0}, in.size(), [&](size_t n) {
    r[n] = residual(in[n], Vec8::Zero());
    for (int c = 0; c < 8; ++c) {
      Vec8 d = Vec8::Zero();
      d[c] = h;
      J[n].col(c) = (residual(in[n], d) - residual(in[n], -d)) / (2 * h);
    }
  });
  Mat8 H = Mat8::Zero();
  for (size_t n = 0; n < in.size(); ++n) H += J[n].transpose() * J[n];
  // S = sum over n, m of w(m - n) g_n g_m^T, g = J^T r. The Bartlett weight (L + 1 - |k|) / (L + 1)
  // counts the (i, j) in [0, L]^2 with i - j = k, so sum_m w(m - n) g_m is a moving sum of L + 1
  // forward, then L + 1 backward, over L + 1: linear in the number of pairs, not in L times it.
  const size_t L = bartlett_window(pairs, in);
  const long N = static_cast<long>(in.size()), W = static_cast<long>(L) + 1;
  std::vector<Vec8> g(in.size());
  for (long n = 0; n < N; ++n) g[n] = J[n].transpose() * r[n];
  std::vector<Vec8> c(N + W, Vec8::Zero());  // c[n + W] = sum_{i=0}^{L} g[n + i], n in [-W, N)
  Vec8 run = Vec8::Zero();
  for (long n = N - 1; n >= -W; --n) {
    if (n >= 0) run += g[n];
    if (n + W < N) run -= g[n + W];
    c[n + W] = run;
  }
  Mat8 S = Mat8::Zero();
  run.setZero();
  for (long n = -W; n < N; ++n) {
    run += c[n + W];  // sum_{j=0}^{L} c[n - j]
    if (n - W >= -W) run -= c[n - W + W];
    if (n >= 0) S += g[n] * run.transpose() / static_cast<double>(W);
  }
  S = 0.5 * (S + S.transpose());
  // Held translation components and, when not estimated, the scale: stiff priors. A prior with
  // a sigma adds its information to H and, its whitened residual having unit variance, to S.
  for (const RefineOptions::Fixed& f : o.fixed) {
    Vec8 a = Vec8::Zero();
    a.segment<3>(3) = f.direction.normalized() / fixed_sigma(f);
    H += a * a.transpose();
    if (f.sigma_m > 0) S += a * a.transpose();
  }
  if (!o.estimate_scale) H(6, 6) += 1e18;
  if (!o.estimate_time_offset) H(7, 7) += 1e18;
  const Mat8 Hinv = H.inverse();
  const double dof_correction =
      in.size() > 6 ? static_cast<double>(in.size()) / static_cast<double>(in.size() - 6) : 1.0;
  return dof_correction * Hinv * S * Hinv;
}

// One robust solve with the given per-pair sigmas (rad, m) on every `step`-th pair, then every
// pair's residuals, the outliers and (when asked) the covariance.
Refined solve(const std::vector<MotionPair>& pairs, const SE3& initial, double initial_scale,
              double initial_dt, const RefineOptions& o, const std::vector<double>& rot_sigma,
              const std::vector<double>& trans_sigma, bool with_covariance, size_t step = 1) {
  Eigen::Quaterniond q = initial.quaternion();
  Eigen::Vector3d t = initial.t;
  double scale = initial_scale, dt = initial_dt;
  ceres::Problem problem;
  for (size_t k = 0; k < pairs.size(); k += step) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PairError, 6, 4, 3, 1, 1>(
                                 new PairError(pair_error(pairs[k], rot_sigma[k], trans_sigma[k]))),
                             new ceres::HuberLoss(o.huber), q.coeffs().data(), t.data(), &scale,
                             &dt);
  }
  for (const RefineOptions::Fixed& f : o.fixed) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<FixedError, 1, 3>(new FixedError{
                                 f.direction.normalized(), f.value_m, fixed_sigma(f)}),
                             nullptr, t.data());
  }
  problem.SetManifold(q.coeffs().data(), new ceres::EigenQuaternionManifold);
  if (!o.estimate_scale) problem.SetParameterBlockConstant(&scale);
  if (!o.estimate_time_offset) problem.SetParameterBlockConstant(&dt);
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  so.max_num_iterations = 100;
  so.num_threads = 2;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);

  Refined out;
  out.T_gnss_lidar = SE3::from_quaternion(q, t);
  out.odometry_scale = scale;
  const SE3& X = out.T_gnss_lidar;
  // Outliers: a pair's squared normalized residual (6 components) beyond the 99.9 % point of
  // chi-square with 6 dof (22.46), after scaling the sigmas by the residuals' own level (the
  // median of chi-square(6) is 5.35), so that sigmas set too small do not flag every pair.
  std::vector<double> z2s;
  for (size_t k = 0; k < pairs.size(); ++k) {
    const MotionPair& p = pairs[k];
    const SE3 A = shifted_motion(p, dt);
    const double rr = rotation_angle((X.R * A.R).transpose() * (p.B.R * X.R));
    const double tr = (p.B.R * X.t + p.B.t - X.R * (scale * A.t) - X.t).norm();
    out.pair_rotation_residual_deg.push_back(rr * 180.0 / M_PI);
    out.pair_translation_residual_m.push_back(tr);
    z2s.push_back(std::pow(rr / rot_sigma[k], 2) + std::pow(tr / trans_sigma[k], 2));
  }
  const double level2 = std::max(1e-12, median(z2s) / 5.35);
  double ss = 0;
  size_t n_in = 0;
  for (double z2 : z2s) {
    const bool outlier = z2 / level2 > 22.46;
    out.outlier.push_back(outlier);
    if (!outlier) ss += z2, ++n_in;
  }
  const double dof =
      std::max(1.0, 6.0 * static_cast<double>(n_in) - 6.0 + static_cast<double>(o.fixed.size()));
  out.noise_scale = std::sqrt(ss / dof);
  out.time_offset_correction_s = dt;
  if (!with_covariance) return out;
  const Eigen::Matrix<double, 8, 8> C =
      sandwich_covariance(pairs, X, scale, dt, out.outlier, o, rot_sigma, trans_sigma);
  out.covariance = C.topLeftCorner<6, 6>();
  out.odometry_scale_sigma = o.estimate_scale ? std::sqrt(std::max(0.0, C(6, 6))) : 0.0;
  out.time_offset_sigma_s = o.estimate_time_offset ? std::sqrt(std::max(0.0, C(7, 7))) : 0.0;
  for (int i = 0; i < 3; ++i) {
    out.rotation_sigma_deg[i] = std::sqrt(std::max(0.0, out.covariance(i, i))) * 180.0 / M_PI;
    out.translation_sigma_m[i] = std::sqrt(std::max(0.0, out.covariance(3 + i, 3 + i)));
  }
  return out;
}

// Pairs grouped by length: sorted by t1 - t0, a new group where two consecutive lengths differ by
// more than 50 ms. Returns each pair's group and the number of groups.
std::pair<std::vector<size_t>, size_t> length_groups(const std::vector<MotionPair>& pairs) {
  std::vector<size_t> order(pairs.size()), group(pairs.size(), 0);
  std::iota(order.begin(), order.end(), size_t{0});
  auto length = [&](size_t k) { return (pairs[k].t1 - pairs[k].t0).seconds(); };
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return length(a) < length(b); });
  size_t g = 0;
  for (size_t n = 1; n < order.size(); ++n) {
    if (length(order[n]) - length(order[n - 1]) > 0.05) ++g;
    group[order[n]] = g;
  }
  return {group, pairs.empty() ? 0 : g + 1};
}

}  // namespace

Refined refine(const std::vector<MotionPair>& pairs, const SE3& initial, const RefineOptions& o) {
  if (pairs.size() < 3)
    throw Error(fmt::format("{} motion pairs; at least 3 are needed", pairs.size()));
  const std::vector<double> given_rot(pairs.size(), o.rotation_sigma_deg * M_PI / 180.0),
      given_trans(pairs.size(), o.translation_sigma_m);
  // The first solve gives the noise levels and a start: on at most 5,000 pairs spread over the
  // set (its residuals on all of them); the second weighs all pairs with those levels.
  const Refined first = solve(pairs, initial, 1.0, 0.0, o, given_rot, given_trans, false,
                              std::max<size_t>(1, pairs.size() / 5000));
  // Where the residuals give no noise levels, the first solve is the answer.
  auto with_given_sigmas = [&] {
    return solve(pairs, initial, 1.0, 0.0, o, given_rot, given_trans, true);
  };
  // The two noise levels from the inlier residuals (RMS per component: a rotation residual has 3,
  // a translation residual 3), then solved again with them: a single scale on the given sigmas
  // would let a noisy rotation inflate the translation's covariance, or the reverse. Each pair
  // length has its own levels (fewer than 10 inliers: all lengths' levels together).
  const auto [group, groups] = length_groups(pairs);
  std::vector<double> rr2(groups + 1, 0.0), tr2(groups + 1, 0.0);
  std::vector<size_t> n(groups + 1, 0);
  std::vector<std::vector<double>> lengths(groups);
  for (size_t k = 0; k < pairs.size(); ++k) {
    if (first.outlier[k]) continue;
    const double r2 = std::pow(first.pair_rotation_residual_deg[k] * M_PI / 180.0, 2);
    const double t2 = std::pow(first.pair_translation_residual_m[k], 2);
    for (size_t g : {group[k], groups}) rr2[g] += r2, tr2[g] += t2, ++n[g];
    lengths[group[k]].push_back((pairs[k].t1 - pairs[k].t0).seconds());
  }
  if (n[groups] < 3) return with_given_sigmas();
  std::vector<double> rot_noise(groups + 1), trans_noise(groups + 1);
  for (size_t g = 0; g <= groups; ++g) {
    const size_t own = n[g] >= 10 ? g : groups;
    rot_noise[g] = std::sqrt(rr2[own] / (3.0 * n[own]));
    trans_noise[g] = std::sqrt(tr2[own] / (3.0 * n[own]));
    if (!(rot_noise[g] > 1e-12 && trans_noise[g] > 1e-12)) return with_given_sigmas();
  }
  std::vector<double> rot_sigma(pairs.size()), trans_sigma(pairs.size());
  for (size_t k = 0; k < pairs.size(); ++k)
    rot_sigma[k] = rot_noise[group[k]], trans_sigma[k] = trans_noise[group[k]];
  Refined out = solve(pairs, first.T_gnss_lidar, first.odometry_scale,
                      first.time_offset_correction_s, o, rot_sigma, trans_sigma, true);
  for (size_t g = 0; g < groups; ++g) {
    if (n[g] == 0) continue;
    out.pair_noise.push_back(
        {median(lengths[g]), n[g], rot_noise[g] * 180.0 / M_PI, trans_noise[g]});
  }
  return out;
}

}  // namespace rigcal::hand_eye
