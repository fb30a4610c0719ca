#include "rigcal/lidar/voxel_map.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>

namespace rigcal::lidar {

namespace {
constexpr double kMinSpread = 0.05;  // middle over largest scatter eigenvalue of a plane's points
}  // namespace

Eigen::Vector3i voxel_of(const Eigen::Vector3d& p, double voxel_size) {
  return (p / voxel_size).array().floor().cast<int>();
}

size_t point_count(const VoxelMap& map) {
  size_t n = 0;
  for (const auto& [key, points] : map.voxels) n += points.size();
  return n;
}

void add_points(VoxelMap& map, const std::vector<Eigen::Vector3d>& points_odom) {
  for (const Eigen::Vector3d& p : points_odom) {
    std::vector<Eigen::Vector3d>& voxel = map.voxels[voxel_of(p, map.voxel_size)];
    if (voxel.size() >= map.max_points_per_voxel) continue;
    const double spacing2 = map.min_point_spacing * map.min_point_spacing;
    if (spacing2 > 0 && std::any_of(voxel.begin(), voxel.end(), [&](const Eigen::Vector3d& v) {
          return (v - p).squaredNorm() < spacing2;
        }))
      continue;
    voxel.push_back(p);
  }
}

void remove_far(VoxelMap& map, const Eigen::Vector3d& origin_odom, double max_distance) {
  const double max_squared = max_distance * max_distance;
  std::erase_if(map.voxels, [&](const auto& entry) {
    return entry.second.empty() || (entry.second.front() - origin_odom).squaredNorm() > max_squared;
  });
}

std::optional<Plane> plane_near(const VoxelMap& map, const Eigen::Vector3d& q, double max_distance,
                                int neighbours, double max_flatness, double max_point_share) {
  constexpr int kMaxNeighbours = 16;
  const int k_wanted = std::clamp(neighbours, 5, kMaxNeighbours);
  // The k nearest, kept sorted by squared distance (insertion: k is small).
  std::array<std::pair<double, const Eigen::Vector3d*>, kMaxNeighbours> nearest;
  int k = 0;
  const double max_squared = max_distance * max_distance;
  // The 2 x 2 x 2 voxels around the voxel corner nearest q: every point within half a voxel of
  // q in each axis is among them.
  const Eigen::Vector3d scaled = q / map.voxel_size;
  const Eigen::Vector3i home = scaled.array().floor().cast<int>();
  Eigen::Vector3i step;
  for (int a = 0; a < 3; ++a) step(a) = scaled(a) - home(a) < 0.5 ? -1 : 1;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3i v(home.x() + (corner & 1 ? step.x() : 0),
                            home.y() + (corner & 2 ? step.y() : 0),
                            home.z() + (corner & 4 ? step.z() : 0));
    const auto it = map.voxels.find(v);
    if (it == map.voxels.end()) continue;
    for (const Eigen::Vector3d& p : it->second) {
      const double d2 = (p - q).squaredNorm();
      if (d2 > max_squared || (k == k_wanted && d2 >= nearest[k - 1].first)) continue;
      int at = k < k_wanted ? k++ : k - 1;
      while (at > 0 && nearest[at - 1].first > d2) {
        nearest[at] = nearest[at - 1];
        --at;
      }
      nearest[at] = {d2, &p};
    }
  }
  if (k < 5) return std::nullopt;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i = 0; i < k; ++i) mean += *nearest[i].second;
  mean /= k;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (int i = 0; i < k; ++i) {
    const Eigen::Vector3d d = *nearest[i].second - mean;
    scatter += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  eigen.computeDirect(scatter);
  const Eigen::Vector3d& lambda = eigen.eigenvalues();  // ascending
  if (!(lambda(1) > 0)) return std::nullopt;
  Plane plane;
  plane.flatness = std::max(lambda(0), 0.0) / lambda(1);
  if (plane.flatness > max_flatness) return std::nullopt;
  // Points along a line (one scan ring on a far wall) fix no normal about the line: a normal
  // from them would constrain a direction the surface does not.
  if (lambda(1) < kMinSpread * lambda(2)) return std::nullopt;
  // One point holding most of the spread across the major axis alone decides the normal's tilt
  // about that axis: a scan line and a stray point of another surface (sparse rings at long
  // range). Such a normal constrains a direction the surface does not (doc/odometry.md, the
  // corridor). Without that point the others must still spread in two directions.
  const Eigen::Vector3d middle = eigen.eigenvectors().col(1);
  int lever = -1;
  double lever_u2 = max_point_share * lambda(1);
  for (int i = 0; i < k; ++i) {
    const double u = middle.dot(*nearest[i].second - mean);
    if (u * u > lever_u2) lever_u2 = u * u, lever = i;
  }
  if (lever >= 0) {
    Eigen::Vector3d rest_mean = Eigen::Vector3d::Zero();
    for (int i = 0; i < k; ++i)
      if (i != lever) rest_mean += *nearest[i].second;
    rest_mean /= k - 1;
    Eigen::Matrix3d rest = Eigen::Matrix3d::Zero();
    for (int i = 0; i < k; ++i) {
      if (i == lever) continue;
      const Eigen::Vector3d d = *nearest[i].second - rest_mean;
      rest += d * d.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> rest_eigen;
    rest_eigen.computeDirect(rest, Eigen::EigenvaluesOnly);
    const Eigen::Vector3d& mu = rest_eigen.eigenvalues();
    if (mu(1) < kMinSpread * mu(2)) return std::nullopt;
  }
  plane.normal = eigen.eigenvectors().col(0).normalized();
  plane.point = mean;
  return plane;
}

}  // namespace rigcal::lidar
