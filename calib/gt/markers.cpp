#include "rigcal/gt/markers.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "rigcal/core/error.h"
#include "rigcal/lidar/voxel_map.h"

namespace rigcal::gt {

std::vector<BrightCluster> bright_clusters(const std::vector<Eigen::Vector3d>& bright,
                                           const MarkerConfig& config) {
  // Cells of the gap's size; touching occupied cells (26 neighbours) join, by union-find over
  // the cells: linear in the points, however many of them a cell holds.
  std::unordered_map<Eigen::Vector3i, uint32_t, lidar::VoxelHash> cell_index;
  std::vector<uint32_t> cell_of(bright.size());
  std::vector<Eigen::Vector3i> cells;
  for (size_t i = 0; i < bright.size(); ++i) {
    const Eigen::Vector3i c = lidar::voxel_of(bright[i], config.cluster_gap_m);
    const auto [it, added] = cell_index.emplace(c, uint32_t(cells.size()));
    if (added) cells.push_back(c);
    cell_of[i] = it->second;
  }
  std::vector<uint32_t> parent(cells.size());
  for (uint32_t i = 0; i < parent.size(); ++i) parent[i] = i;
  auto root = [&](uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (uint32_t i = 0; i < cells.size(); ++i) {
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cell_index.find(cells[i] + Eigen::Vector3i(dx, dy, dz));
          if (it != cell_index.end()) parent[root(it->second)] = root(i);
        }
      }
    }
  }
  std::unordered_map<uint32_t, std::vector<uint32_t>> groups;
  for (uint32_t i = 0; i < bright.size(); ++i) groups[root(cell_of[i])].push_back(i);
  std::vector<BrightCluster> out;
  for (const auto& [r, members] : groups) {
    if (members.size() < config.min_points) continue;
    BrightCluster c;
    c.points = members.size();
    for (uint32_t i : members) c.centre += bright[i];
    c.centre /= double(members.size());
    double spread2 = 0;
    for (uint32_t i : members) {
      const double d2 = (bright[i] - c.centre).squaredNorm();
      spread2 += d2;
      c.extent_m = std::max(c.extent_m, std::sqrt(d2));
    }
    // The rms spread along one axis (of three) over the square root of the points.
    c.sigma_m = std::sqrt(spread2 / 3.0 / double(members.size())) / std::sqrt(double(c.points));
    if (c.extent_m <= config.max_extent_m) out.push_back(c);
  }
  std::sort(out.begin(), out.end(), [](const BrightCluster& a, const BrightCluster& b) {
    return a.points > b.points || (a.points == b.points && a.centre.x() < b.centre.x());
  });
  return out;
}

namespace {

// Depth-first assignment of markers to clusters (or to none), each new assignment checked
// against the survey's distances to the markers already assigned.
struct Search {
  const std::vector<BrightCluster>& clusters;
  const MarkerSurvey& survey;
  double tolerance;
  std::vector<std::vector<std::pair<size_t, double>>> distances_of;  // marker -> (other, m)
  std::vector<int> current, best;
  size_t best_found = 0;
  double best_cost = 0;
  std::vector<bool> used;
  size_t nodes = 0;

  void run(size_t marker, size_t found, double cost) {
    if (++nodes > 2'000'000) return;  // far more than any survey of tens of markers needs
    const size_t left = survey.ids.size() - marker;
    if (found + left < best_found) return;
    if (marker == survey.ids.size()) {
      if (found > best_found || (found == best_found && cost < best_cost)) {
        best_found = found;
        best_cost = cost;
        best = current;
      }
      return;
    }
    for (size_t c = 0; c < clusters.size(); ++c) {
      if (used[c]) continue;
      double added = 0;
      bool fits = true;
      for (const auto& [other, m] : distances_of[marker]) {
        if (other >= marker || current[other] < 0) continue;
        const double e = (clusters[c].centre - clusters[size_t(current[other])].centre).norm() - m;
        if (std::abs(e) > tolerance) {
          fits = false;
          break;
        }
        added += e * e;
      }
      if (!fits) continue;
      used[c] = true;
      current[marker] = int(c);
      run(marker + 1, found + 1, cost + added);
      used[c] = false;
      current[marker] = -1;
    }
    run(marker + 1, found, cost);  // this marker not found
  }
};

}  // namespace

MarkerCheck check_markers(const std::vector<BrightCluster>& clusters, const MarkerSurvey& survey,
                          const MarkerConfig& config) {
  if (survey.ids.size() < 2) throw Error("the markers' survey names fewer than 2 markers");
  Search s{clusters, survey, config.tolerance_m, {}, {}, {}, 0, 0, {}, 0};
  s.distances_of.resize(survey.ids.size());
  for (const MarkerSurvey::Distance& d : survey.distances) {
    s.distances_of[d.a].push_back({d.b, d.m});
    s.distances_of[d.b].push_back({d.a, d.m});
  }
  s.current.assign(survey.ids.size(), -1);
  s.best = s.current;
  s.used.assign(clusters.size(), false);
  s.run(0, 0, 0.0);
  MarkerCheck check;
  check.clusters = clusters;
  check.cluster_of = s.best;
  check.found = s.best_found;
  check.tolerance_m = config.tolerance_m;
  double sum2 = 0;
  for (const MarkerSurvey::Distance& d : survey.distances) {
    const int ca = check.cluster_of[d.a], cb = check.cluster_of[d.b];
    if (ca < 0 || cb < 0) continue;
    const BrightCluster &a = clusters[size_t(ca)], &b = clusters[size_t(cb)];
    MarkerDistanceCheck p{d.a, d.b, d.m, (a.centre - b.centre).norm(),
                          std::hypot(a.sigma_m, b.sigma_m)};
    const double e = p.estimated_m - p.measured_m;
    sum2 += e * e;
    check.max_error_m = std::max(check.max_error_m, std::abs(e));
    check.pairs.push_back(p);
  }
  if (!check.pairs.empty()) check.rms_error_m = std::sqrt(sum2 / double(check.pairs.size()));
  return check;
}

}  // namespace rigcal::gt
