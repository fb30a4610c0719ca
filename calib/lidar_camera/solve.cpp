#include "rigcal/lidar_camera/solve.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <fmt/format.h>

#include <Eigen/Dense>
#include <cmath>

#include "rigcal/core/error.h"

namespace rigcal::lidar_camera {
namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;

// One pair's residual, the camera plane's tangent angles and distance against the LiDAR plane
// carried over by (exp(dr) R0, t0 + dt), whitened by W (for Ceres; residual() below in double).
struct PlaneError {
  Eigen::Matrix3d W, R0;
  Eigen::Vector3d t0, n_lidar;
  Eigen::Matrix<double, 3, 2> B_camera;  // tangent(n_camera)
  double d_camera, d_lidar;
  template <typename S>
  bool operator()(const S* dr, const S* dt, S* out) const {
    S R[9];
    ceres::AngleAxisToRotationMatrix(dr, ceres::ColumnMajorAdapter3x3(R));
    const Eigen::Map<const Eigen::Matrix<S, 3, 3>> Rd(R);  // column-major
    const Eigen::Matrix<S, 3, 1> n = Rd * (R0 * n_lidar).cast<S>();
    const Eigen::Matrix<S, 3, 1> t = t0.cast<S>() + Eigen::Map<const Eigen::Matrix<S, 3, 1>>(dt);
    Eigen::Matrix<S, 3, 1> r;
    r.template head<2>() = B_camera.transpose().cast<S>() * n;
    r[2] = S(d_camera) - (S(d_lidar) + n.dot(t));
    Eigen::Map<Eigen::Matrix<S, 3, 1>> result(out);
    result = W.cast<S>() * r;
    return true;
  }
};

PlaneError plane_error(const BoardPair& p, const SE3& T, const Eigen::Matrix3d& W) {
  return {W, T.R, T.t, p.lidar.n, tangent(p.camera.n), p.camera.d, p.lidar.d};
}

// The residual of one pair at T, unwhitened, and its covariance.
Eigen::Vector3d residual(const BoardPair& p, const SE3& T) {
  const double zero[3] = {0, 0, 0};
  Eigen::Vector3d r;
  plane_error(p, T, Eigen::Matrix3d::Identity())(zero, zero, r.data());
  return r;
}

Eigen::Matrix3d residual_covariance(const BoardPair& p, const SE3& T) {
  const Eigen::Matrix<double, 3, 2> Bc = tangent(p.camera.n), Bl = tangent(p.lidar.n);
  Eigen::Matrix3d Jl = Eigen::Matrix3d::Zero();
  Jl.block<2, 2>(0, 0) = Bc.transpose() * T.R * Bl;
  Jl.block<1, 2>(2, 0) = -T.t.transpose() * T.R * Bl;
  Jl(2, 2) = -1.0;
  return p.camera.covariance + Jl * p.lidar.covariance * Jl.transpose();
}

}  // namespace

std::vector<PairResidual> residuals_at(const std::vector<BoardPair>& pairs, const SE3& T) {
  std::vector<PairResidual> out;
  for (const BoardPair& p : pairs) {
    PairResidual pr;
    const Eigen::Vector3d r = residual(p, T);
    pr.chi2 = r.dot(residual_covariance(p, T).ldlt().solve(r));
    pr.outlier = pr.chi2 > 16.27;
    const Eigen::Vector3d n = T.R * p.lidar.n;
    pr.normal_angle_deg = std::acos(std::clamp(n.dot(p.camera.n), -1.0, 1.0)) * 180 / M_PI;
    pr.distance_m = r[2];
    double s2 = 0;
    for (const Eigen::Vector3d& x : p.lidar_points)
      s2 += std::pow(p.camera.n.dot(T * x) - p.camera.d, 2);
    pr.point_rms_m = p.lidar_points.empty() ? 0.0 : std::sqrt(s2 / p.lidar_points.size());
    out.push_back(pr);
  }
  return out;
}

