#include "rigcal/lidar/preprocess.h"

#include <cmath>
#include <unordered_set>

#include "rigcal/lidar/voxel_map.h"

namespace rigcal::lidar {

SE3 motion_fraction(const SE3& T_start_end, double fraction) {
  SE3 T;
  T.R = rotation_from_vector(fraction * rotation_vector(T_start_end.R));
  T.t = fraction * T_start_end.t;
  return T;
}

std::vector<ScanPoint> voxel_sample(const std::vector<ScanPoint>& points, double voxel_size,
                                    double min_range, double max_range) {
  const double min_squared = min_range * min_range, max_squared = max_range * max_range;
  std::unordered_set<Eigen::Vector3i, VoxelHash> seen;
  seen.reserve(points.size() / 4);
  std::vector<ScanPoint> out;
  for (const ScanPoint& point : points) {
    const Eigen::Vector3d p = point.p.cast<double>();
    const double r2 = p.squaredNorm();
    if (!(r2 >= min_squared && r2 <= max_squared)) continue;  // NaN too
    if (seen.insert(voxel_of(p, voxel_size)).second) out.push_back(point);
  }
  return out;
}

std::vector<Eigen::Vector3d> voxel_sample(const std::vector<Eigen::Vector3d>& points,
                                          double voxel_size) {
  std::unordered_set<Eigen::Vector3i, VoxelHash> seen;
  seen.reserve(points.size() / 4);
  std::vector<Eigen::Vector3d> out;
  for (const Eigen::Vector3d& p : points)
    if (seen.insert(voxel_of(p, voxel_size)).second) out.push_back(p);
  return out;
}

std::vector<Eigen::Vector3d> deskew(const std::vector<ScanPoint>& points, const SE3& T_start_next,
                                    double period_s, bool point_times) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(points.size());
  const bool moving = point_times && period_s > 0 && !(T_start_next == SE3::identity());
  // Per second of sweep: the rotation's angle about a fixed axis, and the translation. A point
  // t after the stamp turns by t * omega about the axis (Rodrigues' formula) and moves by t * v.
  const Eigen::Vector3d phi = rotation_vector(T_start_next.R);
  const double omega = moving ? phi.norm() / period_s : 0;
  const Eigen::Vector3d axis =
      phi.norm() > 0 ? Eigen::Vector3d(phi.normalized()) : Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d v =
      moving ? Eigen::Vector3d(T_start_next.t / period_s) : Eigen::Vector3d::Zero();
  for (const ScanPoint& point : points) {
    const Eigen::Vector3d p = point.p.cast<double>();
    if (!moving || point.t_ns == 0) {
      out.push_back(p);
      continue;
    }
    const double t = static_cast<double>(point.t_ns) * 1e-9, angle = t * omega;
    const double c = std::cos(angle), s = std::sin(angle);
    out.push_back(c * p + s * axis.cross(p) + (1 - c) * axis.dot(p) * axis + t * v);
  }
  return out;
}

std::vector<Eigen::Vector3d> deskewed_points(const Scan& scan, const SE3& T_start_next,
                                             double period_s, double min_range, double max_range) {
  const double min_squared = min_range * min_range, max_squared = max_range * max_range;
  std::vector<ScanPoint> kept;
  kept.reserve(scan.points.size());
  for (const ScanPoint& point : scan.points) {
    const double r2 = point.p.cast<double>().squaredNorm();
    if (r2 >= min_squared && r2 <= max_squared) kept.push_back(point);
  }
  return deskew(kept, T_start_next, period_s, scan.point_times);
}

}  // namespace rigcal::lidar
