#include "rigcal/lidar/voxel_map.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <utility>

namespace rigcal::lidar {

namespace {
constexpr double kMinSpread = 0.05;  // middle over largest scatter eigenvalue of a plane's points
constexpr size_t kMinSlots = 64;

// The slot where the search for `key` starts: VoxelHash's mix spread over the table's bits by a
// multiplication (Fibonacci hashing), the table's size a power of two.
size_t first_slot(const Eigen::Vector3i& key, size_t slots) {
  const uint64_t h = uint64_t(VoxelHash{}(key)) * 0x9E3779B97F4A7C15ull;
  return size_t(h >> 32) & (slots - 1);
}

// The slot holding `key`, or the free slot where it would go, searched from slot `i` on.
size_t probe(const std::vector<VoxelMap::Voxel>& slots, size_t i, const Eigen::Vector3i& key) {
  while (!slots[i].points.empty() && slots[i].key != key) i = (i + 1) & (slots.size() - 1);
  return i;
}
size_t slot_of(const std::vector<VoxelMap::Voxel>& slots, const Eigen::Vector3i& key) {
  return probe(slots, first_slot(key, slots.size()), key);
}

// The table rebuilt with `size` slots (a power of two, more than twice the voxels kept), each
// voxel moved to its slot there; those `keep` refuses dropped.
template <class Keep>
void rebuild(VoxelMap& map, size_t size, const Keep& keep) {
  std::vector<VoxelMap::Voxel> old = std::exchange(map.slots, std::vector<VoxelMap::Voxel>(size));
  map.voxels = 0;
  for (VoxelMap::Voxel& v : old) {
    if (v.points.empty() || !keep(v)) continue;
    map.slots[slot_of(map.slots, v.key)] = std::move(v);
    ++map.voxels;
  }
}

size_t slots_for(size_t voxels) { return std::max(kMinSlots, std::bit_ceil(2 * voxels + 1)); }

}  // namespace

Eigen::Vector3i voxel_of(const Eigen::Vector3d& p, double voxel_size) {
  return (p / voxel_size).array().floor().cast<int>();
}

size_t point_count(const VoxelMap& map) {
  size_t n = 0;
  for (const VoxelMap::Voxel& v : map.slots) n += v.points.size();
  return n;
}

const std::vector<Eigen::Vector3d>* voxel_points(const VoxelMap& map, const Eigen::Vector3i& key) {
  if (map.slots.empty()) return nullptr;
  const VoxelMap::Voxel& v = map.slots[slot_of(map.slots, key)];
  return v.points.empty() ? nullptr : &v.points;
}

void add_points(VoxelMap& map, const std::vector<Eigen::Vector3d>& points_odom) {
  if (map.max_points_per_voxel == 0) return;
  const double spacing2 = map.min_point_spacing * map.min_point_spacing;
  for (const Eigen::Vector3d& p : points_odom) {
    if (2 * (map.voxels + 1) > map.slots.size())
      rebuild(map, slots_for(map.voxels + 1), [](const VoxelMap::Voxel&) { return true; });
    const Eigen::Vector3i key = voxel_of(p, map.voxel_size);
    VoxelMap::Voxel& voxel = map.slots[slot_of(map.slots, key)];
    if (voxel.points.empty()) {
      voxel.key = key;
      ++map.voxels;
    } else if (voxel.points.size() >= map.max_points_per_voxel ||
               (spacing2 > 0 && std::any_of(voxel.points.begin(), voxel.points.end(),
                                            [&](const Eigen::Vector3d& v) {
                                              return (v - p).squaredNorm() < spacing2;
                                            }))) {
      continue;
    }
    voxel.points.push_back(p);
  }
}

void remove_far(VoxelMap& map, const Eigen::Vector3d& origin_odom, double max_distance) {
  const double max_squared = max_distance * max_distance;
  const auto near = [&](const VoxelMap::Voxel& v) {
    return (v.points.front() - origin_odom).squaredNorm() <= max_squared;
  };
  size_t kept = 0;
  for (const VoxelMap::Voxel& v : map.slots) kept += !v.points.empty() && near(v);
  if (kept == map.voxels) return;
  rebuild(map, slots_for(kept), near);
}

void clear(VoxelMap& map) {
  map.slots.clear();
  map.voxels = 0;
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
  // The eight slots, then the eight voxels' points, asked of the memory before any is read: the
  // map is larger than the caches, and the reads then wait for the memory together, not one
  // after the other.
  if (map.slots.empty()) return std::nullopt;
  std::array<Eigen::Vector3i, 8> keys;
  std::array<size_t, 8> slots;
  for (int corner = 0; corner < 8; ++corner) {
    keys[corner] = Eigen::Vector3i(home.x() + (corner & 1 ? step.x() : 0),
                                   home.y() + (corner & 2 ? step.y() : 0),
                                   home.z() + (corner & 4 ? step.z() : 0));
    slots[corner] = first_slot(keys[corner], map.slots.size());
    __builtin_prefetch(&map.slots[slots[corner]]);
  }
  std::array<const std::vector<Eigen::Vector3d>*, 8> voxels;
  for (int corner = 0; corner < 8; ++corner) {
    const VoxelMap::Voxel& voxel = map.slots[probe(map.slots, slots[corner], keys[corner])];
    voxels[corner] = voxel.points.empty() ? nullptr : &voxel.points;
    if (voxels[corner]) __builtin_prefetch(voxel.points.data());
  }
  for (int corner = 0; corner < 8; ++corner) {
    if (!voxels[corner]) continue;
    for (const Eigen::Vector3d& p : *voxels[corner]) {
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
