#pragma once
// The camera step (doc/cameras.md): intrinsics of one or two cameras and their stereo extrinsic
// from images of a target, written into the rig. Detections are reused from an earlier run's
// corners.vnl when it was written for the same target.
#include <filesystem>
#include <optional>
#include <string>

#include "rigcal/io/image_io.h"
#include "rigcal/io/image_sets.h"
#include "rigcal/report/step.h"

namespace rigcal::camera {

struct StepOptions {
  // pinhole-radtan | pinhole-radtan5 | pinhole-equidistant (Kalibr's pinhole-equi), or
  // NAME=MODEL,NAME=MODEL naming every camera (each its own lens model, fitted together).
  std::string model = "pinhole-radtan";
  double outlier_sigma = 4.0;         // corners beyond this many sigma are dropped
  bool board_warp = false;            // solve the board's warp (calibrate.h)
  bool saddle_fit = false;            // checkerboards: DetectOptions::fit_saddles (detect.h)
  io::Bayer bayer = io::Bayer::none;  // raw mosaics: demosaiced to gray
  // Also the detections fitted to the given rig's lenses and stereo poses, only the boards free
  // (rigcal check: the new data at the stored calibration): the report's `at_rig` and the
  // residual figures named `..._at_rig_<unit>`; a note when the rig's cameras cannot be fitted.
  bool fit_at_rig = false;
};

struct StepInputs {
  std::filesystem::path target;  // target YAML
  io::ImageSet images;           // per camera (named as in the rig), per frame
  // The rig to update; none: a new rig of these cameras, the first one the base frame.
  std::optional<rig::Rig> rig;
  std::filesystem::path corners_cache;  // an earlier corners.vnl to reuse ("" or absent: none)
};

// Throws rigcal::Error on bad input: an unreadable image, images of one camera of different
// sizes, a target found in no image, a rig sensor of that name that is not a camera.
report::StepResult calibrate_cameras(const StepInputs& inputs, const StepOptions& options,
                                     const report::Progress& progress = {});

}  // namespace rigcal::camera
