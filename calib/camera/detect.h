#pragma once
// Target detection in one image (doc/cameras.md). Checkerboards: OpenCV's sector-based detector
// on a downscaled probe (bounded time; no minutes-long search on images without a board), then
// cornerSubPix at full resolution with a window derived from the observed square size, and the
// corner order fixed so that point 0 is the target's origin corner. AprilGrids: OpenCV's aruco
// (DICT_APRILTAG_36h11, 2-bit border), then the quads it could not decode read as the grid's own
// tags, then the tags it missed predicted from their found neighbours, then all of it again at
// twice the size if tags are still missing; a tag not decoded by aruco is kept only if the image
// reads as that tag's printed cells through its refined corners. Every tag's four corners
// numbered as Kalibr numbers them, refined the same way; partial boards allowed.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "rigcal/camera/target.h"

namespace rigcal::camera {

struct Detection {
  bool found = false;
  std::vector<int> point_ids;           // indices into object_points(target)
  std::vector<Eigen::Vector2d> pixels;  // refined corners, px
  std::string note;                     // why nothing was found, or what was dropped
  double square_px = 0;                 // median observed square (or tag cell) size, px
};

struct DetectOptions {
  int probe_max_size = 800;  // the probe image's larger side, px
  int min_tags = 4;          // AprilGrid: fewer decoded tags count as no detection
  // Checkerboards: after cornerSubPix, each corner located by a model of its grey values
  // (saddle.h; `rigcal cameras --saddle-fit`). Measured (doc/cameras.md): on the simulator's
  // default session 0.024 px of corner noise against 0.050, no pixel locking; on the OpenCV
  // stereo samples an RMS of 0.180 px against 0.194, but no better agreement between two halves
  // of the views, and on the ACFR fisheye a worse one; over 20 simulated seeds the equidistant
  // model's covariance then misses the efficiency bar: off until real data show a gain. Not for
  // AprilGrids (discs limited by the tags' borders: precision varying with the tags' sizes, and
  // the reported uncertainty then too small).
  bool fit_saddles = false;
};

// `gray`: 8-bit single channel. Never throws for an image without a target (found = false).
Detection detect(const cv::Mat& gray, const Target& target, const DetectOptions& options = {});

}  // namespace rigcal::camera
