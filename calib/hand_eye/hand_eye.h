#pragma once
// Hand-eye calibration from two trajectories of one rigid body: the LiDAR's odometry and the
// GNSS/INS's poses (issue 7; doc/hand-eye.md). The unknown is X = T_gnss_lidar, the LiDAR in the
// GNSS/INS frame. For the motion between two instants, A = T_L(t0)^-1 T_L(t1) (the LiDAR's) and
// B = T_G(t0)^-1 T_G(t1) (the GNSS/INS's) satisfy
//     B X = X A:   R_B R_X = R_X R_A,   (R_B - I) t_X = R_X t_A - t_B.
// The rotation axes therefore satisfy axis(B) = R_X axis(A): the rotation follows from the axes
// (Kabsch, the least-squares form of Park and Martin's), then the translation by least squares.
// Both are conditioned by how the rotation axes spread: motion about one axis only (a car on a
// plane turns about the vertical) leaves the rotation about that axis poorly determined and the
// translation along it not at all; Observability says so in numbers.
#include <Eigen/Core>
#include <optional>
#include <vector>

#include "rigcal/core/se3.h"
#include "rigcal/core/time.h"
#include "rigcal/core/trajectory.h"
#include "rigcal/time_sync/time_sync.h"

namespace rigcal::hand_eye {

struct MotionPair {
  Time t0, t1;  // on the LiDAR's clock
  SE3 A;        // T_L0_L1, the LiDAR's motion (odometry interpolated at t0, t1)
  SE3 B;        // T_G0_G1, the GNSS/INS's motion
  // The LiDAR's body-frame angular (rad/s) and linear (m/s) velocities at t0 and t1: what A
  // becomes when the clock offset moves by dt, A(dt) = exp(-dt xi0) A exp(dt xi1) (refine's
  // time offset).
  Eigen::Vector3d w0 = Eigen::Vector3d::Zero(), v0 = Eigen::Vector3d::Zero(),
                  w1 = Eigen::Vector3d::Zero(), v1 = Eigen::Vector3d::Zero();
};

struct PairOptions {
  // t1 - t0: pairs of each of these lengths. A hand-held rig's rotation grows slower than the
  // spacing (its sway and shake: 0.3 s pairs of the VBR walks turn 35-55 % as much as 1 s pairs)
  // while the odometry's noise grows as its square root, so short pairs add information that 1 s
  // pairs miss, and 1 s pairs hold the slower turns (doc/hand-eye.md, "Pair lengths").
  std::vector<double> spacings_s = {0.3, 1.0};
  // Between the starts of consecutive pairs of one length; 0: the length (pairs end to end).
  // Overlapping pairs use more of the data (every 0.1 s: every LiDAR pose); the covariance does
  // not count them as independent (refine's sandwich estimator).
  double stride_s = 0.1;
  double min_rotation_deg = 1.0;  // pairs whose GNSS/INS rotation is smaller are dropped
  // The GNSS/INS clock: t_lidar = t_gnss + time_offset_s (its time_offset in the rig when the
  // LiDAR is on the base clock).
  double time_offset_s = 0.0;
  double max_gap_s = 0.5;  // longest LiDAR pose interval interpolated across
  // Each GNSS/INS pose replaced by a local quadratic fit over the fixes within +- this many
  // seconds (smooth_poses), where at least 5 are: a pair then rests on ~11 fixes at 100 Hz
  // instead of 2 (white RTK noise down ~2x; no gain, and no harm, on noise correlated over
  // seconds). 0: the fixes as they are.
  double gnss_half_window_s = 0.05;
};

// Each pose replaced by a local fit over the poses within +- half_window_s of it: positions by a
// least-squares quadratic in time, orientations likewise by their rotation vectors relative to
// the pose's own; fixes beyond 5 sigmas (and 5 cm; sigma from the trajectory's second
// differences, robustly) of a window's fit are left out of it, and it is fitted again (a multipath
// jump is neither spread to its neighbours nor kept). Poses with fewer than 5 neighbours in the
// window stay as they are. The motion must be smooth on that scale: a walk's 2 Hz bounce of 2.5 cm
// is followed to 0.2 mm by +-0.05 s.
Trajectory smooth_poses(const Trajectory& trajectory, double half_window_s);

// options.spacings_s each once, shortest first. Throws rigcal::Error on a spacing that is not
// positive.
std::vector<double> pair_lengths(const PairOptions& options);

// Pairs along the GNSS/INS trajectory (smoothed, options.gnss_half_window_s): for each spacing
// (pair_lengths), a
// GNSS/INS pose at t0, the first one at least the spacing later at t1, the LiDAR odometry
// interpolated (slerp + linear) at both instants. Pairs outside the odometry, across a gap, or
// rotating too little are skipped. In order of t0 (then t1).
std::vector<MotionPair> motion_pairs(const Trajectory& T_odom_lidar, const Trajectory& T_enu_gnss,
                                     const PairOptions& options = {});

// The GNSS/INS clock offset from the two trajectories' angular velocities (the time-offset
// step's method, doc/time-offset.md), searched around prior_offset_s: t_lidar = t_gnss +
// offset_s, the prior included in the result's offset_s. Check the verdict before using it.
time_sync::TimeSyncResult estimate_clock_offset(const Trajectory& T_odom_lidar,
                                                const Trajectory& T_enu_gnss,
                                                double prior_offset_s = 0.0);

struct Observability {
  // Singular values (descending) of the stacked rotation vectors of the LiDAR motions, rad: all
  // three large when the motion turns about spread axes; a small third one means one direction
  // of rotation axes is missing.
  Eigen::Vector3d rotation_singular_values = Eigen::Vector3d::Zero();
  // The motion turns (nearly) about one axis only: the third rotation singular value is below
  // kNearPlanarRatio of the first (a car on a road: about 0.05; hand-held walking: 0.15-0.45).
  // Then the rotation about that axis is poorly conditioned and the translation along it is
  // weakly determined or not at all (translation_sigma_m says how much).
  bool near_planar = false;
  // The dominant rotation axis (first principal direction of the rotation vectors), GNSS/INS
  // frame: the plane's normal when near_planar.
  Eigen::Vector3d dominant_axis = Eigen::Vector3d::UnitZ();
  // Singular values (descending) of the stacked (R_B - I), and their right singular vectors
  // (columns, GNSS/INS frame): the translation along a column whose value is small is not
  // determined by the data.
  Eigen::Vector3d translation_singular_values = Eigen::Vector3d::Zero();
  Eigen::Matrix3d translation_directions = Eigen::Matrix3d::Identity();
  // 1-sigma of the translation along each of those directions, m, from the stacked residuals by
  // the sandwich estimator with Bartlett weights over pairs that share fixes or overlap (see
  // refine): sqrt(v^T S v) / s^2.
  Eigen::Vector3d translation_sigma_m = Eigen::Vector3d::Zero();
  // Directions (columns of translation_directions) the data do not determine: a 1-sigma above
  // max_sigma_m, a singular value below 1e-3 of the largest, or (near_planar) the one closest to
  // the dominant rotation axis. Their translation component is
  // set to 0 (minimum norm), not estimated.
  std::vector<int> unobservable;
};

inline constexpr double kNearPlanarRatio = 0.1;
// The hand-eye step refuses motion pairs whose LiDAR and GNSS/INS rotation angles differ by more
// than this factor (median over the pairs), and calls the rotation undetermined when the second
// rotation singular value is below kMinRotationSpread of the first (every pair about one axis).
inline constexpr double kMinAngleRatio = 0.5;
inline constexpr double kMinRotationSpread = 1e-3;

struct ClosedForm {
  SE3 T_gnss_lidar;
  Observability observability;
  size_t pairs = 0;
  // Pairs left out as outliers before the fit (consensus below), and which.
  size_t rejected = 0;
  std::vector<bool> outlier;
  double rotation_residual_rms_deg = 0.0;  // of the inliers' axes after the fit
};

// Consensus first: rotations from random couples of pairs with different axes, the one with the
// least median axis residual (least median of squares: up to half the pairs may be wrong) marks
// the pairs beyond 3 robust sigmas of it (and 0.1 deg) as outliers; the translation's least
// squares on the rest marks those beyond 3 robust sigmas (and 1 cm) of it. The closed form and
// its observability figures then use the inliers. Throws rigcal::Error with fewer than 3 pairs
// (or inliers).
ClosedForm closed_form(const std::vector<MotionPair>& pairs, double max_sigma_m = 0.05);

struct RefineOptions {
  // Per-pair noise: a pair's residual is scaled by these (rotation error of R_B R_X vs R_X R_A;
  // translation error of B X vs X A, GNSS/INS frame).
  double rotation_sigma_deg = 0.05;
  double translation_sigma_m = 0.02;
  double huber = 3.0;  // robust loss width, in those sigmas
  // Translation components held at a value, not estimated: t . direction = value (a unit
  // direction in the GNSS/INS frame; e.g. the vertical on a car, with the value measured by tape);
  // or, with sigma_m > 0, a prior: t . direction = value +- sigma_m, weighed with the pairs (the
  // covariance then carries the prior's sigma along that direction).
  struct Fixed {
    Eigen::Vector3d direction;
    double value_m = 0.0;
    double sigma_m = 0.0;  // 0: held exactly
  };
  std::vector<Fixed> fixed;
  // A scale factor on every LiDAR translation t_A, estimated with X: LiDAR odometry's scale error
  // (tenths of a percent are common) would otherwise leak into the lever arm in every turn
  // (simulated car at 10 m/s with 0.2 %: 2 cm in the plane).
  bool estimate_scale = true;
  // A correction dt to the clock offset the pairs were built with, estimated with X (the LiDAR
  // motion of each pair taken at t0 + dt, t1 + dt to first order): t_lidar = t_gnss + offset + dt.
  bool estimate_time_offset = false;
};

struct Refined {
  SE3 T_gnss_lidar;
  // 6 x 6 covariance: rotation (left tangent, rad: R = exp(d) R_X) then translation (m), by the
  // sandwich H^-1 S H^-1 from the inlier pairs' residuals, S summing the products of pairs whose
  // intervals touch or overlap with Bartlett weights (Newey-West): the noise level comes from the
  // residuals, and pairs sharing a GNSS/INS fix or odometry steps are not counted as independent.
  // Held directions have (near) zero variance.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  // Its diagonal as 1-sigmas: about the GNSS/INS frame's axes (deg), and of t (m).
  Eigen::Vector3d rotation_sigma_deg = Eigen::Vector3d::Zero();
  Eigen::Vector3d translation_sigma_m = Eigen::Vector3d::Zero();
  std::vector<double> pair_rotation_residual_deg, pair_translation_residual_m;
  std::vector<bool> outlier;  // beyond the 99.9 % of chi-square(6) at the residuals' level
  double noise_scale = 1.0;   // RMS of the normalized residuals: the sigmas' correction factor
  // The noise levels the final solve weighed the pairs with, one per pair length (spacing):
  // estimated from the first solve's inlier residuals (RMS per component), the given sigmas
  // serving only as a start. Lengths differ in noise: the GNSS/INS's is the same at any length,
  // the odometry's grows with it.
  struct PairNoise {
    double length_s = 0;  // the group's median t1 - t0
    size_t pairs = 0;     // its inliers
    double rotation_deg = 0, translation_m = 0;
  };
  std::vector<PairNoise> pair_noise;
  // The odometry's scale correction (GNSS/INS distance over LiDAR distance) and its 1-sigma;
  // 1 and 0 when not estimated.
  double odometry_scale = 1.0, odometry_scale_sigma = 0.0;
  // With estimate_time_offset: the correction to the pairs' clock offset, and its 1-sigma (s).
  double time_offset_correction_s = 0.0, time_offset_sigma_s = 0.0;
};

// The unobservable directions of `observability` that no entry of `fixed` covers (|cos| > 0.9)
// are appended to `fixed`, held at the prior extrinsic's component. Returns the indices (columns
// of translation_directions) so held; without a prior, throws nothing and appends nothing but
// returns them in `uncovered` instead.
struct Held {
  std::vector<int> from_prior, uncovered;
};
Held hold_unobservable(const Observability& observability, const std::optional<SE3>& prior,
                       std::vector<RefineOptions::Fixed>& fixed);

// Nonlinear least squares over X from `initial` (Ceres, Huber loss): all pairs' rotation and
// translation residuals together, unlike the closed form's two separate steps. Solved twice: with
// the given sigmas, then with the rotation and translation noise levels the residuals show, for
// each pair length apart (pairs whose lengths differ by more than 50 ms).
Refined refine(const std::vector<MotionPair>& pairs, const SE3& initial,
               const RefineOptions& options = {});

}  // namespace rigcal::hand_eye
