#pragma once
// The hand-eye report (doc/hand-eye.md): hand_eye.json (every figure with its definition),
// residuals.png (per-pair residuals against time) and trajectories.png (top view of the GNSS/INS
// positions and of the LiDAR odometry carried into the GNSS/INS frame through the extrinsic).
#include <filesystem>
#include <string>
#include <vector>

#include "rigcal/core/trajectory.h"
#include "rigcal/hand_eye/hand_eye.h"
#include "rigcal/io/files.h"

namespace rigcal::hand_eye {

struct HandEyeInputs {
  std::string lidar, gnss, rig;  // paths as given
  double gnss_time_offset_s = 0.0;
  std::vector<double> spacings_s;
  double stride_s = 0.0, min_rotation_deg = 0.0, max_sigma_m = 0.0;
  std::vector<std::string> notes;
};

std::vector<io::OutputFile> hand_eye_report_files(const std::filesystem::path& dir,
                                                  const HandEyeInputs& in,
                                                  const std::vector<MotionPair>& pairs,
                                                  const ClosedForm& cf, const Refined& r,
                                                  const Trajectory& lidar, const Trajectory& gnss);

// What a person must look at before trusting an extrinsic that was found: more than a tenth of
// the motion pairs outliers; the odometry's scale (estimated with the extrinsic) away from 1 by
// more than 3 sigma and 1 %.
std::vector<std::string> fit_warnings(const Refined& r);

}  // namespace rigcal::hand_eye
