#include "rigcal/gt/plane_patches.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace rigcal::gt {
namespace {

struct Splitter {
  const std::vector<Eigen::Vector3d>& points;
  const PatchConfig& config;
  const std::vector<uint32_t>* scan_of_point;
  std::vector<PlanePatch>& out;

  // Every scan's own points of the leaf (at least 5 of them) flat within max_scan_thickness_m.
  bool flat_in_every_scan(const std::vector<uint32_t>& members, const PlaneFit& fit) const {
    const double limit2 = config.max_scan_thickness_m * config.max_scan_thickness_m;
    if (!scan_of_point) return fit.variances(0) <= limit2;
    std::unordered_map<uint32_t, std::vector<uint32_t>> by_scan;
    for (uint32_t i : members) by_scan[(*scan_of_point)[i]].push_back(i);
    for (const auto& [scan, own] : by_scan)
      if (own.size() >= 5 && fit_plane(points, own).variances(0) > limit2) return false;
    return true;
  }

  void split(std::vector<uint32_t> members, int depth) const {
    if (members.size() < config.min_points) return;
    const PlaneFit fit = fit_plane(points, members);
    const Eigen::Vector3d& v = fit.variances;
    // A uniform spread of length L has variance L^2 / 12.
    const double extent = std::sqrt(12.0 * std::max(v(2), 0.0));
    if (extent <= config.max_size_m && std::sqrt(std::max(v(0), 0.0)) <= config.max_thickness_m &&
        v(1) >= config.min_middle_ratio * v(2) &&
        v(1) >= std::pow(config.min_width_over_thickness, 2) * v(0)) {
      const double thickness = std::sqrt(std::max(v(0), 0.0));
      double farthest = 0;
      for (uint32_t i : members)
        farthest = std::max(farthest, std::abs(fit.normal.dot(points[i] - fit.centroid)));
      if (farthest <= config.max_distance_over_thickness * thickness &&
          flat_in_every_scan(members, fit)) {
        out.push_back({fit.normal, fit.centroid, thickness, std::move(members)});
        return;
      }
    }
    if (depth >= config.max_depth) return;
    const Eigen::Vector3d& axis = fit.major_axis;
    std::vector<uint32_t> low, high;
    for (uint32_t i : members) ((points[i] - fit.centroid).dot(axis) < 0 ? low : high).push_back(i);
    if (low.empty() || high.empty()) return;
    members.clear();
    members.shrink_to_fit();
    split(std::move(low), depth + 1);
    split(std::move(high), depth + 1);
  }
};

}  // namespace

PlaneFit fit_plane(const std::vector<Eigen::Vector3d>& points,
                   const std::vector<uint32_t>& members) {
  PlaneFit fit;
  if (members.empty()) return fit;
  for (uint32_t i : members) fit.centroid += points[i];
  fit.centroid /= double(members.size());
  Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
  for (uint32_t i : members)
    c += (points[i] - fit.centroid) * (points[i] - fit.centroid).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(c / double(members.size()));
  fit.normal = eigen.eigenvectors().col(0);
  fit.major_axis = eigen.eigenvectors().col(2);
  fit.variances = eigen.eigenvalues();
  return fit;
}

std::vector<PlanePatch> plane_patches(const std::vector<Eigen::Vector3d>& points,
                                      const PatchConfig& config,
                                      const std::vector<uint32_t>* scan_of_point) {
  std::vector<PlanePatch> out;
  std::vector<uint32_t> all(points.size());
  for (size_t i = 0; i < points.size(); ++i) all[i] = uint32_t(i);
  Splitter{points, config, scan_of_point, out}.split(std::move(all), 0);
  return out;
}

}  // namespace rigcal::gt
