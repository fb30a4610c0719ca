#pragma once
// Calibration assistance while the board is recorded (doc/capture.md, "Assistance"): the target
// detector runs on a decimated stream of each camera, the kept views (the board moved since the
// last one) are counted over a grid of the image, and every few views a calibration of each
// camera alone (the camera step's solver) gives the intrinsics' sigmas, the boards' tilts and
// distances and the projection uncertainty over the image (the camera step's model, mrcal's
// definition). What is still missing is said in words: the parts of the image no corner reached,
// the tilts not yet seen, and the sigmas above the camera step's bars divided by three (focal
// 2e-4 relative, principal point 0.3 px: so that the bars hold at 3 sigma).
#include <condition_variable>
#include <filesystem>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <string>
#include <thread>
#include <vector>

#include "rigcal/camera/target.h"
#include "rigcal/io/image_io.h"

namespace rigcal::capture {

struct AssistOptions {
  camera::Target target;
  io::Bayer bayer = io::Bayer::none;
  double every_s = 0.5;      // a camera's frame looked at this often at most
  double min_motion = 0.05;  // a new view: the corners moved by this share of the image width
  int grid_cols = 8, grid_rows = 6;
  double focal_goal = 2e-4 / 3;    // relative 1-sigma of fx and fy
  double principal_goal_px = 0.1;  // 1-sigma of cx and cy
  double tilt_goal_deg = 30;       // views tilted this far about each image axis, both ways
  std::filesystem::path png;       // refreshed with each new view ("" none)
};

// What one camera's views say so far.
struct CameraCoverage {
  std::string folder;
  size_t looked_at = 0, views = 0;       // frames detected on, kept views
  double covered = 0;                    // share of the grid's cells a corner reached
  std::vector<std::string> empty_zones;  // "top-left", "right", ... less than half covered
  bool solved = false;                   // a calibration of its views ran
  double focal_px = 0;                   // fx of the last solve
  double focal_rel_sigma = 0, principal_sigma_px = 0;
  double tilt_x_min_deg = 0, tilt_x_max_deg = 0, tilt_y_min_deg = 0, tilt_y_max_deg = 0;
  double distance_min_m = 0, distance_max_m = 0;
  double worst_projection_sigma_px = 0;  // over the image, at the boards' median distance
  cv::Point2d worst_at;                  // where (px)
  std::vector<std::string> missing;      // in words; empty: enough
};

class Assistant {
 public:
  Assistant(AssistOptions options, std::vector<std::string> folders);
  ~Assistant();
  Assistant(const Assistant&) = delete;
  Assistant& operator=(const Assistant&) = delete;
  // A frame of camera `index`; taken (shared, not copied) only when that camera's last one was
  // looked at more than every_s ago and the assistant is not busy with it. Never blocks.
  void offer(size_t index, const cv::Mat& frame);
  std::vector<CameraCoverage> coverage() const;
  // One line a camera for a person.
  static std::vector<std::string> lines(const std::vector<CameraCoverage>& coverage);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rigcal::capture
