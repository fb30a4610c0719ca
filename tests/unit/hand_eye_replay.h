#pragma once
// Acceptance 1 of issue 7 on real motion: a VBR ground truth (the LiDAR's poses, hand-held or
// car) replayed by the simulator as the rig's true motion, with the sample rig's GNSS/INS moved
// to a known extrinsic of about 0.3 m and 20 deg, its clock offset (-3.1 ms), odometry noise and
// RTK noise (2 cm horizontal, 3 cm vertical, outages, multipath jumps). The whole chain runs:
// clock offset from the trajectories, pairs, closed form, refinement.
#include <Eigen/Core>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <string>
#include <utility>
#include <vector>

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
  std::vector<MotionPair> pairs;       // the default: 0.3 s and 1 s pairs every 0.1 s
  std::vector<MotionPair> end_to_end;  // 1 s pairs end to end: stations for OpenCV
};

// OpenCV's calibrateHandEye on the stations the pairs chain into (GNSS/INS = gripper, LiDAR =
// camera, the odometry frame = the target; its X, cam2gripper, is T_gnss_lidar). OpenCV forms a
// motion from every two stations (i < j), not only consecutive ones: `every_two` receives those
// motions so rigcal can be run on the same set.
inline SE3 opencv_hand_eye(const std::vector<MotionPair>& pairs, cv::HandEyeCalibrationMethod m,
                           std::vector<MotionPair>* every_two = nullptr) {
  std::vector<cv::Mat> R_g2b, t_g2b, R_t2c, t_t2c;
  std::vector<SE3> Gs{SE3{}}, Ls{SE3{}};
  for (const MotionPair& p : pairs) Gs.push_back(Gs.back() * p.B), Ls.push_back(Ls.back() * p.A);
  for (size_t k = 0; k < Gs.size(); ++k) {
    cv::Mat R, t, R2, t2;
    cv::eigen2cv(Gs[k].R, R);
    cv::eigen2cv(Gs[k].t, t);
    const SE3 L_inv = Ls[k].inverse();
    cv::eigen2cv(L_inv.R, R2);
    cv::eigen2cv(L_inv.t, t2);
    R_g2b.push_back(R), t_g2b.push_back(t), R_t2c.push_back(R2), t_t2c.push_back(t2);
  }
  if (every_two) {
    for (size_t i = 0; i < Gs.size(); ++i) {
      for (size_t j = i + 1; j < Gs.size(); ++j)
        every_two->push_back({Time{}, Time{}, Ls[i].inverse() * Ls[j], Gs[i].inverse() * Gs[j]});
    }
  }
  cv::Mat R, t;
  cv::calibrateHandEye(R_g2b, t_g2b, R_t2c, t_t2c, R, t, m);
  SE3 X;
  cv::cv2eigen(R, X.R);
  cv::cv2eigen(t, X.t);
  return X;
}

inline const std::vector<std::pair<cv::HandEyeCalibrationMethod, const char*>>& opencv_methods() {
  static const std::vector<std::pair<cv::HandEyeCalibrationMethod, const char*>> m = {
      {cv::CALIB_HAND_EYE_TSAI, "Tsai"},
      {cv::CALIB_HAND_EYE_PARK, "Park"},
      {cv::CALIB_HAND_EYE_HORAUD, "Horaud"},
      {cv::CALIB_HAND_EYE_ANDREFF, "Andreff"},
      {cv::CALIB_HAND_EYE_DANIILIDIS, "Daniilidis"}};
  return m;
}

// The sequence's ground truth; the unobservable directions (a car's vertical) held at the truth,
// as `--fix` would with a measured value.
inline ReplayRun replay_vbr(const Trajectory& gt, uint64_t seed, double rtk_correlation_s = 0.0) {
  rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  rig::sensor(rig, "gnss").T_base_sensor =
      SE3::from_rotation_vector({0.2, -0.15, 0.25}, {0.25, -0.12, 0.15});
  sim::SimConfig cfg;
  cfg.seed = seed;
  cfg.trajectory_duration_s = 1e9;  // the whole sequence
  cfg.gnss.correlation_time_s = rtk_correlation_s;
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
  run.pairs = motion_pairs(part.odometry, part.gnss, po);
  PairOptions end_to_end = po;
  end_to_end.stride_s = 0;
  end_to_end.spacings_s = {1.0};
  run.end_to_end = motion_pairs(part.odometry, part.gnss, end_to_end);
  const std::vector<MotionPair>& pairs = run.pairs;
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