Observability observability(const std::vector<BoardPair>& pairs, double max_condition) {
  Observability o;
  Eigen::MatrixXd N(pairs.size(), 3);
  for (size_t k = 0; k < pairs.size(); ++k) N.row(k) = pairs[k].camera.n.transpose();
  if (pairs.size() >= 1) {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(N, Eigen::ComputeFullV);
    const Eigen::VectorXd sv = svd.singularValues();
    for (int i = 0; i < 3; ++i) o.singular_values[i] = i < sv.size() ? sv[i] : 0.0;
    o.weak_direction = svd.matrixV().col(2);
    o.condition = o.singular_values[2] > 0 ? o.singular_values[0] / o.singular_values[2] : INFINITY;
  }
  if (pairs.size() < 3) {
    o.reason = fmt::format("{} board(s): at least 3 with differently tilted boards are needed",
                           pairs.size());
  } else if (!(o.condition <= max_condition)) {
    o.reason = fmt::format(
        "the boards' normals do not span space (singular values {:.3f} {:.3f} {:.3f}, condition "
        "{:.0f} > {}): the translation along [{:.2f} {:.2f} {:.2f}] (camera frame) is not "
        "determined; tilt the board differently (left/right and up/down) between poses",
        o.singular_values[0], o.singular_values[1], o.singular_values[2], o.condition,
        max_condition, o.weak_direction.x(), o.weak_direction.y(), o.weak_direction.z());
  } else {
    o.enough = true;
  }
  return o;
}

Solution solve(const std::vector<BoardPair>& pairs, double huber) {
  Solution out;
  out.observability = observability(pairs);
  if (!out.observability.enough) throw Error(out.observability.reason);
  // Closed form.
  Eigen::Matrix3d Hm = Eigen::Matrix3d::Zero();
  for (const BoardPair& p : pairs) Hm += p.camera.n * p.lidar.n.transpose();
  SE3 T;
  T.R = nearest_rotation(Hm);  // Kabsch
  Eigen::MatrixXd A(pairs.size(), 3);
  Eigen::VectorXd b(pairs.size());
  for (size_t k = 0; k < pairs.size(); ++k) {
    A.row(k) = pairs[k].camera.n.transpose();
    b[k] = pairs[k].camera.d - pairs[k].lidar.d;
  }
  T.t = A.colPivHouseholderQr().solve(b);
  out.closed_form = T;
  // Ceres over SE(3) (a left rotation vector and a translation added to the closed form), the
  // residuals whitened by the planes' covariances at the current extrinsic, Huber loss; solved
  // twice, the second time whitened at the first solution.
  std::vector<Eigen::Matrix3d> W(pairs.size());
  auto whiten = [&] {
    for (size_t k = 0; k < pairs.size(); ++k) {
      W[k] = Eigen::LLT<Eigen::Matrix3d>(residual_covariance(pairs[k], T).inverse())
                 .matrixU();  // W^T W = Sigma^-1
    }
  };
  for (int round = 0; round < 2; ++round) {
    whiten();
    double dr[3] = {0, 0, 0}, dt[3] = {0, 0, 0};
    ceres::Problem problem;
    for (size_t k = 0; k < pairs.size(); ++k) {
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PlaneError, 3, 3, 3>(
                                   new PlaneError(plane_error(pairs[k], T, W[k]))),
                               new ceres::HuberLoss(huber), dr, dt);
    }
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.function_tolerance = 1e-14;
    options.parameter_tolerance = 1e-14;
    options.gradient_tolerance = 1e-16;
    options.max_num_iterations = 100;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    Vec6 d;
    d << dr[0], dr[1], dr[2], dt[0], dt[1], dt[2];
    T = perturbed(T, d);
  }
  // The information matrix at the solution (the whitened Jacobian, Huber-weighted like the loss's
  // second-order approximation): its inverse is the covariance.
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  for (size_t k = 0; k < pairs.size(); ++k) {
    const Eigen::Vector3d r = W[k] * residual(pairs[k], T);
    Eigen::Matrix<double, 3, 6> J;
    for (int c = 0; c < 6; ++c) {
      Vec6 d = Vec6::Zero();
      d[c] = 1e-7;
      J.col(c) = W[k] *
                 (residual(pairs[k], perturbed(T, d)) - residual(pairs[k], perturbed(T, -d))) /
                 2e-7;
    }
    const double w = r.norm() <= huber ? 1.0 : huber / r.norm();
    H += w * J.transpose() * J;
  }
  out.T_camera_lidar = T;
  out.residuals = residuals_at(pairs, T);
  double ss = 0;
  size_t n_in = 0;
  for (const PairResidual& pr : out.residuals) {
    if (!pr.outlier) ss += pr.chi2, ++n_in;
  }
  const double dof = std::max(1.0, 3.0 * static_cast<double>(n_in) - 6.0);
  out.noise_scale = std::sqrt(ss / dof);
  out.covariance = H.inverse() * std::max(1.0, out.noise_scale * out.noise_scale);
  for (int i = 0; i < 3; ++i) {
    out.rotation_sigma_deg[i] = std::sqrt(out.covariance(i, i)) * 180 / M_PI;
    out.translation_sigma_m[i] = std::sqrt(out.covariance(3 + i, 3 + i));
  }
  return out;
}

