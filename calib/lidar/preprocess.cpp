#include "rigcal/lidar/preprocess.h"

#include <unordered_set>

#include "rigcal/lidar/voxel_map.h"

namespace rigcal::lidar {

SE3 motion_fraction(const SE3& T_start_end, double fraction) {
  SE3 T;
  T.R = rotation_from_vector(fraction * rotation_vector(T_start_end.R));
  T.t = fraction * T_start_end.t;
  return T;
}

std::vector<Eigen::Vector3d> deskewed_points(const Scan& scan, const SE3& T_start_next,
                                             double period_s, double min_range, double max_range) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(scan.points.size());
  const double min_squared = min_range * min_range, max_squared = max_range * max_range;
  const bool moving = scan.point_times && period_s > 0 && !(T_start_next == SE3::identity());
  // Rotation vector and translation per second of sweep: one small exp a point.
  const Eigen::Vector3d phi = moving ? Eigen::Vector3d(rotation_vector(T_start_next.R) / period_s)
                                     : Eigen::Vector3d::Zero();
  const Eigen::Vector3d v =
      moving ? Eigen::Vector3d(T_start_next.t / period_s) : Eigen::Vector3d::Zero();
  for (const ScanPoint& point : scan.points) {
    const Eigen::Vector3d p = point.p.cast<double>();
    const double r2 = p.squaredNorm();
    if (r2 < min_squared || r2 > max_squared) continue;
    if (!moving || point.t_ns == 0) {
      out.push_back(p);
      continue;
    }
    const double t = static_cast<double>(point.t_ns) * 1e-9;
    out.push_back(rotation_from_vector(t * phi) * p + t * v);
  }
  return out;
}

std::vector<Eigen::Vector3d> voxel_downsample(const std::vector<Eigen::Vector3d>& points,
                                              double voxel_size) {
  std::unordered_set<Eigen::Vector3i, VoxelHash> seen;
  seen.reserve(points.size());
  std::vector<Eigen::Vector3d> out;
  out.reserve(points.size() / 2);
  for (const Eigen::Vector3d& p : points)
    if (seen.insert(voxel_of(p, voxel_size)).second) out.push_back(p);
  return out;
}

}  // namespace rigcal::lidar
