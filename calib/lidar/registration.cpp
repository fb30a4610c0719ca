#include "rigcal/lidar/registration.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <unordered_map>

#include "rigcal/lidar/preprocess.h"

namespace rigcal::lidar {
namespace {

// The normal equations of one pass over N parameters: the start pose (6), and for a sweep's own
// motion 6 more.
template <int N>
struct Normal {
  using Matrix = Eigen::Matrix<double, N, N>;
  using Vector = Eigen::Matrix<double, N, 1>;
  Matrix JtWJ = Matrix::Zero();
  Vector JtWr = Vector::Zero();
  double sum_w = 0, sum_wr2 = 0, sum_r2 = 0;
  size_t n = 0;
  // Where asked: the gradient sum w r J of the residuals in each cluster (a cube of the space).
  std::unordered_map<Eigen::Vector3i, Vector, VoxelHash> clusters;
  Normal& operator+=(const Normal& o) {
    JtWJ += o.JtWJ, JtWr += o.JtWr, sum_w += o.sum_w, sum_wr2 += o.sum_wr2, sum_r2 += o.sum_r2;
    n += o.n;
    for (const auto& [key, g] : o.clusters) {
      auto [it, inserted] = clusters.try_emplace(key, g);
      if (!inserted) it->second += g;
    }
    return *this;
  }
};

// A point for the residual: in the sensor frame at the start pose (`p`), with what the sweep's
// motion derivative needs (N = 12): its fraction of the sweep and its rotated raw position.
struct SweepPoint {
  Eigen::Vector3d p, rotated;
  double fraction = 0;
};

template <int N, class PointAt>
Normal<N> linearize(size_t count, const PointAt& point_at, const VoxelMap& map,
                    const SE3& T_odom_lidar, double max_correspondence_m, double kernel_m,
                    const RegistrationConfig& config, double cluster_size_m = 0) {
  const double c2 = kernel_m * kernel_m;
  // Deterministic: the same chunks joined in the same order every run, so that a run repeats
  // to the last bit whatever the threads do.
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<size_t>(0, count, 256), Normal<N>{},
      [&](const tbb::blocked_range<size_t>& range, Normal<N> acc) {
        for (size_t i = range.begin(); i != range.end(); ++i) {
          const SweepPoint point = point_at(i);
          const Eigen::Vector3d a = T_odom_lidar.R * point.p;
          const Eigen::Vector3d q = a + T_odom_lidar.t;
          const std::optional<Plane> plane =
              plane_near(map, q, max_correspondence_m, config.plane_neighbours, config.max_flatness,
                         config.max_point_share);
          if (!plane) continue;
          const double r = plane->normal.dot(q - plane->point);
          if (std::abs(r) > max_correspondence_m) continue;
          typename Normal<N>::Vector J;
          J.template head<3>() = a.cross(plane->normal);  // d r / d rotation (left)
          J.template segment<3>(3) = plane->normal;       // d r / d translation
          if constexpr (N == 12) {  // d r / d the sweep's motion (its rotation, its translation)
            const Eigen::Vector3d m = T_odom_lidar.R.transpose() * plane->normal;
            J.template segment<3>(6) = point.fraction * point.rotated.cross(m);
            J.template tail<3>() = point.fraction * m;
          }
          const double s = c2 / (c2 + r * r), w = s * s;  // Geman-McClure
          acc.JtWJ.noalias() += w * J * J.transpose();
          acc.JtWr.noalias() += w * r * J;
          acc.sum_w += w, acc.sum_wr2 += w * r * r, acc.sum_r2 += r * r;
          ++acc.n;
          if (cluster_size_m > 0) {
            auto [it, inserted] = acc.clusters.try_emplace(voxel_of(q, cluster_size_m), w * r * J);
            if (!inserted) it->second += w * r * J;
          }
        }
        return acc;
      },
      [](Normal<N> a, const Normal<N>& b) { return a += b; });
}

// The covariance of the parameters at the solution: cluster-robust (sandwich) H^-1 B H^-1, B the
// sum over clusters of their gradients' outer products (G / (G - 1) corrected) plus `prior` (the
// information of a prior term, its own gradient's covariance), where there are more than 12
// clusters; else noise_sigma^2 H^-1.
template <int N>
typename Normal<N>::Matrix covariance_of(const Normal<N>& normal,
                                         const typename Normal<N>::Matrix& H, double noise_sigma_m,
                                         double cluster_size_m,
                                         const typename Normal<N>::Matrix& prior) {
  using Matrix = typename Normal<N>::Matrix;
  const Matrix H_inv = H.inverse();
  const double G = static_cast<double>(normal.clusters.size());
  if (cluster_size_m <= 0 || G <= 12) return noise_sigma_m * noise_sigma_m * H_inv;
  // Residuals of one cluster may share an error (a map plane off by a millimetre moves all of
  // them), clusters are taken as independent.
  Matrix B = Matrix::Zero();
  for (const auto& [key, g] : normal.clusters) B.noalias() += g * g.transpose();
  return H_inv * (G / (G - 1.0) * B + prior) * H_inv;
}

// Converged: a step (rad and m together) below the tolerance, or below ten times it without
// halving from the one before (the correspondences switching between two neighbour sets: a cycle
// of that size).
bool has_converged(double step, double& last_step, const RegistrationConfig& config) {
  const bool cycling = step < 10 * config.convergence && step > 0.5 * last_step;
  last_step = step;
  return step < config.convergence || cycling;
}

}  // namespace

