#pragma once
// The LiDAR odometry of rigcal (doc/odometry.md): point-to-plane ICP of each deskewed sweep
// against a local voxel map, in the shape of KISS-ICP's pipeline, with the covariance and the
// degeneracy of every step. Each pose is the sensor's at the scan's stamp (the sweep's first
// point, Scan::stamp), the convention of VBR's ground truth.
#include <string>
#include <string_view>
#include <vector>

#include "rigcal/core/scan.h"
#include "rigcal/core/se3.h"
#include "rigcal/core/trajectory.h"
#include "rigcal/lidar/registration.h"
#include "rigcal/lidar/threshold.h"
#include "rigcal/lidar/voxel_map.h"

namespace rigcal::lidar {

struct OdometryConfig {
  double voxel_size_m = 1.0;  // the map's voxels; the sweep is sampled at 0.5 and 1.5 of it
  double min_range_m = 0.5, max_range_m = 100.0;
  size_t max_points_per_voxel = 20;
  double initial_threshold_m = 2.0, min_motion_m = 0.1;
  bool deskew = true;
  int deskew_passes = 2;  // 2: deskew again with the estimated motion and refine
  // Estimate each sweep's own motion with its pose (register_sweep) instead of taking the motion
  // of the step before it, with a loose prior about that step's motion of these sigmas (per
  // axis, over the sweep; chosen on a simulated walk, doc/odometry.md).
  bool estimate_sweep_motion = false;
  double sweep_motion_sigma_deg = 5.0, sweep_motion_sigma_m = 0.3;
  RegistrationConfig registration;
  // A step is called degenerate when the information's weakest direction holds less than this
  // fraction of its strongest (translation and rotation blocks separately), or the covariance's
  // largest translation variance is more than its inverse times the smallest.
  double degenerate_ratio = 0.01;
  // A step degenerate in translation gets this sigma (m) added along its weakest translation
  // direction in its covariance: the scene does not see the motion there (a corridor), and the
  // registration's own sigma would be far below its error (doc/odometry.md). 0 leaves it.
  double degenerate_sigma_m = 1.0;
  // A sweep is skipped (no pose, the map unchanged) when fewer of its registration points than
  // this fraction, or than `min_correspondences`, find a plane of the map near the prediction:
  // it shares no surface with the map (a gap in the recording, a blocked sensor).
  double min_overlap = 0.05;
  size_t min_correspondences = 30;
  // Added to every step's covariance (1 sigma on each rotation and translation axis): the errors
  // the registration's information does not hold (the map's own, from the earlier poses; the
  // deskew's). Set on simulated street drives (seeds 1-5), checked on others (doc/odometry.md).
  double step_sigma_floor_deg = 0.01, step_sigma_floor_m = 0.001;
};
// Presets for the Ouster models of the VBR rig.
OdometryConfig os0_128_handheld();  // 10 Hz, indoor and outdoor on foot: 0.5 m voxels, 50 m
OdometryConfig os1_64_car();        // 20 Hz, streets: 1.0 m voxels, 100 m
// The presets' names, for option checks: "os0-128", "os1-64".
std::vector<std::string> preset_names();
// One of preset_names(); throws rigcal::Error naming the choices otherwise.
OdometryConfig odometry_preset(const std::string& name);
// The preset for a rig's LiDAR `model` ("OS0-128", "Ouster OS1-64", ...): "os0-128" for an OS0,
// "os1-64" for an OS1, "" for a model neither names.
std::string preset_for_model(std::string_view model);

// How well a step's registration constrains each direction: from its relative covariance, the
// largest translation and rotation sigmas and their directions, and the information's weakest
// over strongest eigenvalue per block; and the covariance's smallest over largest translation
// variance (the marginal: the rotation's coupling and the residuals' clusters are in it).
struct Degeneracy {
  double translation_sigma_max_m = 0, rotation_sigma_max_deg = 0;
  Eigen::Vector3d weakest_translation = Eigen::Vector3d::Zero();  // unit, previous sensor frame
  Eigen::Vector3d weakest_rotation = Eigen::Vector3d::Zero();
  double translation_ratio = 0, rotation_ratio = 0;
  double translation_variance_ratio = 0;
  bool degenerate = false;
  // The step's covariance was widened along weakest_translation (degenerate_sigma_m); the
  // sigmas and ratios above are the registration's own, before it.
  bool translation_widened = false;
};

struct Step {
  Time stamp;
  // Why the sweep has no pose ("" when registered): its stamp is not after the last registered
  // one, or it shares no surface with the map (OdometryConfig::min_overlap).
  std::string skipped;
  SE3 T_odom_lidar;
  // Covariance of the relative motion T_prev_cur = T_odom_lidar(prev)^-1 T_odom_lidar(cur) in
  // rigcal's tangent (rotation first, left perturbation, the previous sensor frame), rad and m.
  // Zero for the first scan.
  Matrix6d covariance_prev_cur = Matrix6d::Zero();
  Degeneracy degeneracy;
  size_t points_in = 0, points_used = 0, correspondences = 0;
  double residual_rms_m = 0, noise_sigma_m = 0, threshold_m = 0;
  int iterations = 0;
  bool converged = false, deskewed = false;
  double seconds = 0;  // wall time of the step
};

struct Odometry {
  OdometryConfig config;
  VoxelMap map;
  AdaptiveThreshold threshold;
  Trajectory T_odom_lidar;  // one pose a registered scan
  Scan first_scan;  // its map sample, kept until the second scan gives the motion to deskew it
};

Odometry start_odometry(const OdometryConfig& config);
// Registers the next scan. The first scan starts the map as measured; the second's registration
// gives the motion that deskews it, and the map is then rebuilt from both. A scan stamped at or
// before the last registered one, or sharing no surface with the map, is skipped (Step::skipped
// says why): no pose, nothing changed.
Step register_scan(Odometry& odometry, const Scan& scan);

}  // namespace rigcal::lidar
