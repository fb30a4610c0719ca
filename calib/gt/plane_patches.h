#pragma once
// The planar patches of the LiDAR bundle adjustment (doc/ground-truth.md): a map's points split
// as a kd-tree whose leaves are planes. A node is split in two at its centroid, across its
// largest principal axis, until it is small and flat enough to be one plane (or too few points
// are left); the association of the scans' points to planes then comes with the split.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace rigcal::gt {

struct PatchConfig {
  double max_size_m = 2.0;  // a leaf's extent along its largest axis at most this
  // Its points' standard deviation along the normal at most this: loose, for the scans of a
  // window are offset from each other before the adjustment.
  double max_thickness_m = 0.05;
  // Each scan's own points of a leaf (the whole leaf when no scans are given) at most this thick
  // about their own plane: an offset between scans is what the adjustment removes, a leaf that
  // one scan sees bent (an edge, a corner) is not a plane. Twice the OS0's 1 cm range noise.
  double max_scan_thickness_m = 0.02;
  size_t min_points = 20;  // fewer points: the node is dropped
  // A leaf whose middle principal variance is under this fraction of the largest is a line (a
  // pole, an edge), not a plane: its normal is not determined. It is split further.
  double min_middle_ratio = 0.05;
  // A leaf must be flat against its own width too: the standard deviation along its middle axis
  // at least this many times its thickness (a short piece of a noisy pole is a blob, not a
  // plane, whatever its thickness).
  double min_width_over_thickness = 5.0;
  // And without stray points: every point within this many thicknesses of the plane (a leaf at
  // an edge, mostly one face with a few points of the other, is thin on average but not flat).
  // Gaussian noise reaches 4.5 sigma once in 150,000 points; scans offset from each other form
  // layers within about one thickness.
  double max_distance_over_thickness = 4.5;
  int max_depth = 40;
};

struct PlanePatch {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  double thickness_m = 0;         // the points' standard deviation along the normal
  std::vector<uint32_t> members;  // indices into the points split
};

// The patches of `points`; a point belongs to at most one of them. `scan_of_point`, when given,
// names each point's scan (for max_scan_thickness_m).
std::vector<PlanePatch> plane_patches(const std::vector<Eigen::Vector3d>& points,
                                      const PatchConfig& config,
                                      const std::vector<uint32_t>* scan_of_point = nullptr);

// The plane through some points: centroid, the unit normal (the smallest principal axis), the
// largest principal axis, and the principal variances in increasing order.
struct PlaneFit {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d major_axis = Eigen::Vector3d::UnitX();
  Eigen::Vector3d variances = Eigen::Vector3d::Zero();
};
PlaneFit fit_plane(const std::vector<Eigen::Vector3d>& points,
                   const std::vector<uint32_t>& members);

}  // namespace rigcal::gt
