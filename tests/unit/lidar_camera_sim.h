#pragma once
// The LiDAR-camera step on one simulated session (issue 8), shared by the unit and long tests:
// detection in the rendered images, PnP through the rig's lens, the board found in every scan
// (without a prior; ambiguous scans searched again after a first solve), the solve.
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "rigcal/camera/detect.h"
#include "rigcal/lidar_camera/solve.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/sim/session.h"

namespace rigcal::lidar_camera::testing {

struct SimRun {
  Solution solution;
  SE3 truth;  // T_camera_lidar
  int found = 0, pairs = 0;
};

// The whole chain on one simulated session: detection in the rendered images, PnP through the
// rig's lens, the board found in every scan (the first pass without a prior; boards of the
// board's size elsewhere would need one), the solve.
inline SimRun simulate_and_solve(uint64_t seed, int pairs_wanted = 10, bool print = true) {
  rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  sim::SimConfig cfg;
  cfg.seed = seed;
  cfg.lidar_camera_pairs = pairs_wanted;
  const sim::LidarCameraPart part = sim::simulate_lidar_camera(rig, cfg);
  const rig::CameraModel& cam = rig::sensor(rig, part.camera_name).camera;
  const camera::Outline outline = camera::outline(cfg.target);
  SimRun run;
  run.truth = rig::T_a_b(rig, part.camera_name, rig.base_frame);
  std::vector<PairInput> inputs;
  for (size_t k = 0; k < part.scans.size(); ++k) {
    ++run.pairs;
    PairInput in;
    cv::Mat gray = part.images[k];
    if (gray.channels() == 3) cv::cvtColor(gray, gray, cv::COLOR_BGR2GRAY);
    const camera::Detection det = camera::detect(gray, cfg.target);
    if (det.found && det.pixels.size() == camera::object_points(cfg.target).size())
      in.camera = board_in_camera(cam, cfg.target, det.pixels);
    for (const sim::LidarPoint& p : part.scans[k]) in.scan.push_back(p.p.cast<double>());
    inputs.push_back(std::move(in));
  }
  BoardSearch s;
  s.board_width_m = outline.width();
  s.board_height_m = outline.height();
  s.seed = seed * 100;
  const Calibration c = calibrate(inputs, s);
  for (size_t k = 0; k < c.pairs.size(); ++k) {
    if (print) std::printf("pair %zu: %s\n", k, c.pairs[k].note.c_str());
    run.found += c.pairs[k].used;
  }
  run.solution = c.solution;
  return run;
}

}  // namespace rigcal::lidar_camera::testing
