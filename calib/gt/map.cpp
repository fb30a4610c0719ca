#include "rigcal/gt/map.h"

#include <algorithm>
#include <unordered_map>

#include "rigcal/core/error.h"
#include "rigcal/lidar/preprocess.h"
#include "rigcal/lidar/voxel_map.h"

namespace rigcal::gt {

namespace {

struct VoxelSum {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double intensity = 0;
  size_t n = 0;
};

double median_intensity(const Scan& scan) {
  std::vector<float> v;
  v.reserve(scan.points.size());
  for (const ScanPoint& p : scan.points) v.push_back(p.intensity);
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

}  // namespace

LidarMap build_map(const std::function<std::optional<Scan>()>& next_scan,
                   const Trajectory& T_world_lidar, const MapConfig& config,
                   const report::Progress& progress) {
  if (T_world_lidar.size() < 2) throw Error("the map needs a trajectory of at least 2 poses");
  LidarMap map;
  map.voxel_size_m = config.voxel_size_m;
  map.bright_intensity = config.bright_intensity;
  std::unordered_map<Eigen::Vector3i, VoxelSum, lidar::VoxelHash> voxels;
  const std::vector<Time>& stamps = T_world_lidar.stamps;
  const std::vector<SE3>& poses = T_world_lidar.T_world_body;
  size_t k = 0;
  while (std::optional<Scan> scan = next_scan()) {
    while (k < stamps.size() && stamps[k] < scan->stamp) ++k;
    if (k == stamps.size() || stamps[k] != scan->stamp) {
      ++map.scans_unused;
      continue;
    }
    if (map.bright_intensity <= 0) {
      map.bright_intensity = std::max(config.bright_factor * median_intensity(*scan), 1e-6);
    }
    // The motion over the sweep: to the next pose, or the last one repeated at the end.
    const size_t a = k + 1 < stamps.size() ? k : k - 1;
    const SE3 T_start_next = poses[a].inverse() * poses[a + 1];
    const double period_s = (stamps[a + 1] - stamps[a]).seconds();
    const SE3& T_world_start = poses[k];
    const double min2 = config.min_range_m * config.min_range_m,
                 max2 = config.max_range_m * config.max_range_m;
    // A column's points share their time: its pose is computed once.
    int64_t t_ns = -1;
    SE3 T_world_point = T_world_start;
    for (const ScanPoint& q : scan->points) {
      const double r2 = q.p.cast<double>().squaredNorm();
      if (r2 < min2 || r2 > max2) continue;
      if (scan->point_times && period_s > 0 && q.t_ns != t_ns) {
        t_ns = q.t_ns;
        T_world_point =
            T_world_start * lidar::motion_fraction(T_start_next, 1e-9 * double(t_ns) / period_s);
      }
      const Eigen::Vector3d p = T_world_point * q.p.cast<double>();
      VoxelSum& v = voxels[lidar::voxel_of(p, config.voxel_size_m)];
      v.sum += p;
      v.intensity += q.intensity;
      ++v.n;
      if (q.intensity >= map.bright_intensity) map.bright.push_back(p);
    }
    ++map.scans;
    map.scan_points += scan->points.size();
    report::tell(progress, "building the map", k + 1, stamps.size());
  }
  map.points.reserve(voxels.size());
  map.intensity.reserve(voxels.size());
  for (const auto& [key, v] : voxels) {
    map.points.push_back(v.sum / double(v.n));
    map.intensity.push_back(static_cast<float>(v.intensity / double(v.n)));
  }
  return map;
}

}  // namespace rigcal::gt