Registration register_points(const std::vector<Eigen::Vector3d>& points_lidar, const VoxelMap& map,
                             const SE3& T_odom_lidar_guess, double max_correspondence_m,
                             double kernel_m, const RegistrationConfig& config) {
  Registration out;
  out.T_odom_lidar = T_odom_lidar_guess;
  out.points = points_lidar.size();
  const auto point_at = [&](size_t i) { return SweepPoint{points_lidar[i], {}, 0.0}; };
  const size_t count = points_lidar.size();
  Normal<6> normal;
  double last_step = INFINITY;
  for (out.iterations = 0; out.iterations < config.max_iterations; ++out.iterations) {
    normal = linearize<6>(count, point_at, map, out.T_odom_lidar, max_correspondence_m, kernel_m,
                          config);
    if (normal.n < 6) return out;
    const Vector6d d = normal.JtWJ.ldlt().solve(-normal.JtWr);
    if (!d.allFinite()) return out;
    out.T_odom_lidar = perturbed(out.T_odom_lidar, d);
    if (has_converged(d.norm(), last_step, config)) {
      out.converged = true;
      ++out.iterations;
      break;
    }
  }
  // The information and noise at the solution.
  normal = linearize<6>(count, point_at, map, out.T_odom_lidar, max_correspondence_m, kernel_m,
                        config, config.cluster_size_m);
  out.correspondences = normal.n;
  if (normal.n < 6) return out;
  out.information = normal.JtWJ;
  out.noise_sigma_m = std::sqrt(normal.sum_wr2 / std::max(normal.sum_w - 6.0, 1.0));
  out.residual_rms_m = std::sqrt(normal.sum_r2 / static_cast<double>(normal.n));
  out.covariance = covariance_of<6>(normal, normal.JtWJ, out.noise_sigma_m, config.cluster_size_m,
                                    Matrix6d::Zero());
  return out;
}

SweepRegistration register_sweep(const std::vector<ScanPoint>& points, double period_s,
                                 const VoxelMap& map, const SE3& T_odom_start_guess,
                                 const SE3& T_start_end_prior, const Vector6d& prior_sigma,
                                 double max_correspondence_m, double kernel_m,
                                 const RegistrationConfig& config) {
  using Matrix12d = Eigen::Matrix<double, 12, 12>;
  using Vector12d = Eigen::Matrix<double, 12, 1>;
  SweepRegistration out;
  Registration& start = out.start;
  start.T_odom_lidar = T_odom_start_guess;
  start.points = points.size();
  out.T_start_end = T_start_end_prior;
  // The prior on the sweep's motion: its information, and its residual at the current motion.
  Matrix12d prior = Matrix12d::Zero();
  for (int i = 0; i < 6; ++i) prior(6 + i, 6 + i) = 1.0 / (prior_sigma[i] * prior_sigma[i]);
  auto prior_residual = [&] {
    Vector12d e = Vector12d::Zero();
    e.segment<3>(6) = rotation_vector(out.T_start_end.R * T_start_end_prior.R.transpose());
    e.tail<3>() = out.T_start_end.t - T_start_end_prior.t;
    return e;
  };
  // Each point moved to the start pose by its fraction of the current motion.
  std::vector<double> fraction(points.size());
  for (size_t i = 0; i < points.size(); ++i)
    fraction[i] = period_s > 0 ? 1e-9 * static_cast<double>(points[i].t_ns) / period_s : 0.0;
  const auto point_at = [&](size_t i) {
    const SE3 T_start_point = motion_fraction(out.T_start_end, fraction[i]);
    SweepPoint sp;
    sp.rotated = T_start_point.R * points[i].p.cast<double>();
    sp.p = sp.rotated + T_start_point.t;
    sp.fraction = fraction[i];
    return sp;
  };
  Normal<12> normal;
  double last_step = INFINITY;
  for (start.iterations = 0; start.iterations < config.max_iterations; ++start.iterations) {
    normal = linearize<12>(points.size(), point_at, map, start.T_odom_lidar, max_correspondence_m,
                           kernel_m, config);
    if (normal.n < 12) return out;
    const Vector12d d =
        (normal.JtWJ + prior).ldlt().solve(-(normal.JtWr + prior * prior_residual()));
    if (!d.allFinite()) return out;
    start.T_odom_lidar = perturbed(start.T_odom_lidar, d.head<6>());
    out.T_start_end = perturbed(out.T_start_end, d.tail<6>());
    if (has_converged(d.norm(), last_step, config)) {
      start.converged = true;
      ++start.iterations;
      break;
    }
  }
  normal = linearize<12>(points.size(), point_at, map, start.T_odom_lidar, max_correspondence_m,
                         kernel_m, config, config.cluster_size_m);
  start.correspondences = normal.n;
  if (normal.n < 12) return out;
  const Matrix12d H = normal.JtWJ + prior;
  // The start pose's information with the motion marginalised (a Schur complement).
  start.information = H.topLeftCorner<6, 6>() - H.topRightCorner<6, 6>() *
                                                    H.bottomRightCorner<6, 6>().inverse() *
                                                    H.bottomLeftCorner<6, 6>();
  start.noise_sigma_m = std::sqrt(normal.sum_wr2 / std::max(normal.sum_w - 12.0, 1.0));
  start.residual_rms_m = std::sqrt(normal.sum_r2 / static_cast<double>(normal.n));
  const Matrix12d C =
      covariance_of<12>(normal, H, start.noise_sigma_m, config.cluster_size_m, prior);
  start.covariance = C.topLeftCorner<6, 6>();
  out.motion_covariance = C.bottomRightCorner<6, 6>();
  return out;
}

}  // namespace rigcal::lidar
