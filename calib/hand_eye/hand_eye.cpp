#include "rigcal/hand_eye/hand_eye.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <random>

#include "rigcal/bench/metrics.h"
#include "rigcal/core/error.h"
#include "rigcal/core/stats.h"

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

// The body-frame angular and linear velocity of `traj` at t, by central differences over +-50 ms
// (one LiDAR period); zero where the poses are not there.
void velocity(const Trajectory& traj, Time t, Time max_gap, Eigen::Vector3d& w,
              Eigen::Vector3d& v) {
  const Time h = Time::from_ns(50'000'000);
  const auto a = pose_at(traj, t - h, max_gap), b = pose_at(traj, t + h, max_gap);
  w.setZero(), v.setZero();
  if (!a || !b) return;
  const SE3 d = a->inverse() * *b;
  w = rotation_vector(d.R) / 0.1;
  v = d.t / 0.1;
}

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

time_sync::TimeSyncResult estimate_clock_offset(const Trajectory& lidar, const Trajectory& gnss,
                                                double prior_offset_s) {
  time_sync::AngularRates gnss_rates = time_sync::angular_rates_from_trajectory(gnss);
  for (Time& t : gnss_rates.stamps) t = t + Time::from_seconds(prior_offset_s);
  time_sync::TimeSyncResult r =
      time_sync::estimate_time_offset(time_sync::angular_rates_from_trajectory(lidar), gnss_rates);
  r.offset_s += prior_offset_s;
  return r;
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

namespace {

// The window L of the Bartlett weights over the pairs `in` (indices, in time order): twice the
// largest number of following pairs that start before or when a pair ends (pairs end to end
// share a fix: 1; pairs every 0.1 s of 1 s: 10), at most kMaxLag (motions between every two
// stations of a long trajectory all overlap; their covariance is not meaningful anyway).
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

Trajectory smooth_poses(const Trajectory& in, double half_window_s) {
  Trajectory out = in;
  if (half_window_s <= 0) return out;
  const Time h = Time::from_seconds(half_window_s);
  // The fixes' noise from their second differences (white noise: variance 6 sigma^2), robustly:
  // fixes beyond 5 sigma (and 5 cm) of a window's fit are left out of it. A window's own misfits
  // would not do: a 1.5 m jump drags a least-squares quadratic by decimetres at every fix.
  double noise = 0;
  if (in.size() >= 3) {
    for (int a = 0; a < 3; ++a) {
      std::vector<double> d2;
      for (size_t k = 1; k + 1 < in.size(); ++k) {
        d2.push_back(std::abs(in.T_world_body[k + 1].t[a] - 2 * in.T_world_body[k].t[a] +
                              in.T_world_body[k - 1].t[a]));
      }
      noise += std::pow(1.4826 * median(d2) / std::sqrt(6.0), 2);
    }
  }
  const double cut = std::max(0.05, 5.0 * std::sqrt(noise));
  tbb::parallel_for(size_t{0}, in.size(), [&](size_t i) {
    const size_t lo = static_cast<size_t>(
        std::lower_bound(in.stamps.begin(), in.stamps.end(), in.stamps[i] - h) - in.stamps.begin());
    const size_t hi = static_cast<size_t>(
        std::upper_bound(in.stamps.begin(), in.stamps.end(), in.stamps[i] + h) - in.stamps.begin());
    if (hi - lo < 5) return;
    // Rows 1, dt, dt^2: positions, then rotation vectors relative to the pose's own (a linear fit
    // would be biased by the angular acceleration: alpha h^2 / 6, 0.1 deg on a hand-held rig).
    const size_t m = hi - lo;
    std::vector<Eigen::Vector3d> q(m);
    for (size_t k = 0; k < m; ++k) {
      const double dt = (in.stamps[lo + k] - in.stamps[i]).seconds();
      q[k] = Eigen::Vector3d(1.0, dt, dt * dt);
    }
    std::vector<char> use(m, 1);
    Eigen::Matrix3d Ap, cp;
    auto normal_matrix = [&] {
      Ap.setZero();
      int n = 0;
      for (size_t k = 0; k < m; ++k) {
        if (use[k]) Ap += q[k] * q[k].transpose(), ++n;
      }
      return n >= 5;
    };
    bool ok = true;
    for (int it = 0; it < 4; ++it) {  // fit, keep the fixes within the cut of it, again
      if (!(ok = normal_matrix())) break;
      Eigen::Matrix3d bp = Eigen::Matrix3d::Zero();
      for (size_t k = 0; k < m; ++k) {
        if (use[k]) bp += q[k] * in.T_world_body[lo + k].t.transpose();
      }
      cp = Ap.ldlt().solve(bp);
      std::vector<char> next(m);
      for (size_t k = 0; k < m; ++k)
        next[k] = (in.T_world_body[lo + k].t - cp.transpose() * q[k]).norm() <= cut;
      if (next == use) break;
      use.swap(next);
    }
    if (!ok || !normal_matrix()) return;
    const SE3& Ti = in.T_world_body[i];
    Eigen::Matrix3d bp = Eigen::Matrix3d::Zero(), br = Eigen::Matrix3d::Zero();
    for (size_t k = 0; k < m; ++k) {
      if (!use[k]) continue;
      bp += q[k] * in.T_world_body[lo + k].t.transpose();
      br += q[k] * rotation_vector(Ti.R.transpose() * in.T_world_body[lo + k].R).transpose();
    }
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(Ap);
    out.T_world_body[i].t = ldlt.solve(bp).row(0).transpose();
    out.T_world_body[i].R = Ti.R * rotation_from_vector(ldlt.solve(br).row(0).transpose());
  });
  return out;
}

namespace {

// The pairs of one length along the smoothed GNSS/INS trajectory (motion_pairs).
void pairs_of_length(const Trajectory& lidar, const Trajectory& gnss, const PairOptions& o,
                     double spacing_s, std::vector<MotionPair>& pairs) {
  const Time offset = Time::from_seconds(o.time_offset_s);
  const Time spacing = Time::from_seconds(spacing_s), max_gap = Time::from_seconds(o.max_gap_s);
  const Time stride = o.stride_s > 0 ? Time::from_seconds(o.stride_s) : spacing;
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
      MotionPair p{t0, t1, L0->inverse() * *L1, B};
      velocity(lidar, t0, max_gap, p.w0, p.v0);
      velocity(lidar, t1, max_gap, p.w1, p.v1);
      pairs.push_back(p);
    }
    i = stride == spacing
            ? j
            : static_cast<size_t>(std::lower_bound(gnss.stamps.begin() + i + 1, gnss.stamps.end(),
                                                   gnss.stamps[i] + stride) -
                                  gnss.stamps.begin());
  }
}

}  // namespace

std::vector<double> pair_lengths(const PairOptions& o) {
  for (double s : o.spacings_s) {
    if (!(s > 0)) throw Error(fmt::format("pair spacing {} s: must be positive", s));
  }
  std::vector<double> lengths = o.spacings_s;
  std::sort(lengths.begin(), lengths.end());
  lengths.erase(std::unique(lengths.begin(), lengths.end()), lengths.end());
  return lengths;
}

std::vector<MotionPair> motion_pairs(const Trajectory& lidar, const Trajectory& raw_gnss,
                                     const PairOptions& o) {
  const Trajectory gnss = smooth_poses(raw_gnss, o.gnss_half_window_s);
  std::vector<MotionPair> pairs;
  for (double s : pair_lengths(o)) pairs_of_length(lidar, gnss, o, s, pairs);
  std::stable_sort(pairs.begin(), pairs.end(), [](const MotionPair& a, const MotionPair& b) {
    return a.t0 < b.t0 || (a.t0 == b.t0 && a.t1 < b.t1);
  });
  return pairs;
}

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

}  // namespace rigcal::hand_eye
