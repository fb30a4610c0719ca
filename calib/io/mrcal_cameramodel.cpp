#include "rigcal/io/mrcal_cameramodel.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "rigcal/camera/lens.h"
#include "rigcal/core/error.h"
#include "rigcal/core/se3.h"
#include "rigcal/core/text.h"
#include "rigcal/core/version.h"

extern "C" {
#include <mrcal/mrcal.h>
}

namespace rigcal::io {
namespace {

// mrcal's name of a radtan lens with n coefficients ("" for a lens mrcal has no model for).
std::string lensmodel_of(const rig::CameraModel& m) {
  if (m.distortion_model != rig::DistortionModel::radtan) return "";
  if (m.distortion_coeffs.size() == 4) return "LENSMODEL_OPENCV4";
  if (m.distortion_coeffs.size() == 5) return "LENSMODEL_OPENCV5";
  return "";
}

// mrcal's rt of T_a_b: the Rodrigues vector of R_a_b, then t_a_b.
void append_rt(std::vector<double>& out, const SE3& T_a_b) {
  const Eigen::Vector3d r = rotation_vector(T_a_b.R);
  out.insert(out.end(), {r.x(), r.y(), r.z(), T_a_b.t.x(), T_a_b.t.y(), T_a_b.t.z()});
}

std::string number_list(const std::vector<double>& values) {
  std::string s = "[ ";
  for (size_t i = 0; i < values.size(); ++i) s += (i ? ", " : "") + format_double(values[i]);
  return s + " ]";
}

// mrcal stores None as the empty string.
NpyArray none() { return npy_string(""); }

}  // namespace

std::optional<MrcalBoard> mrcal_board(const camera::Target& target, std::string* why_not) {
  MrcalBoard board;
  if (target.type == camera::TargetType::checkerboard) {
    board.width_n = target.cols;
    board.height_n = target.rows;
    board.spacing = target.square;
    for (int k = 0; k < target.cols * target.rows; ++k) board.grid_index.push_back(k);
    return board;
  }
  // AprilGrid: tag_spacing = b / a puts every corner on a grid of step tag_size / a.
  int a = 0, b = 0;
  for (int d = 1; d <= kMrcalMaxDenominator && a == 0; ++d) {
    const double n = target.tag_spacing * d;
    if (std::llround(n) >= 1 && std::abs(n - std::llround(n)) <= 1e-9)
      a = d, b = static_cast<int>(std::llround(n));
  }
  if (a == 0) {
    if (why_not) {
      *why_not = fmt::format(
          "AprilGrid '{}': its tag_spacing {} is not a fraction b/a with a <= {}, so its corners "
          "lie on no uniform grid, mrcal 2.2's only board",
          target.name, format_double(target.tag_spacing), kMrcalMaxDenominator);
    }
    return std::nullopt;
  }
  const auto grid = [&](int k) { return (k / 2) * (a + b) + (k % 2) * a; };
  board.width_n = grid(2 * target.cols - 1) + 1;
  board.height_n = grid(2 * target.rows - 1) + 1;
  board.spacing = target.tag_size / a;
  if (static_cast<long long>(board.width_n) * board.height_n > kMrcalMaxGridPoints) {
    if (why_not) {
      *why_not = fmt::format(
          "AprilGrid '{}': its corners lie on a uniform grid of {} x {} points (tag_spacing {} = "
          "{}/{}), more than the {} an mrcal board observation may have here",
          target.name, board.width_n, board.height_n, format_double(target.tag_spacing), b, a,
          kMrcalMaxGridPoints);
    }
    return std::nullopt;
  }
  // object_points' order: row by row from the bottom-left, 2 cols corners a row.
  for (int n = 0; n < 2 * target.rows; ++n) {
    for (int m = 0; m < 2 * target.cols; ++m)
      board.grid_index.push_back(grid(n) * board.width_n + grid(m));
  }
  return board;
}

std::string mrcal_unsupported(const camera::CalibrationResult& result, const camera::Target& target,
                              const std::vector<std::string>& names) {
  if (names.size() != result.cameras.size())
    throw std::invalid_argument("mrcal_unsupported: one name a camera");
  for (size_t c = 0; c < result.cameras.size(); ++c) {
    const rig::CameraModel& m = result.cameras[c].model;
    if (m.distortion_model != rig::DistortionModel::radtan) {
      return fmt::format(
          "camera '{}' is pinhole-equidistant (Kannala-Brandt, as cv::fisheye), which mrcal 2.2 "
          "has no lens model for",
          names[c]);
    }
    if (lensmodel_of(m).empty()) {
      return fmt::format(
          "camera '{}' has {} radtan coefficients; mrcal's LENSMODEL_OPENCV4 and OPENCV5 have 4 "
          "and 5",
          names[c], m.distortion_coeffs.size());
    }
    if (lensmodel_of(m) != lensmodel_of(result.cameras[0].model)) {
      return fmt::format(
          "cameras '{}' ({}) and '{}' ({}) differ in lens model; mrcal 2.2's optimization_inputs "
          "hold one for all cameras",
          names[0], lensmodel_of(result.cameras[0].model), names[c], lensmodel_of(m));
    }
  }
  std::string why_not;
  if (!mrcal_board(target, &why_not)) return why_not;
  return "";
}

std::vector<NamedArray> mrcal_optimization_inputs(const camera::CalibrationResult& r,
                                                  const camera::Target& target,
                                                  const std::vector<std::string>& names) {
  if (const std::string why = mrcal_unsupported(r, target, names); !why.empty())
    throw Error("no mrcal optimization_inputs: " + why);
  const MrcalBoard board = *mrcal_board(target);
  const size_t n_cams = r.cameras.size();
  const size_t grid_points = static_cast<size_t>(board.width_n) * board.height_n;

  // The (frame, camera) pairs with an inlier corner, in mrcal's order; frames renumbered.
  std::map<std::pair<int, int>, std::vector<const camera::CornerResidual*>> views;
  std::map<int, int> with_inlier;  // frame -> its corners' count
  for (const camera::CornerResidual& cr : r.residuals) {
    if (cr.frame < 0 || static_cast<size_t>(cr.frame) >= r.T_cam0_board.size() ||
        !r.T_cam0_board[cr.frame] || cr.camera < 0 || static_cast<size_t>(cr.camera) >= n_cams ||
        cr.point < 0 || static_cast<size_t>(cr.point) >= board.grid_index.size()) {
      throw std::invalid_argument(fmt::format(
          "mrcal_optimization_inputs: corner {} of camera {}, frame {} outside the result",
          cr.point, cr.camera, cr.frame));
    }
    views[{cr.frame, cr.camera}].push_back(&cr);
    if (!cr.outlier) ++with_inlier[cr.frame];
  }
  std::map<int, int32_t> iframe;
  std::vector<double> frames_rt;
  for (const auto& [f, count] : with_inlier) {
    iframe[f] = static_cast<int32_t>(iframe.size());
    append_rt(frames_rt, *r.T_cam0_board[f]);
  }
  std::vector<double> observations;
  std::vector<int32_t> indices;
  size_t n_obs = 0;
  for (const auto& [key, corners] : views) {
    const auto [frame, cam] = key;
    bool any_inlier = false;
    for (const camera::CornerResidual* cr : corners) any_inlier |= !cr->outlier;
    if (!any_inlier) continue;
    // x, y, weight per grid point: -1 weight for what is not an inlier (mrcal's "ignore").
    const size_t at = observations.size();
    observations.resize(at + 3 * grid_points, -1.0);
    for (const camera::CornerResidual* cr : corners) {
      double* p = &observations[at + 3 * static_cast<size_t>(board.grid_index[cr->point])];
      p[0] = cr->observed.x();
      p[1] = cr->observed.y();
      p[2] = cr->outlier ? -1.0 : 1.0;
    }
    indices.insert(indices.end(), {iframe.at(frame), cam, cam - 1});
    ++n_obs;
  }

  std::vector<double> intrinsics, extrinsics_rt;
  std::vector<int32_t> imagersizes;
  for (size_t c = 0; c < n_cams; ++c) {
    const rig::CameraModel& m = r.cameras[c].model;
    const std::vector<double> k = camera::intrinsics_vector(m);
    intrinsics.insert(intrinsics.end(), k.begin(), k.end());
    imagersizes.insert(imagersizes.end(), {m.width, m.height});
    if (c > 0) append_rt(extrinsics_rt, r.T_cam_cam0[c]);
  }
  const size_t nk = intrinsics.size() / n_cams;
  const size_t W = static_cast<size_t>(board.width_n), H = static_cast<size_t>(board.height_n);
  NpyArray warp = none();
  if (r.board_warp_m)
    warp = npy_array(std::vector<double>{r.board_warp_m->x(), r.board_warp_m->y()}, {2});

  return {{"intrinsics", npy_array(intrinsics, {n_cams, nk})},
          {"extrinsics_rt_fromref", npy_array(extrinsics_rt, {n_cams - 1, 6})},
          {"frames_rt_toref", npy_array(frames_rt, {iframe.size(), 6})},
          {"points", none()},
          {"observations_board", npy_array(observations, {n_obs, H, W, 3})},
          {"indices_frame_camintrinsics_camextrinsics", npy_array(indices, {n_obs, 3})},
          {"observations_point", none()},
          {"indices_point_camintrinsics_camextrinsics", none()},
          {"lensmodel", npy_string(lensmodel_of(r.cameras[0].model))},
          {"imagersizes", npy_array(imagersizes, {n_cams, 2})},
          {"calobject_warp", warp},
          {"do_optimize_intrinsics_core", npy_bool(true)},
          {"do_optimize_intrinsics_distortions", npy_bool(true)},
          {"do_optimize_extrinsics", npy_bool(true)},
          {"do_optimize_frames", npy_bool(true)},
          {"do_optimize_calobject_warp", npy_bool(r.board_warp_m.has_value())},
          {"calibration_object_spacing", npy_scalar(board.spacing)},
          {"do_apply_regularization", npy_bool(false)},
          {"do_apply_outlier_rejection", npy_bool(false)}};
}

std::vector<OutputFile> mrcal_cameramodels(const camera::CalibrationResult& r,
                                           const camera::Target& target,
                                           const std::vector<std::string>& names,
                                           ZipMethod method) {
  const std::string blob = base85(npz_bytes(mrcal_optimization_inputs(r, target, names), method));
  std::string index;
  for (size_t c = 0; c < names.size(); ++c)
    index += fmt::format("{}{}: '{}'", c ? ", " : "", c, names[c]);
  std::vector<OutputFile> files;
  for (size_t c = 0; c < names.size(); ++c) {
    const rig::CameraModel& m = r.cameras[c].model;
    const std::string lensmodel = lensmodel_of(m);
    std::vector<double> rt;
    append_rt(rt, r.T_cam_cam0[c]);
    std::string text = fmt::format(
        "# mrcal camera model of '{}' with the optimization_inputs of its calibration, written "
        "by {}.\n"
        "# extrinsics = rt_cam_ref, the reference frame being camera 0 ('{}') of the calibration.\n"
        "# icam_intrinsics: the camera's index in optimization_inputs ({}).\n"
        "{{\n"
        "    'lensmodel':  '{}',\n"
        "    'intrinsics': {},\n"
        "    'imagersize': [{}, {}],\n"
        "    'extrinsics': {},\n"
        "    'icam_intrinsics': {},\n",
        names[c], version_string(), names[0], index, lensmodel,
        number_list(camera::intrinsics_vector(m)), m.width, m.height, number_list(rt), c);
    // The blob on one line: libmrcal's parser does not join adjacent literals.
    text += "    'optimization_inputs': b'" + blob + "',\n}\n";

    // Self-check with libmrcal's own reader (which skips optimization_inputs).
    if (text.size() > static_cast<size_t>(std::numeric_limits<int>::max()))
      throw Error(fmt::format("{}: the .cameramodel text would be over 2 GiB", names[c]));
    check_with_libmrcal(text, lensmodel, names[c]);
    files.push_back({names[c] + ".cameramodel", std::move(text)});
  }
  return files;
}

void check_with_libmrcal(const std::string& text, const std::string& lensmodel,
                         const std::string& name) {
  mrcal_cameramodel_t* model =
      mrcal_read_cameramodel_string(text.c_str(), static_cast<int>(text.size()));
  if (model == nullptr)
    throw Error(fmt::format("{}: libmrcal did not accept the generated .cameramodel text", name));
  const std::string read_lensmodel = mrcal_lensmodel_name_unconfigured(&model->lensmodel);
  mrcal_free_cameramodel(&model);
  if (read_lensmodel != lensmodel) {
    throw Error(fmt::format("{}: libmrcal read lens model {} instead of {}", name, read_lensmodel,
                            lensmodel));
  }
}

}  // namespace rigcal::io
