#pragma once
// The ground truth's inputs and outputs (doc/ground-truth.md): the odometry's scan poses and
// relative motions with their covariances, GNSS position fixes with theirs, and the poses the
// pose graph puts in the local ENU frame of the fixes, each with its covariance.
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/core/se3.h"
#include "rigcal/core/time.h"
#include "rigcal/core/trajectory.h"

namespace rigcal::gt {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

// U with U' U = covariance^-1 (an error term's weight); directions of (numerically) zero variance
// get a large but finite weight rather than an infinite one.
template <int N>
Eigen::Matrix<double, N, N> sqrt_information(const Eigen::Matrix<double, N, N>& covariance) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> eigen(covariance);
  const double largest = std::max(eigen.eigenvalues().maxCoeff(), 1e-300);
  Eigen::Matrix<double, N, 1> inv_sqrt;
  for (int i = 0; i < N; ++i)
    inv_sqrt(i) = 1.0 / std::sqrt(std::max(eigen.eigenvalues()(i), 1e-16 * largest));
  return inv_sqrt.asDiagonal() * eigen.eigenvectors().transpose();
}

// What the receiver says of a fix. The sigmas a quality stands for when the receiver gives none
// are PoseGraphConfig's.
enum class FixQuality { rtk_fixed, rtk_float, single };
std::string_view to_string(FixQuality quality);

// A position of the GNSS antenna (or the INS frame's origin) in the local ENU frame, on the base
// clock.
struct PositionFix {
  Time stamp;
  Eigen::Vector3d p_enu = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();  // m^2, ENU
  FixQuality quality = FixQuality::rtk_fixed;
};

// The LiDAR's attitude in the local ENU frame as a GNSS/INS measures it (its INS frame's
// attitude through the rig's rotation between the two), on the base clock. Its error is a
// rotation vector in the ENU frame, q_enu_lidar = Exp(e) q_true with e ~ N(0, covariance): the
// first two axes are the tilt (about east and north), the third the heading (about up).
struct AttitudeFix {
  Time stamp;
  Eigen::Quaterniond q_enu_lidar = Eigen::Quaterniond::Identity();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();  // rad^2, ENU
};

// The scans' poses from the odometry, and each step's covariance: steps[k] is the motion from
// pose k to pose k + 1, T_prev_cur = perturbed(truth, e) with e ~ N(0, covariance) (rigcal's
// tangent: rotation first, left perturbation, in the previous sensor frame).
struct OdometryInput {
  Trajectory T_odom_lidar;
  std::vector<Matrix6d> step_covariance;  // size() - 1 of them
};

// A fix's prior as the pose graph used it.
struct PriorResidual {
  size_t fix = 0;   // index into the fixes
  size_t node = 0;  // the scan pose it constrains
  Time stamp;
  Eigen::Vector3d residual_enu = Eigen::Vector3d::Zero();  // antenna estimate - fix, m
  double mahalanobis2 = 0;  // residual' covariance^-1 residual (chi-square with 3 dof)
  bool rejected = false;
};

// An attitude's prior as the pose graph used it.
struct AttitudeResidual {
  size_t fix = 0;   // index into the attitudes
  size_t node = 0;  // the scan pose it constrains
  Time stamp;
  // The estimate's rotation from the measured one, a rotation vector in ENU (rad): east and north
  // the tilt, up the heading.
  Eigen::Vector3d residual_enu = Eigen::Vector3d::Zero();
  double mahalanobis2 = 0;  // against the attitude's own covariance (chi-square, 3 dof)
  bool rejected = false;
};

// What the data cannot fix, said in words (and the data that would).
struct Undetermined {
  std::string what, why;
};

struct PoseGraphResult {
  Trajectory T_enu_lidar;
  std::vector<Matrix6d> covariance;  // one a pose, rigcal's tangent in the ENU frame
  std::vector<PriorResidual> priors;
  size_t rejected = 0;
  // The GNSS/INS attitudes' priors, when attitudes were given, and how many the gate rejected.
  std::vector<AttitudeResidual> attitude_priors;
  size_t attitudes_rejected = 0;
  size_t fixes_unused = 0;                     // no scan within the interpolation gap
  std::vector<std::pair<Time, Time>> outages;  // scan spans with no prior, longer than the gap
  std::vector<Undetermined> undetermined;
  std::vector<std::string> notes;
  int iterations = 0;
  double initial_cost = 0, final_cost = 0;
  // The fixes' correlation time the final solve used, s (the configuration's, or the most
  // likely one when PoseGraphConfig::fix_correlation_by_likelihood).
  double fix_correlation_s = 0;
  // The white share of a fix's variance when its error was a state (> 0 then), else 0.
  double fix_white_fraction = 0;
};

}  // namespace rigcal::gt
