#pragma once
// The ground truth's files (doc/ground-truth.md): the trajectory in VBR's ground-truth format
// (TUM with the header `#timestamp tx ty tz qx qy qz qw`, the LiDAR frame) and each pose's
// standard deviations.
#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "rigcal/core/trajectory.h"
#include "rigcal/gt/markers.h"

namespace rigcal::io {

// VBR's <seq>_gt.txt: the header line, then one pose a line, stamps in seconds to the nanosecond.
std::string ground_truth_to_text(const Trajectory& T_world_lidar);

// One line a pose: the stamp, then the standard deviations of the position (x y z, m) and of
// the rotation (about x y z, deg) in the world frame, from each 6 x 6 covariance (rigcal's
// tangent: rotation first, left perturbation), after a header line naming the columns.
std::string pose_sigmas_to_text(const Trajectory& T_world_lidar,
                                const std::vector<Eigen::Matrix<double, 6, 6>>& covariance);

// The markers' survey (`--markers`): a CSV (commas or spaces), `#` comments, a header line
// allowed; either `id,x,y,z` a marker (coordinates in m, in any frame: a total station's) or
// `id_a,id_b,distance` a measured distance (m), not both. Throws rigcal::Error naming the file
// and line: a row of another width, a number that is not one, an id given twice, a distance
// between a marker and itself or not positive, fewer than 2 markers.
gt::MarkerSurvey read_marker_survey(const std::filesystem::path& path);
// The same from the file's text; `source` names it in messages.
gt::MarkerSurvey parse_marker_survey(std::string_view text, const std::string& source);

// A binary little-endian PLY of the points (float x y z, float intensity), for the map.
std::string point_cloud_to_ply(const std::vector<Eigen::Vector3d>& points,
                               const std::vector<float>& intensity);

}  // namespace rigcal::io