Calibration calibrate(const std::vector<PairInput>& in, const BoardSearch& search,
                      const std::optional<SE3>& prior) {
  Calibration out;
  out.pairs.resize(in.size());
  auto centre_in_lidar = [&](const CameraBoard& cb, const SE3& T_camera_lidar) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& x : cb.outline_camera) c += x;
    return Eigen::Vector3d(T_camera_lidar.inverse() * (c / 4.0));
  };
  auto search_all = [&](const std::optional<SE3>& T) {
    for (size_t k = 0; k < in.size(); ++k) {
      PairOutcome& o = out.pairs[k];
      if (!in[k].camera) {
        o.note = "no full board detected in the image";
        continue;
      }
      if (o.used) continue;
      BoardSearch s = search;
      s.seed = search.seed + k;
      if (T) s.expected_centre = centre_in_lidar(*in[k].camera, *T);
      o.lidar = find_board(in[k].scan, s);
      o.used = o.lidar.found;
      o.note = o.lidar.reason;
    }
  };
  auto collect = [&] {
    std::vector<BoardPair> bp;
    for (size_t k = 0; k < in.size(); ++k) {
      if (out.pairs[k].used)
        bp.push_back({in[k].camera->plane, out.pairs[k].lidar.plane, out.pairs[k].lidar.points});
    }
    return bp;
  };
  search_all(prior);
  size_t used = 0;
  for (const PairOutcome& o : out.pairs) used += o.used;
  if (used < in.size() && !prior) {
    // A first solve on the pairs found unambiguously predicts where the board is in the others.
    const std::vector<BoardPair> first = collect();
    if (observability(first).enough) search_all(solve(first).T_camera_lidar);
  }
  const std::vector<BoardPair> bp = collect();
  out.solution = solve(bp);
  size_t j = 0;
  for (size_t k = 0; k < in.size(); ++k) {
    if (!out.pairs[k].used) continue;
    if (out.solution.residuals[j].outlier) out.pairs[k].note += "; its residual is an outlier";
    ++j;
  }
  return out;
}

std::vector<std::string> outlier_warnings(const Solution& s) {
  size_t outliers = 0;
  for (const PairResidual& r : s.residuals) outliers += r.outlier;
  const size_t solved = s.residuals.size();
  if (solved == 0 || 3 * outliers <= solved) return {};
  return {fmt::format(
      "{} of the {} pairs used are outliers (their board planes disagree with the solution by "
      "more than chi-square 16.3 over 3): the extrinsic rests on the other {}. Look at each "
      "pair's overlay: a wrong plane taken as the board, a board that moved between the image "
      "and the scan, or clocks apart",
      outliers, solved, solved - outliers)};
}

}  // namespace rigcal::lidar_camera
