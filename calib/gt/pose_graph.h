#pragma once
// Stage 1 of the ground truth (doc/ground-truth.md): a pose graph over the scan poses, the
// odometry's relative motions weighted by its step covariances, GNSS position priors weighted by
// the fixes' covariances (the paper's eq. 1). Ceres builds and solves it in the shape of its
// pose_graph_3d example; a robust first solve, a chi-square gate on every prior, a second solve
// on the priors kept, and each pose's marginal covariance.
#include <Eigen/Core>
#include <vector>

#include "rigcal/gt/types.h"

namespace rigcal::gt {

struct PoseGraphConfig {
  // A prior at a scan from the two fixes around its stamp, when they are at most this far apart.
  double max_fix_gap_s = 0.5;
  // Huber scale of the first solve, in sigmas of the prior.
  double robust_sigmas = 3.0;
  // A prior whose squared normalized residual exceeds this after the first solve is rejected:
  // 16.27, the 99.9 % point of chi-square with 3 degrees of freedom.
  double gate_chi2 = 16.27;
  // Sigmas (horizontal, vertical; m) of a fix whose receiver reports none, by its quality.
  Eigen::Vector2d sigma_rtk_fixed{0.02, 0.03}, sigma_rtk_float{0.3, 0.5}, sigma_single{2.0, 4.0};
  // RTK errors drift over seconds: priors closer than this in time share their error, and each
  // prior's covariance is multiplied by how many scans fall in twice this time (at least 1):
  // a first-order Gauss-Markov error averages over a span T as T / (2 tau) independent ones. 0: the
  // fixes' errors taken as independent. (The ground- truth step reads a negative value as: estimate
  // it, estimate_fix_correlation.)
  double fix_correlation_s = 0.0;
  // How the final solve (after the gate) takes correlated fixes (fix_correlation_s > 0): true,
  // as an error state per scan (a first-order Gauss-Markov process in units of each fix's
  // sigmas, gt/fix_error_state.h); false, by the covariance scaling above. The robust first
  // solve, whose residuals gate the priors, always uses the scaling.
  bool fix_error_states = true;
  // The share of a fix's variance that is white (independent from fix to fix) when its error is
  // a state; the rest is the Gauss-Markov process. The likelihood search below starts here.
  double fix_white_fraction = 0.1;
  // With the fixes' error as states: take the correlation time and the white share that make the
  // fixes and motions most likely (the final solve's marginal likelihood, the poses and states
  // integrated out; the time searched over 0.2-120 s, the share over 1e-4-0.5, about 35 solves).
  // fix_correlation_s still sets the first, robust solve's scaling and so the gate.
  bool fix_correlation_by_likelihood = false;
  // The fixes' spread (m, standard deviation) below which they are taken as a point (a
  // standing rig: no heading, the odometry's rotation held) or a line (the start rotation
  // from the line's direction; the roll about it judged by max_rotation_sigma_deg).
  double min_spread_m = 2.0;
  // The rotation (about its weakest axis, the median over the poses) counts as undetermined
  // when its marginal sigma is above this, deg: a near-straight path leaves the rotation about
  // it to the lever arm and the path's small bends.
  double max_rotation_sigma_deg = 1.0;
  // GNSS/INS attitudes (when given): their errors drift too (an INS's heading over tens of
  // seconds); each attitude prior's covariance is multiplied by how many scans fall in twice
  // this time (at least 1), as the fixes' are by fix_correlation_s with the scaled model. 0:
  // independent.
  double attitude_correlation_s = 10.0;
  int max_iterations = 100;
  bool covariances = true;
};

// Fixes from a GNSS/INS trajectory (its positions: the antenna or the INS frame's origin, ENU)
// on its own clock: stamps moved to the base clock by `time_offset_s`. Each fix's quality: from
// `quality` (the solution's type, one a fix, or empty) when given, else from `status`
// (NavSatFix's, one a fix or empty: 2 RTK fixed, 0 and 1 single), else rtk_fixed; a fix whose
// status is -1 (no fix) is left out whatever its quality. Its covariance: from the receiver's
// standard deviations (`std_enu_m`, one a fix, or empty; zeros: not known) when given, the
// whole matrix when `covariance_enu_m2` gives it (one a standard deviation, or empty), else
// the quality's sigmas (config.sigma_rtk_fixed, sigma_rtk_float, sigma_single).
std::vector<PositionFix> position_fixes(const Trajectory& T_enu_gnss,
                                        const std::vector<Eigen::Vector3d>& std_enu_m,
                                        const std::vector<int>& status, double time_offset_s,
                                        const PoseGraphConfig& config,
                                        const std::vector<FixQuality>& quality = {},
                                        const std::vector<Eigen::Matrix3d>& covariance_enu_m2 = {});

// The LiDAR's attitudes from GNSS/INS poses (T_enu_ins on the INS's clock: their rotations are
// used), through the rig's rotation `q_ins_lidar`, stamps moved to the base clock by
// `time_offset_s`; each with the covariance of `sigma_rad`: tilt (about east and north) and
// heading (about up), rad. Throws rigcal::Error when every rotation is the identity (a file of
// positions written as poses carries no attitude).
std::vector<AttitudeFix> attitude_fixes(const Trajectory& T_enu_ins,
                                        const Eigen::Quaterniond& q_ins_lidar, double time_offset_s,
                                        const Eigen::Vector2d& sigma_rad);

// The fixes' error correlation time, s, from the residuals of the priors a solve kept (time
// order; each prior's residual is its fix's error, less what the solve took up): the first lag
// at which their autocorrelation falls below 1/e, over pairs of priors that lag apart in scans
// and time (an outage breaks the series); 0 when under one scan's period or fewer than 20
// priors. Each residual is first divided by its fix's own sigmas (`fixes`: the priors' fix
// indices point into it): a few seconds of float or single fixes, metres off where the others
// are centimetres, would otherwise make the whole autocorrelation theirs, and theirs falls at
// their span's edges (measured: 1.3 s for a true 5 s, with 2 s of single fixes in a minute).
// Biased low where the trajectory is free to follow the fixes' drift (a weak odometry, a short
// sequence): it is read from what the solve left.
double estimate_fix_correlation(const std::vector<PriorResidual>& priors,
                                const std::vector<PositionFix>& fixes, double max_s = 120.0);

// The scan poses in the fixes' ENU frame. `p_lidar_antenna`: the antenna (the fixes' point) in
// the LiDAR frame. Nothing throws on data that fix too little: the result says what is
// undetermined (no prior at all: no pose; a standing rig without attitudes: the rotation held at
// the odometry's; a rotation sigma above max_rotation_sigma_deg, or none on a line: said, the
// poses kept).
// `attitudes` (GNSS/INS, optional) are priors on the poses' rotations, interpolated at the scans'
// stamps as the fixes are, gated with them; they settle what the fixes leave (a standing rig's
// heading, the roll about a straight path).
PoseGraphResult solve_pose_graph(const OdometryInput& odometry,
                                 const std::vector<PositionFix>& fixes,
                                 const Eigen::Vector3d& p_lidar_antenna,
                                 const PoseGraphConfig& config,
                                 const std::vector<AttitudeFix>& attitudes = {});

// The marginal covariance of every pose of a chain: H block tridiagonal (pose k tied to k - 1 and
// k + 1 only), given by its diagonal blocks D (n of them) and the blocks B[k] = H(k, k + 1)
// (n - 1). O(n); none when H is singular.
std::vector<Matrix6d> chain_marginals(const std::vector<Matrix6d>& D,
                                      const std::vector<Matrix6d>& B);
// The same with a pose and its fix error state a block (9 x 9).
using Matrix9d = Eigen::Matrix<double, 9, 9>;
std::vector<Matrix9d> chain_marginals(const std::vector<Matrix9d>& D,
                                      const std::vector<Matrix9d>& B);

}  // namespace rigcal::gt
