#pragma once
// Preprocessing of a sweep for the LiDAR odometry (doc/odometry.md): the range limits, the
// voxel downsampling of KISS-ICP (the first point of each voxel) and the deskew: every point
// moved from the sensor's pose at its own time to the pose at the sweep's stamp, with the motion
// taken as constant over the sweep.
#include <Eigen/Core>
#include <vector>

#include "rigcal/core/scan.h"
#include "rigcal/core/se3.h"

namespace rigcal::lidar {

// The pose `fraction` of a constant motion `T_start_end` along (fraction 0: identity, 1: the
// motion itself; any real fraction): rotation exp(f log R), translation f t.
SE3 motion_fraction(const SE3& T_start_end, double fraction);

// The first point of every voxel of the given size among those with a range in
// [min_range, max_range], in input order, with its time.
std::vector<ScanPoint> voxel_sample(const std::vector<ScanPoint>& points, double voxel_size,
                                    double min_range, double max_range);

// The same for points without times or range limits (the bundle adjustment's scans).
std::vector<Eigen::Vector3d> voxel_sample(const std::vector<Eigen::Vector3d>& points,
                                          double voxel_size);

// The points moved to the sensor's pose at the scan's stamp (see deskewed_points); as they are
// where `point_times` is false.
std::vector<Eigen::Vector3d> deskew(const std::vector<ScanPoint>& points, const SE3& T_start_next,
                                    double period_s, bool point_times);

// The scan's points in the sensor frame at the scan's stamp, those with a range in
// [min_range, max_range] only. `T_start_next` is the sensor's motion from this scan's stamp over
// `period_s` (the next stamp's pose in this one's frame); a point measured t after the stamp is
// moved by motion_fraction(T_start_next, t / period_s). Scans without point times, or an identity
// motion, are only range-filtered.
std::vector<Eigen::Vector3d> deskewed_points(const Scan& scan, const SE3& T_start_next,
                                             double period_s, double min_range, double max_range);

}  // namespace rigcal::lidar
