#include "rigcal/gt/markers.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "rigcal/core/error.h"
#include "rigcal/lidar/voxel_map.h"

namespace rigcal::gt {

std::vector<BrightCluster> bright_clusters(const std::vector<Eigen::Vector3d>& bright,
                                           const MarkerConfig& config) {
  // Union-find over a grid of cells as large as the gap: only neighbouring cells can join.
  const double gap = config.cluster_gap_m, gap2 = gap * gap;
  std::unordered_map<Eigen::Vector3i, std::vector<uint32_t>, lidar::VoxelHash> cells;
  for (uint32_t i = 0; i < bright.size(); ++i) cells[lidar::voxel_of(bright[i], gap)].push_back(i);
  std::vector<uint32_t> parent(bright.size());
  for (uint32_t i = 0; i < parent.size(); ++i) parent[i] = i;
  auto root = [&](uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (const auto& [cell, members] : cells) {
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells.find(cell + Eigen::Vector3i(dx, dy, dz));
          if (it == cells.end()) continue;
          // Each cell pair once; within a cell, the first point is joined by every near one.
          for (uint32_t i : members) {
            for (uint32_t j : it->second) {
              if (j <= i || root(i) == root(j)) continue;
              if ((bright[i] - bright[j]).squaredNorm() <= gap2) parent[root(j)] = root(i);
            }
          }
        }
      }
    }
  }
  std::unordered_map<uint32_t, std::vector<uint32_t>> groups;
  for (uint32_t i = 0; i < bright.size(); ++i) groups[root(i)].push_back(i);
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
