#include "rigcal/lidar/registration.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <unordered_map>

namespace rigcal::lidar {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;

struct Normal {  // the normal equations of one pass
  Matrix6d JtWJ = Matrix6d::Zero();
  Vector6d JtWr = Vector6d::Zero();
  double sum_w = 0, sum_wr2 = 0, sum_r2 = 0;
  size_t n = 0;
  // Where asked: the gradient sum w r J of the residuals in each cluster (a cube of the space).
  std::unordered_map<Eigen::Vector3i, Vector6d, VoxelHash> clusters;
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

Normal linearize(const std::vector<Eigen::Vector3d>& points_lidar, const VoxelMap& map,
                 const SE3& T_odom_lidar, double max_correspondence_m, double kernel_m,
                 const RegistrationConfig& config, double cluster_size_m = 0) {
  const double c2 = kernel_m * kernel_m;
  // Deterministic: the same chunks joined in the same order every run, so that a run repeats
  // to the last bit whatever the threads do.
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<size_t>(0, points_lidar.size(), 256), Normal{},
      [&](const tbb::blocked_range<size_t>& range, Normal acc) {
        for (size_t i = range.begin(); i != range.end(); ++i) {
          const Eigen::Vector3d a = T_odom_lidar.R * points_lidar[i];
          const Eigen::Vector3d q = a + T_odom_lidar.t;
          const std::optional<Plane> plane = plane_near(
              map, q, max_correspondence_m, config.plane_neighbours, config.max_flatness);
          if (!plane) continue;
          const double r = plane->normal.dot(q - plane->point);
          if (std::abs(r) > max_correspondence_m) continue;
          Vector6d J;
          J.head<3>() = a.cross(plane->normal);           // d r / d rotation (left)
          J.tail<3>() = plane->normal;                    // d r / d translation
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
      [](Normal a, const Normal& b) { return a += b; });
}

}  // namespace

Registration register_points(const std::vector<Eigen::Vector3d>& points_lidar, const VoxelMap& map,
                             const SE3& T_odom_lidar_guess, double max_correspondence_m,
                             double kernel_m, const RegistrationConfig& config) {
  Registration out;
  out.T_odom_lidar = T_odom_lidar_guess;
  out.points = points_lidar.size();
  Normal normal;
  double last_step = INFINITY;
  for (out.iterations = 0; out.iterations < config.max_iterations; ++out.iterations) {
    normal = linearize(points_lidar, map, out.T_odom_lidar, max_correspondence_m, kernel_m, config);
    if (normal.n < 6) return out;
    const Vector6d d = normal.JtWJ.ldlt().solve(-normal.JtWr);
    if (!d.allFinite()) return out;
    out.T_odom_lidar = perturbed(out.T_odom_lidar, d);
    // Converged: a step below the tolerance, or below ten times it without halving (the
    // correspondences switching between two neighbour sets: a cycle of that size).
    const double step = d.norm();
    const bool cycling = step < 10 * config.convergence && step > 0.5 * last_step;
    last_step = step;
    if (step < config.convergence || cycling) {
      out.converged = true;
      ++out.iterations;
      break;
    }
  }
  // The information and noise at the solution.
  normal = linearize(points_lidar, map, out.T_odom_lidar, max_correspondence_m, kernel_m, config,
                     config.cluster_size_m);
  out.correspondences = normal.n;
  if (normal.n < 6) return out;
  out.information = normal.JtWJ;
  out.noise_sigma_m = std::sqrt(normal.sum_wr2 / std::max(normal.sum_w - 6.0, 1.0));
  out.residual_rms_m = std::sqrt(normal.sum_r2 / static_cast<double>(normal.n));
  const Matrix6d H_inv = normal.JtWJ.inverse();
  out.covariance = out.noise_sigma_m * out.noise_sigma_m * H_inv;
  const double G = static_cast<double>(normal.clusters.size());
  if (config.cluster_size_m > 0 && G > 12) {
    // Cluster-robust (sandwich) form: residuals of one cluster may share an error (a map plane
    // off by a millimetre moves all of them), clusters are taken as independent.
    Matrix6d B = Matrix6d::Zero();
    for (const auto& [key, g] : normal.clusters) B.noalias() += g * g.transpose();
    out.covariance = G / (G - 1.0) * H_inv * B * H_inv;
  }
  return out;
}

}  // namespace rigcal::lidar
