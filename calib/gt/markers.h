#pragma once
// The survey markers' check of a ground truth (doc/ground-truth.md, "The map and the markers"),
// as the VBR paper validates its own: retro-reflective markers measured by a total station, and
// the distances between them in the estimated map against the measured ones. The markers are
// found in the map as clusters of bright points (map.h), each placed at its points' centroid;
// which cluster is which marker is decided by the measured distances alone (the survey's frame
// need not be the map's), the assignment that explains the most markers within a tolerance and,
// among those, with the smallest distance errors.
#include <Eigen/Core>
#include <string>
#include <vector>

namespace rigcal::gt {

// What a total station gives: the markers' coordinates in its own frame, or distances between
// them.
struct MarkerSurvey {
  std::vector<std::string> ids;
  std::vector<Eigen::Vector3d> positions;  // one a marker, or empty when distances are given
  struct Distance {
    size_t a = 0, b = 0;  // into ids
    double m = 0;
  };
  std::vector<Distance> distances;  // every pair when positions are given
};

// A cluster of bright map points: its centroid, its size, and the centroid's standard error
// (the points' rms spread about it over the square root of their number).
struct BrightCluster {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  size_t points = 0;
  double extent_m = 0;  // the largest distance of a point from the centre
  double sigma_m = 0;
};

struct MarkerConfig {
  double cluster_gap_m = 0.1;  // bright points in touching cells of this size join a cluster
  size_t min_points = 20;      // smaller clusters are noise, not markers
  double max_extent_m = 1.0;   // larger ones are not a marker (a bright sign, a window)
  double tolerance_m = 0.15;   // a distance off by more than this rules an assignment out
};

// Clusters of the bright points (their cells of cluster_gap_m, touching by a face, an edge or a
// corner), largest first; those under min_points or over max_extent_m dropped.
std::vector<BrightCluster> bright_clusters(const std::vector<Eigen::Vector3d>& bright,
                                           const MarkerConfig& config);

struct MarkerDistanceCheck {
  size_t a = 0, b = 0;  // into the survey's ids
  double measured_m = 0, estimated_m = 0;
  double sigma_m = 0;  // of estimated_m, from the two centroids' sigmas
};

struct MarkerCheck {
  std::vector<int> cluster_of;  // a marker's cluster, -1 not found
  std::vector<BrightCluster> clusters;
  std::vector<MarkerDistanceCheck> pairs;  // the survey's distances between markers found
  size_t found = 0;
  double rms_error_m = 0, max_error_m = 0;  // estimated - measured, over the pairs
  double tolerance_m = 0;                   // the assignment's (MarkerConfig)
};

// Throws rigcal::Error when the survey names fewer than 2 markers.
MarkerCheck check_markers(const std::vector<BrightCluster>& clusters, const MarkerSurvey& survey,
                          const MarkerConfig& config);

}  // namespace rigcal::gt
