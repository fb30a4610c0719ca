#pragma once
// The simulator's configuration file (doc/simulator.md lists every key and its default):
//   seed, base_start_s, target (a target YAML path),
//   stereo: {views, min_fill, max_fill, max_tilt_deg, max_roll_deg, margin_px, frame_period_s}
//   image: {supersample, blur_sigma_px, black_dn, white_dn, background_dn, gain_dn_per_e,
//           read_noise_dn, vignetting, bayer}
//   lidar: {model: os0-128|os1-64, range_noise_m}
//   lidar_camera: {pairs, camera, clutter}
//   imu / os_imu: {rate_hz, jitter_s, drift_ppm, gaps: [[from, to], ...]}, imu_duration_s,
//   imu_motion trajectories: {duration_s, motion: handheld|car|walk, replay, building, odometry:
//   {trans_sigma_m,
//                  rot_sigma_deg, scale_error}, gnss: {rate_hz, horizontal_sigma_m,
//                  vertical_sigma_m, rot_sigma_deg, outages: [[from, to], ...],
//                  float_fixes, single_fixes: [[from, to], ...], float_horizontal_sigma_m,
//                  float_vertical_sigma_m, single_horizontal_sigma_m, single_vertical_sigma_m,
//                  outlier_probability, outlier_jump_m}}
//   scans: {count}
// Unknown keys are errors naming the line.
#include <filesystem>
#include <string_view>

#include "rigcal/sim/session.h"

namespace rigcal::io {

// Applies the keys present in the file to `config` (relative paths resolve against the file).
void apply_sim_config(std::string_view text, std::string_view file_name, sim::SimConfig& config);
void read_sim_config(const std::filesystem::path& path, sim::SimConfig& config);

}  // namespace rigcal::io
