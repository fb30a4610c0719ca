#pragma once
// Simulated trajectories for hand-eye and ground truth (doc/simulator.md): the base (LiDAR) frame's
// true poses, a LiDAR odometry with slow drift, and a GNSS/INS trajectory of another frame on
// the rig, through the true extrinsic, with RTK noise, outages and multipath outliers.
#include <functional>
#include <random>
#include <utility>
#include <vector>

#include "rigcal/core/trajectory.h"
#include "rigcal/sim/motion.h"

namespace rigcal::sim {

// T_world_base at motion time t (s).
using PoseSource = std::function<SE3(double)>;
PoseSource pose_source(const Motion& motion);  // holds a copy of the motion
// Replays a trajectory (e.g. a VBR ground truth): motion time 0 is its first stamp; poses are
// interpolated (slerp + linear). The second value is its duration in s. The source refers to
// `replay`, which must outlive it.
std::pair<PoseSource, double> pose_source(const Trajectory& replay);

struct OdometryNoise {
  double trans_sigma_m = 0.003;  // per step, each axis
  double rot_sigma_deg = 0.01;   // per step, each axis
  double scale_error = 0.002;    // relative error of every step's translation
};

// The state of a fix, as a receiver reports it (RTKLIB's Q: 1 fixed, 2 float, 5 single).
enum class FixState { rtk_fixed, rtk_float, single };

struct GnssNoise {
  double rate_hz = 100.0;
  double horizontal_sigma_m = 0.02;  // RTK fixed, each of east and north
  double vertical_sigma_m = 0.03;
  double rot_sigma_deg = 0.05;
  // 0: the position and attitude noise is white (independent at every fix); > 0: first-order
  // Gauss-Markov with this correlation time, same sigmas (RTK errors drift over seconds).
  double correlation_time_s = 0.0;
  double time_offset_s = 0.0;                      // the GNSS/INS clock: t_base = t_stamp + offset
  std::vector<std::pair<double, double>> outages;  // [from, to) s with no fixes
  // [from, to) s of RTK float fixes and of single (code-only) fixes; single wins where both
  // apply. Their position errors are the same correlated process as the fixed ones', scaled by
  // their own sigmas (so a span changes no random draw: the rest of the output is unchanged).
  // The defaults are of the order receivers give: decimetres for a float solution, a metre or
  // two for a single one (u-blox's ZED-F9P datasheet: 1.5 m CEP standalone), vertical about
  // twice horizontal as for the RTK fixed ones.
  std::vector<std::pair<double, double>> float_spans, single_spans;
  double float_horizontal_sigma_m = 0.2, float_vertical_sigma_m = 0.4;
  double single_horizontal_sigma_m = 1.5, single_vertical_sigma_m = 3.0;
  double outlier_probability = 0.001;  // multipath jumps
  double outlier_jump_m = 1.5;
};

// Poses of the base frame every 1/rate s over [0, duration]; stamps base_start + t.
Trajectory sample_poses(const PoseSource& source, double rate_hz, double duration, Time base_start);

// LiDAR odometry from true base poses: relative motions with noise and scale error, chained from
// the identity (the odometry frame is the first pose).
Trajectory simulate_odometry(const Trajectory& truth, const OdometryNoise& noise,
                             std::mt19937_64& rng);

// The state of the fixes at motion time t (GnssNoise's spans), and its sigmas (horizontal,
// vertical; m).
FixState fix_state_at(const GnssNoise& noise, double t);
std::pair<double, double> fix_sigmas(const GnssNoise& noise, FixState state);

// GNSS/INS poses of the frame `T_base_gnss` in a local ENU frame (T_enu_world), on the GNSS clock.
// `outliers` receives the indices of the poses made outliers, `states` each pose's fix state.
Trajectory simulate_gnss(const PoseSource& source, double duration, Time base_start,
                         const SE3& T_base_gnss, const SE3& T_enu_world, const GnssNoise& noise,
                         std::mt19937_64& rng, std::vector<size_t>* outliers = nullptr,
                         std::vector<FixState>* states = nullptr);

}  // namespace rigcal::sim
