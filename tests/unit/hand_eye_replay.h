#pragma once
// Acceptance 1 of issue 7 on real motion: a VBR ground truth (the LiDAR's poses, hand-held or
// car) replayed by the simulator as the rig's true motion, with the sample rig's GNSS/INS moved
// to a known extrinsic of about 0.3 m and 20 deg, its clock offset (-3.1 ms), odometry noise and
// RTK noise (2 cm horizontal, 3 cm vertical, outages, multipath jumps). The whole chain runs:
// clock offset from the trajectories, pairs, closed form, refinement.
#include <cmath>
#include <string>

#include "rigcal/hand_eye/hand_eye.h"
#include "rigcal/io/trajectory_io.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/sim/session.h"

namespace rigcal::hand_eye::testing {

struct ReplayRun {
  double offset_error_s = 0, offset_sigma_s = 0;
  ClosedForm closed;
  Refined refined;
  SE3 truth;  // T_gnss_lidar
  Eigen::Vector3d t_error = Eigen::Vector3d::Zero();
  double rotation_error_deg = 0;
};

// The sequence's ground truth; the unobservable directions (a car's vertical) held at the truth,
// as `--fix` would with a measured value.
inline ReplayRun replay_vbr(const Trajectory& gt, uint64_t seed) {
  rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  rig::sensor(rig, "gnss").T_base_sensor =
      SE3::from_rotation_vector({0.2, -0.15, 0.25}, {0.25, -0.12, 0.15});
  sim::SimConfig cfg;
  cfg.seed = seed;
  cfg.trajectory_duration_s = 1e9;  // the whole sequence
  const sim::TrajectoryPart part = sim::simulate_trajectories(rig, cfg, &gt);
  ReplayRun run;
  run.truth = rig::T_a_b(rig, part.gnss_name, "lidar");
  const double offset_truth =
      rig::sensor(rig, part.gnss_name).time_offset - rig::sensor(rig, "lidar").time_offset;
  const time_sync::TimeSyncResult sync = estimate_clock_offset(part.odometry, part.gnss);
  run.offset_error_s = sync.offset_s - offset_truth;
  run.offset_sigma_s = sync.sigma_s;
  PairOptions po;
  po.time_offset_s = sync.offset_s;
  const std::vector<MotionPair> pairs = motion_pairs(part.odometry, part.gnss, po);
  run.closed = closed_form(pairs);
  RefineOptions ro;
  for (int i : run.closed.observability.unobservable) {
    const Eigen::Vector3d d = run.closed.observability.translation_directions.col(i);
    ro.fixed.push_back({d, d.dot(run.truth.t)});
  }
  run.refined = refine(pairs, run.closed.T_gnss_lidar, ro);
  run.t_error = run.refined.T_gnss_lidar.t - run.truth.t;
  run.rotation_error_deg =
      rotation_angle(run.refined.T_gnss_lidar.R * run.truth.R.transpose()) * 180.0 / M_PI;
  return run;
}

}  // namespace rigcal::hand_eye::testing
