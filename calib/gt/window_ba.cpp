#include "rigcal/gt/window_ba.h"

#include <ceres/ceres.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <thread>
#include <unordered_map>

#include "rigcal/core/error.h"
#include "rigcal/gt/point_to_plane_error.h"
#include "rigcal/lidar/preprocess.h"

namespace rigcal::gt {
namespace {

// One residual: point `index` of scan `scan` on plane `plane`.
struct Association {
  uint32_t scan = 0, index = 0, plane = 0;
};
struct Associations {
  std::vector<PlanePatch> planes;  // those seen by two scans or more; their members cleared
  std::vector<Association> points;
};

// The patches of the scans placed by their poses, and the points kept of each.
Associations associate(const std::vector<std::vector<Eigen::Vector3d>>& points,
                       const std::vector<SE3>& T_world_lidar, const WindowBaConfig& config) {
  std::vector<Eigen::Vector3d> world;
  std::vector<uint32_t> scan_of_point, index_in_scan;
  for (size_t k = 0; k < points.size(); ++k) {
    for (size_t i = 0; i < points[k].size(); ++i) {
      world.push_back(T_world_lidar[k] * points[k][i]);
      scan_of_point.push_back(uint32_t(k));
      index_in_scan.push_back(uint32_t(i));
    }
  }
  Associations out;
  std::unordered_map<uint32_t, std::vector<uint32_t>> by_scan;
  for (PlanePatch& patch : plane_patches(world, config.patches, &scan_of_point)) {
    by_scan.clear();
    for (uint32_t m : patch.members) by_scan[scan_of_point[m]].push_back(index_in_scan[m]);
    size_t scans = 0;
    for (const auto& [scan, members] : by_scan)
      scans += members.size() >= config.min_points_per_scan;
    if (scans < 2) continue;
    const uint32_t plane = uint32_t(out.planes.size());
    for (const auto& [scan, members] : by_scan) {
      if (members.size() < config.min_points_per_scan) continue;
      const size_t n = std::min(members.size(), config.max_points_per_scan);
      for (size_t j = 0; j < n; ++j)
        out.points.push_back({scan, members[j * members.size() / n], plane});
    }
    patch.members.clear();
    out.planes.push_back(std::move(patch));
  }
  return out;
}

// The points' rms distance to their patches' planes (the planes as found).
double rms_distance(const Associations& a, const std::vector<std::vector<Eigen::Vector3d>>& points,
                    const std::vector<SE3>& T_world_lidar) {
  if (a.points.empty()) return 0;
  double sum = 0;
  for (const Association& r : a.points) {
    const PlanePatch& plane = a.planes[r.plane];
    const double d =
        plane.normal.dot(T_world_lidar[r.scan] * points[r.scan][r.index] - plane.centroid);
    sum += d * d;
  }
  return std::sqrt(sum / double(a.points.size()));
}

}  // namespace

WindowBaResult window_ba(const std::vector<std::vector<Eigen::Vector3d>>& points_lidar,
                         const std::vector<SE3>& T_world_lidar, const WindowBaConfig& config) {
  if (points_lidar.size() != T_world_lidar.size())
    throw Error("window bundle adjustment: one pose a scan is needed");
  WindowBaResult out;
  out.T_world_lidar = T_world_lidar;
  if (points_lidar.size() < 2) return out;
  std::vector<std::vector<Eigen::Vector3d>> points;
  for (const auto& scan : points_lidar)
    points.push_back(lidar::voxel_sample(scan, config.voxel_size_m));

  std::vector<Eigen::Quaterniond> q(points.size());
  std::vector<Eigen::Vector3d> t(points.size());
  for (size_t k = 0; k < points.size(); ++k) {
    q[k] = Eigen::Quaterniond(T_world_lidar[k].R).normalized();
    t[k] = T_world_lidar[k].t;
  }
  for (out.rounds = 0; out.rounds < config.rounds;) {
    const Associations a = associate(points, out.T_world_lidar, config);
    if (out.rounds == 0) out.rms_before_m = rms_distance(a, points, out.T_world_lidar);
    ++out.rounds;
    if (a.points.empty()) break;
    // The planes are estimated with the poses (not held at their fits: holding them, each round
    // would move the scans only part of the way towards the first one).
    // Each plane one block (its normal, then its offset): the Schur solver eliminates the planes,
    // which needs no two of its blocks in one residual.
    std::vector<Eigen::Vector4d> plane(a.planes.size());
    for (size_t j = 0; j < a.planes.size(); ++j) plane[j] << a.planes[j].normal, 0.0;
    ceres::Problem problem;
    auto* ordering = new ceres::ParameterBlockOrdering;
    for (const Association& r : a.points) {
      auto* cost =
          new ceres::AutoDiffCostFunction<PointToPlaneError, 1, 4, 3, 4>(new PointToPlaneError{
              points[r.scan][r.index], a.planes[r.plane].centroid, 1.0 / config.point_sigma_m});
      problem.AddResidualBlock(cost, new ceres::HuberLoss(config.huber_sigmas),
                               q[r.scan].coeffs().data(), t[r.scan].data(), plane[r.plane].data());
    }
    for (size_t j = 0; j < a.planes.size(); ++j) {
      problem.SetManifold(
          plane[j].data(),
          new ceres::ProductManifold<ceres::SphereManifold<3>, ceres::EuclideanManifold<1>>{});
      ordering->AddElementToGroup(plane[j].data(), 0);
    }
    for (size_t k = 0; k < points.size(); ++k) {
      if (!problem.HasParameterBlock(q[k].coeffs().data())) continue;
      problem.SetManifold(q[k].coeffs().data(), new ceres::EigenQuaternionManifold);
      ordering->AddElementToGroup(q[k].coeffs().data(), 1);
      ordering->AddElementToGroup(t[k].data(), 1);
    }
    if (problem.HasParameterBlock(q[0].coeffs().data())) {
      problem.SetParameterBlockConstant(q[0].coeffs().data());
      problem.SetParameterBlockConstant(t[0].data());
    }
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_SCHUR;  // the planes eliminated, the poses solved
    options.linear_solver_ordering.reset(ordering);
    options.max_num_iterations = config.max_iterations;
    options.num_threads = int(std::max(1u, std::thread::hardware_concurrency()));
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    if (!summary.IsSolutionUsable())
      throw Error("window bundle adjustment: the solve failed: " + summary.message);
    double moved = 0;
    for (size_t k = 1; k < points.size(); ++k) {
      const SE3 T = SE3::from_quaternion(q[k].normalized(), t[k]);
      moved = std::max({moved, (T.t - out.T_world_lidar[k].t).norm(),
                        10.0 * rotation_angle(T.R * out.T_world_lidar[k].R.transpose())});
      out.T_world_lidar[k] = T;
    }
    out.patches = a.planes.size();
    out.residuals = a.points.size();
    if (moved < config.converged_m) break;
  }
  out.rms_after_m =
      rms_distance(associate(points, out.T_world_lidar, config), points, out.T_world_lidar);
  return out;
}

}  // namespace rigcal::gt
