#pragma once
// mrcal .cameramodel files of a camera calibration that carry mrcal's `optimization_inputs`
// (doc/exports.md): the solve's final state and inlier corners in mrcal 2.2's layout, so that
// mrcal's own tools (mrcal-show-projection-uncertainty, mrcal-show-residuals, ...) evaluate
// rigcal's result. mrcal recomputes residuals and Jacobian from that state.
//
// The lens models mrcal shares with rigcal: pinhole-radtan is LENSMODEL_OPENCV4, pinhole-radtan5
// LENSMODEL_OPENCV5; pinhole-equidistant (Kannala-Brandt) has no mrcal 2.2 counterpart.
// Frames: camera 0 is mrcal's reference; frames_rt_toref[f] is T_cam0_board of frame f,
// extrinsics_rt_fromref[i-1] is T_cami_cam0, each as mrcal's rt (Rodrigues rotation vector, then
// translation). Every file's own 'extrinsics' is its camera's rt_cam_ref with camera 0 as the
// reference, as mrcal itself writes them.
#include <optional>
#include <string>
#include <vector>

#include "rigcal/camera/calibrate.h"
#include "rigcal/camera/target.h"
#include "rigcal/io/files.h"
#include "rigcal/io/npz.h"

namespace rigcal::io {

// mrcal's board: a uniform grid of width_n x height_n points `spacing` apart, point (row, col)
// at (col * spacing, row * spacing, 0). Object point k of the target is grid point
// grid_index[k] = row * width_n + col; grid points no object point lands on are never observed.
struct MrcalBoard {
  int width_n = 0, height_n = 0;
  double spacing = 0;  // m
  std::vector<int> grid_index;
};

// Checkerboards are mrcal's grid as they are. An AprilGrid is embedded exactly in a finer grid
// when its tag_spacing is a fraction b/a with a <= kMrcalMaxDenominator (Kalibr's 0.3 = 3/10): step
// tag_size / a, corner k of a row at grid column (k / 2) (a + b) + (k % 2) a, and at most
// kMrcalMaxGridPoints grid points. Otherwise nullopt, with the reason in `why_not`.
inline constexpr int kMrcalMaxDenominator = 20;
inline constexpr int kMrcalMaxGridPoints = 20000;
std::optional<MrcalBoard> mrcal_board(const camera::Target& target, std::string* why_not = nullptr);

// Why this calibration has no mrcal counterpart, naming the camera or the target; "" when it has
// one. `names`: the cameras' names, in the order of result.cameras.
std::string mrcal_unsupported(const camera::CalibrationResult& result, const camera::Target& target,
                              const std::vector<std::string>& names);

// mrcal's optimization_inputs dict of the solve, its keys in mrcal's order: the final state
// (intrinsics, camera and board poses, warp), every (frame, camera) with an inlier corner as one
// board observation, sorted by frame then camera (frames without an inlier renumbered away),
// outliers and unobserved grid points at weight -1, every do_optimize_* flag explicit and
// do_apply_regularization False (rigcal's cost has none). Throws rigcal::Error with
// mrcal_unsupported's reason.
std::vector<NamedArray> mrcal_optimization_inputs(const camera::CalibrationResult& result,
                                                  const camera::Target& target,
                                                  const std::vector<std::string>& names);

// `<name>.cameramodel` (relative paths) for every camera, all carrying the same
// optimization_inputs (one line: a bytes literal of the base85 text of its .npz) and
// 'icam_intrinsics'. Each text is read back by libmrcal as a self-check. Throws rigcal::Error
// with mrcal_unsupported's reason.
std::vector<OutputFile> mrcal_cameramodels(const camera::CalibrationResult& result,
                                           const camera::Target& target,
                                           const std::vector<std::string>& names,
                                           ZipMethod method = ZipMethod::deflated);

// Reads `text` back with libmrcal's own reader: throws rigcal::Error naming the camera when it
// does not load or loads with another lens model than `lensmodel`.
void check_with_libmrcal(const std::string& text, const std::string& lensmodel,
                         const std::string& name);

}  // namespace rigcal::io
