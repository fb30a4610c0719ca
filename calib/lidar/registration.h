#pragma once
// Point-to-plane ICP of a sweep against the local map (doc/odometry.md): Gauss-Newton on
// r_i = n_i . (T_odom_lidar p_i - m_i), the plane (n_i, m_i) through the map points nearest the
// moved point, a Geman-McClure kernel of scale `kernel_m`, correspondences within
// `max_correspondence_m`. Its information and the residuals' noise level give the pose's
// covariance.
#include <Eigen/Core>
#include <vector>

#include "rigcal/core/scan.h"
#include "rigcal/core/se3.h"
#include "rigcal/lidar/voxel_map.h"

namespace rigcal::lidar {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

struct RegistrationConfig {
  int max_iterations = 50;
  // Stop when the step (rad and m together) is below this, or below ten times it without
  // halving from the one before (correspondences switching between two sets).
  double convergence = 1e-4;
  int plane_neighbours = 8;   // map points a plane is fitted to
  double max_flatness = 0.1;  // smallest over middle scatter eigenvalue of a plane's points
  // The largest share of the middle scatter eigenvalue one of a plane's points may hold
  // (plane_near): above it that point alone would set the normal's tilt.
  double max_point_share = 0.35;
  // The covariance's clusters: cubes of this size (m) whose residuals may share an error; 0:
  // every residual independent.
  double cluster_size_m = 2.0;
};

struct Registration {
  SE3 T_odom_lidar;
  // sum of w_i J_i^T J_i at the solution, J_i = d r_i / d(rotation, translation) in rigcal's
  // tangent (rotation first, left perturbation: R' = exp(d_rot) R, t' = t + d_t); units 1, m, m^2.
  Matrix6d information = Matrix6d::Zero();
  // sqrt(sum w r^2 / (sum w - 6)): the residuals' noise level, m.
  double noise_sigma_m = 0;
  // covariance of T_odom_lidar in that tangent (rad, m): cluster-robust, H^-1 B H^-1 with B the
  // sum over clusters of their gradients' outer products (G / (G - 1) corrected), where there are
  // more than 12 clusters; else noise_sigma^2 * H^-1.
  Matrix6d covariance = Matrix6d::Zero();
  size_t points = 0, correspondences = 0;
  double residual_rms_m = 0;  // over the correspondences, unweighted
  int iterations = 0;
  bool converged = false;
};

// Too few correspondences (fewer than 6 planes) leave the guess unchanged with converged false.
Registration register_points(const std::vector<Eigen::Vector3d>& points_lidar, const VoxelMap& map,
                             const SE3& T_odom_lidar_guess, double max_correspondence_m,
                             double kernel_m, const RegistrationConfig& config);

// The continuous-time form: the sweep's own motion over its period estimated with its start
// pose, each point placed by its time (motion_fraction of the motion, as the deskew does), so that
// a motion that changes from one sweep to the next (a walker's bob and sway) is followed rather
// than lagged by one sweep. r_i = n_i . (T_odom_start M(f_i) p_i - m_i), f_i = t_i / period,
// 12 parameters, a Gaussian prior on the motion (its sigmas per rotation and translation axis
// over the sweep, rad and m) about `T_start_end_prior`.
struct SweepRegistration {
  // The start pose (T_odom_lidar at the sweep's stamp): its information and covariance with the
  // motion marginalised.
  Registration start;
  SE3 T_start_end;                                // the sensor's motion over the period
  Matrix6d motion_covariance = Matrix6d::Zero();  // of T_start_end, rigcal's tangent
};
SweepRegistration register_sweep(const std::vector<ScanPoint>& points, double period_s,
                                 const VoxelMap& map, const SE3& T_odom_start_guess,
                                 const SE3& T_start_end_prior, const Vector6d& prior_sigma,
                                 double max_correspondence_m, double kernel_m,
                                 const RegistrationConfig& config);

}  // namespace rigcal::lidar
