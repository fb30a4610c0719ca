#pragma once
// The hand-eye step (doc/hand-eye.md): the GNSS/INS-to-LiDAR extrinsic from the LiDAR odometry
// and the GNSS/INS trajectory, written into the rig as the GNSS/INS sensor's T_b; sensors
// declared rigidly attached to it (`attached_to`, the INS's own IMU) move with it.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/hand_eye/hand_eye.h"
#include "rigcal/io/trajectory_io.h"
#include "rigcal/report/step.h"

namespace rigcal::hand_eye {

struct StepOptions {
  std::string sensor = "gnss", lidar_sensor = "lidar";  // the rig's sensors
  io::TrajectoryReadOptions::Duplicates duplicates = io::TrajectoryReadOptions::Duplicates::error;
  std::string attitude;  // GNSS fixes only: "enu" or "ned"
  PairOptions pairs;     // time_offset_s is taken from the rig (and the estimate)
  RefineOptions refine;  // estimate_time_offset follows estimate_offset
  double max_sigma_m = 0.05;
  // Estimate the clock offset from the trajectories' angular velocities and write it. When not,
  // the estimate is still made and a disagreement with the rig's value is reported.
  bool estimate_offset = false;
  // rigcal's odometry on StepInputs::lidar_scans: a lidar::odometry_preset name, or "" for the
  // one the rig's LiDAR model names (lidar::preset_for_model), else os0-128.
  std::string odometry_preset;
  // And it estimates each sweep's own motion (lidar::OdometryConfig::estimate_sweep_motion): a
  // motion recording turns and walks the rig, which the motion of the step before lags.
  bool odometry_sweep_motion = true;
  // Also the motion pairs' residuals at the given rig's T_gnss_lidar and clock offset (odometry
  // scale 1), nothing re-estimated (rigcal check: the new motion at the stored calibration):
  // the residual figures pair_*_median_at_rig_<unit>, beside the estimate's pair_*_median_<unit>.
  bool fit_at_rig = false;
};

struct StepInputs {
  std::filesystem::path lidar;  // T_odom_lidar
  // Or, with `lidar` empty, the LiDAR's scans (a folder or a capture, as lidar::scans_folder
  // gives): rigcal's odometry runs on them first; its trajectory (lidar_odometry.tum), step
  // covariances and odometry.json join the report beside hand_eye.json.
  std::filesystem::path lidar_scans;
  std::filesystem::path gnss;   // T_enu_gnss, or a CSV of fixes
  std::optional<rig::Rig> rig;  // clock offsets and the prior extrinsic; none: estimate only
  std::string rig_source;       // where the rig came from, for the report
};

// The inputs of a run from what a command was given: `odometry` (T_odom_lidar, --lidar) or
// `scans` (not both), `gnss`, and for the ones not given what the session folder `session` names in
// its session.yaml (odometry, gnss); the rig read from `rig` when given. Throws rigcal::Error when
// an input is missing or both of lidar and scans are given, or when `out` is one of the inputs
// (`rig` may be `out`: the sensor's T_b is written into it).
StepInputs step_inputs(const std::filesystem::path& odometry, const std::filesystem::path& scans,
                       const std::filesystem::path& gnss, const std::filesystem::path& session,
                       const std::filesystem::path& rig, const std::filesystem::path& out,
                       const report::Progress& progress = {});

// Translation components held (`--fix AXIS=METRES`) or given a prior (`with_sigma`: `--prior
// AXIS=METRES,SIGMA`), AXIS x, y or z of the GNSS/INS frame. Throws rigcal::Error naming the
// option and what it expects.
std::vector<RefineOptions::Fixed> parse_translation_constraints(
    const std::vector<std::string>& specs, bool with_sigma);

// Status undetermined when the clock offset cannot be estimated (with estimate_offset) or a
// translation direction is determined neither by the motion nor by a fix, a prior or the rig.
// Throws rigcal::Error on bad input: unreadable trajectories, no overlap in time, too few motion
// pairs, sensors missing from the rig.
report::StepResult estimate_extrinsic(const StepInputs& inputs, const StepOptions& options,
                                      const report::Progress& progress = {});

}  // namespace rigcal::hand_eye
