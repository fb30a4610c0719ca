#pragma once
// The local map of the LiDAR odometry (doc/odometry.md): points in the odometry frame hashed into
// cubic voxels, a few a voxel, the voxels beyond the sensor's reach dropped as it moves (the map
// of KISS-ICP), and the plane through the map points nearest a query point, which gives the
// point-to-plane residual.
#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <vector>

namespace rigcal::lidar {

struct VoxelHash {
  size_t operator()(const Eigen::Vector3i& v) const {
    return static_cast<size_t>(v.x()) * 73856093u ^ static_cast<size_t>(v.y()) * 19349669u ^
           static_cast<size_t>(v.z()) * 83492791u;
  }
};

struct VoxelMap {
  double voxel_size = 1.0;  // m
  size_t max_points_per_voxel = 20;
  // A point closer than this to one of its voxel's points is not added: the same surface measured
  // again from nearly the same place adds no geometry, only the range noise spread along the
  // rays (KISS-ICP's spacing).
  double min_point_spacing = 0.0;
  // The voxels that hold points, each its key and its points in the order they were added, in an
  // open-addressing table (a power of two slots, at most half of them used, linear probing; a
  // slot without points is free): a lookup is a multiplication and, mostly, one slot read, where
  // std::unordered_map divides by its prime bucket count and follows a chain of nodes (the
  // lookups are most of the odometry's time; doc/performance.md).
  struct Voxel {
    Eigen::Vector3i key = Eigen::Vector3i::Zero();
    std::vector<Eigen::Vector3d> points;
  };
  std::vector<Voxel> slots;
  size_t voxels = 0;  // slots in use
};

Eigen::Vector3i voxel_of(const Eigen::Vector3d& p, double voxel_size);
size_t point_count(const VoxelMap& map);
// The points of voxel `key`, none when it holds none.
const std::vector<Eigen::Vector3d>* voxel_points(const VoxelMap& map, const Eigen::Vector3i& key);
// Adds points (odometry frame) to voxels not yet full.
void add_points(VoxelMap& map, const std::vector<Eigen::Vector3d>& points_odom);
// Drops the voxels whose first point is farther than `max_distance` from `origin_odom`.
void remove_far(VoxelMap& map, const Eigen::Vector3d& origin_odom, double max_distance);
// Drops every voxel (the settings kept).
void clear(VoxelMap& map);

// A plane through map points: unit normal, a point on it (their centroid), and how flat the
// points lie (the smallest over the middle eigenvalue of their scatter, 0 for a perfect plane).
struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double flatness = 0;
};
// The plane through the `neighbours` map points nearest q within `max_distance`, searched in the
// 8 voxels around the voxel corner nearest q (all points within half a voxel of q); none when fewer
// than 5 are found, they do not lie on a plane (flatness over `max_flatness`), they lie along a
// line (the middle scatter eigenvalue under 0.05 of the largest: a normal about the line is not
// determined), or one of them holds more than `max_point_share` of the middle eigenvalue (the
// tilt about the line would be that one point's).
std::optional<Plane> plane_near(const VoxelMap& map, const Eigen::Vector3d& q, double max_distance,
                                int neighbours, double max_flatness, double max_point_share = 1.0);

}  // namespace rigcal::lidar
