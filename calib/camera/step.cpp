#include "rigcal/camera/step.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <map>
#include <mutex>
#include <set>
#include <tuple>

#include "rigcal/camera/calibrate.h"
#include "rigcal/camera/rectify.h"
#include "rigcal/camera/report.h"
#include "rigcal/camera/uncertainty.h"
#include "rigcal/core/error.h"
#include "rigcal/core/stats.h"
#include "rigcal/core/text.h"
#include "rigcal/io/files.h"
#include "rigcal/io/mrcal_cameramodel.h"
#include "rigcal/io/target_yaml.h"
#include "rigcal/report/json.h"
#include "rigcal/report/rotation.h"
#include "rigcal/rig/rig_yaml.h"

namespace rigcal::camera {
namespace {

// A lens model by rigcal's name or Kalibr's (Kalibr's pinhole-equi is pinhole-equidistant).
void set_model(std::string_view name, CalibrationOptions& c) {
  if (name == "pinhole-radtan")
    c.model = rig::DistortionModel::radtan, c.radtan_coefficients = 4;
  else if (name == "pinhole-radtan5")
    c.model = rig::DistortionModel::radtan, c.radtan_coefficients = 5;
  else if (name == "pinhole-equidistant" || name == "pinhole-equi")
    c.model = rig::DistortionModel::equidistant;
  else if (name == "pinhole-fov" || name == "omni-none" || name == "omni-radtan" ||
           name == "eucm-none" || name == "ds-none")
    throw Error(fmt::format(
        "--model: Kalibr's {} has no counterpart in rigcal; its models are pinhole-radtan (also "
        "pinhole-radtan5, with k3) and pinhole-equidistant (Kalibr's pinhole-equi)",
        name));
  else
    throw Error(fmt::format(
        "--model: expected pinhole-radtan, pinhole-radtan5 or pinhole-equidistant (or Kalibr's "
        "pinhole-equi), got '{}'",
        name));
}

// --model MODEL for every camera, or NAME=MODEL,NAME=MODEL per camera (every camera named).
CalibrationOptions calibration_options(const StepOptions& o,
                                       const std::vector<std::string>& names) {
  CalibrationOptions c;
  c.outlier_k_sigma = o.outlier_sigma;
  c.board_warp = o.board_warp;
  if (o.model.find('=') == std::string::npos) {
    set_model(o.model, c);
    return c;
  }
  std::map<std::string, std::string> per_camera;
  for (std::string_view item : split_fields(o.model)) {
    const size_t eq = item.find('=');
    if (eq == std::string_view::npos)
      throw Error(fmt::format("--model: expected NAME=MODEL in a list, got '{}'", item));
    const std::string name(item.substr(0, eq));
    if (std::find(names.begin(), names.end(), name) == names.end())
      throw Error(
          fmt::format("--model: no camera '{}' (the cameras: {})", name, fmt::join(names, ", ")));
    per_camera[name] = std::string(item.substr(eq + 1));
  }
  for (const std::string& name : names) {
    const auto it = per_camera.find(name);
    if (it == per_camera.end()) throw Error(fmt::format("--model: no model for camera '{}'", name));
    CalibrationOptions one = c;
    set_model(it->second, one);
    c.per_camera.push_back({one.model, one.radtan_coefficients});
  }
  return c;
}

struct Detections {
  std::vector<CameraInput> cameras;
  std::vector<std::pair<size_t, size_t>> jobs;  // (camera, frame) with an image
  size_t found = 0, from_cache = 0;
};

// The target in every image: from the cache where it holds the image, else detected (in
// parallel); each camera's image size checked to be one.
Detections detect_all(const Target& target, const io::ImageSet& in, const StepOptions& o,
                      const std::filesystem::path& cache_path, const report::Progress& progress) {
  const size_t n_cams = in.names.size(), n_frames = in.files[0].size();
  std::map<std::string, Detection> cache;
  if (!cache_path.empty() && std::filesystem::exists(cache_path))
    cache = parse_corners_vnl(io::read_text_file(cache_path), target, o.saddle_fit);
  Detections d;
  for (size_t c = 0; c < n_cams; ++c) {
    for (size_t f = 0; f < n_frames; ++f) {
      if (!in.files[c][f].empty()) d.jobs.emplace_back(c, f);
    }
  }
  d.cameras.resize(n_cams);
  for (size_t c = 0; c < n_cams; ++c) {
    d.cameras[c].name = in.names[c];
    d.cameras[c].frames.assign(n_frames, Detection{});
  }
  std::vector<std::vector<cv::Size>> sizes(n_cams, std::vector<cv::Size>(n_frames));
  std::atomic<size_t> done{0}, from_cache{0};
  std::mutex tell;
  tbb::parallel_for(size_t(0), d.jobs.size(), [&](size_t j) {
    const auto [c, f] = d.jobs[j];
    const std::string& file = in.files[c][f];
    const cv::Mat img = io::read_gray(file, o.bayer);
    sizes[c][f] = img.size();
    if (auto it = cache.find(file); it != cache.end()) {
      d.cameras[c].frames[f] = it->second;
      ++from_cache;
    } else {
      DetectOptions detect_options;
      detect_options.fit_saddles = o.saddle_fit;
      d.cameras[c].frames[f] = detect(img, target, detect_options);
    }
    const size_t k = ++done;
    std::lock_guard<std::mutex> lock(tell);
    report::tell(progress, "detecting the target", k, d.jobs.size());
  });
  for (size_t c = 0; c < n_cams; ++c) {
    cv::Size first;
    std::string first_file;
    for (size_t f = 0; f < n_frames; ++f) {
      if (in.files[c][f].empty()) continue;
      if (first.empty()) first = sizes[c][f], first_file = in.files[c][f];
      if (sizes[c][f] != first) {
        throw Error(
            fmt::format("camera {}: {} is {}x{} but {} is {}x{}: one camera, one image size",
                        in.names[c], in.files[c][f], sizes[c][f].width, sizes[c][f].height,
                        first_file, first.width, first.height));
      }
    }
    d.cameras[c].width = first.width;
    d.cameras[c].height = first.height;
  }
  for (const auto& [c, f] : d.jobs) d.found += d.cameras[c].frames[f].found;
  d.from_cache = from_cache;
  return d;
}

// The rig: intrinsics of every camera; cameras after the first placed through the stereo
// extrinsic, the first keeping its T_b.
rig::Rig updated_rig(const StepInputs& in, const CalibrationResult& r) {
  const std::vector<std::string>& names = in.images.names;
  rig::Rig rig;
  if (in.rig) {
    rig = *in.rig;
  } else {
    rig.base_frame = names[0];
    rig.notes.push_back(fmt::format("no --rig: {} is the base frame", names[0]));
  }
  for (size_t c = 0; c < names.size(); ++c) {
    rig::Sensor* s = rig::find_sensor(rig, names[c]);
    if (!s) {
      rig.sensors.push_back({});
      s = &rig.sensors.back();
      s->name = names[c];
      s->type = rig::SensorType::camera;
    }
    if (s->type != rig::SensorType::camera)
      throw Error(fmt::format("sensor '{}' of the rig is not a camera", s->name));
    s->camera = r.cameras[c].model;
  }
  const SE3 T_b_cam0 = rig::sensor(rig, names[0]).T_base_sensor;
  for (size_t c = 1; c < names.size(); ++c)
    rig::sensor(rig, names[c]).T_base_sensor = T_b_cam0 * r.T_cam_cam0[c].inverse();
  return rig;
}

std::vector<std::string> summary_lines(const std::vector<std::string>& names,
                                       const CalibrationResult& r, const CameraReportInput& rep) {
  std::vector<std::string> out;
  out.push_back(fmt::format(
      "RMS reprojection error: {:.4f} px per corner (2-D, OpenCV's), {:.4f} px per coordinate "
      "(mrcal's); {} outlier corners of {}",
      r.rms_2d_px, r.rms_coord_px, r.n_outliers, r.residuals.size()));
  if (r.board_warp_m) {
    out.push_back(fmt::format(
        "board warp: {:.2f} ± {:.2f} mm along x, {:.2f} ± {:.2f} mm along y (the height of each "
        "parabola at the board's middle)",
        1e3 * r.board_warp_m->x(), 1e3 * r.board_warp_stddev_m->x(), 1e3 * r.board_warp_m->y(),
        1e3 * r.board_warp_stddev_m->y()));
  }
  for (size_t c = 0; c < names.size(); ++c) {
    const auto& m = r.cameras[c].model;
    const auto& s = r.cameras[c].stddev;
    out.push_back(fmt::format(
        "{}: fx {:.3f} ± {:.3f}, fy {:.3f} ± {:.3f}, cx {:.3f} ± {:.3f}, cy {:.3f} ± {:.3f} px ({} "
        "views); projection 1-sigma at {:.2f} m: mean {:.3f}, max {:.3f} px",
        names[c], m.fx, s[0], m.fy, s[1], m.cx, s[2], m.cy, s[3], r.cameras[c].n_views,
        rep.uncertainty_distance_m, rep.uncertainty[c].mean_px, rep.uncertainty[c].max_px));
  }
  for (size_t c = 1; c < names.size(); ++c) {
    out.push_back(fmt::format(
        "T_{}_{}: baseline {:.5f} m, t = [{:.5f} {:.5f} {:.5f}] ± [{:.5f} {:.5f} {:.5f}] m, {}",
        names[c], names[0], r.T_cam_cam0[c].t.norm(), r.T_cam_cam0[c].t.x(), r.T_cam_cam0[c].t.y(),
        r.T_cam_cam0[c].t.z(), r.translation_stddev_m[c].x(), r.translation_stddev_m[c].y(),
        r.translation_stddev_m[c].z(),
        report::rotation_text(r.T_cam_cam0[c].R, r.rotation_stddev_deg[c], names[c])));
  }
  return out;
}

// The stereo pair rectified with the estimate (camera 0 left, camera 1 right): the rows of the
// inlier corners both saw, right's less left's, over every view, and the view with the most of
// them as a picture with its epipolar lines.
nlohmann::json stereo_rectification(const CalibrationResult& r, const Detections& d,
                                    const std::vector<std::vector<std::string>>& images,
                                    io::Bayer bayer, std::vector<io::OutputFile>& files) {
  const rig::CameraModel &left = r.cameras[0].model, &right = r.cameras[1].model;
  const Rectification rect = rectify(left, right, r.T_cam_cam0[1]);
  std::set<std::tuple<int, int, int>> outliers;  // camera, frame, point
  for (const CornerResidual& c : r.residuals)
    if (c.outlier) outliers.insert({c.camera, c.frame, c.point});
  const auto inliers = [&](int camera, size_t f) {
    Detection det = d.cameras[size_t(camera)].frames[f];
    Detection kept = det;
    kept.point_ids.clear(), kept.pixels.clear();
    for (size_t i = 0; i < det.point_ids.size(); ++i) {
      if (outliers.count({camera, int(f), det.point_ids[i]})) continue;
      kept.point_ids.push_back(det.point_ids[i]);
      kept.pixels.push_back(det.pixels[i]);
    }
    return kept;
  };
  std::vector<double> rows;
  size_t best = 0, best_count = 0;
  for (size_t f = 0; f < d.cameras[0].frames.size(); ++f) {
    if (!d.cameras[0].frames[f].found || !d.cameras[1].frames[f].found) continue;
    const std::vector<double> v = row_differences(rect, left, right, inliers(0, f), inliers(1, f));
    rows.insert(rows.end(), v.begin(), v.end());
    if (v.size() > best_count) best = f, best_count = v.size();
  }
  if (rows.empty()) return nullptr;
  std::vector<double> magnitudes;
  for (double x : rows) magnitudes.push_back(std::abs(x));
  files.push_back(
      {"stereo_rectified.png", report::encode_png(rectified_pair_png(
                                   rect, left, right, io::read_gray(images[0][best], bayer),
                                   io::read_gray(images[1][best], bayer), inliers(0, best),
                                   inliers(1, best), std::max(8, rect.height / 24)))});
  return {{"definition",
           "both images turned to one orientation whose x axis is the baseline and resampled "
           "into one pinhole (focal length f_px, principal point at the centre); the row of "
           "each inlier corner seen by both cameras, the right image's less the left's: the "
           "corner noise alone gives an RMS near sqrt(2) times the per-coordinate residual "
           "RMS (expected_rms_px), a wrong stereo extrinsic or lens more"},
          {"f_px", rect.f_px},
          {"corners", rows.size()},
          {"row_difference_rms_px", rms(rows)},
          {"row_difference_median_abs_px", median(magnitudes)},
          {"expected_rms_px", std::sqrt(2.0) * r.rms_coord_px},
          // The warning's rule: more than twice the noise's RMS, and 0.1 px.
          {"exceeds_noise", rms(rows) > 2 * std::sqrt(2.0) * r.rms_coord_px + 0.1},
          {"figure_view_left", images[0][best]},
          {"figure_view_right", images[1][best]},
          {"figure", "stereo_rectified.png"}};
}

}  // namespace

report::StepResult calibrate_cameras(const StepInputs& in, const StepOptions& o,
                                     const report::Progress& progress) {
  const Target target = io::read_target_file(in.target);
  const std::vector<std::string>& names = in.images.names;
  const CalibrationOptions copt = calibration_options(o, names);
  if (names.empty() || in.images.files.empty() || in.images.files[0].empty())
    throw Error("the camera step was given no images");
  const size_t n_cams = names.size(), n_frames = in.images.files[0].size();

  const Detections d = detect_all(target, in.images, o, in.corners_cache, progress);
  report::StepResult out;
  out.step = "cameras";
  out.summary.push_back(fmt::format(
      "target '{}' found in {} of {} images{}", target.name, d.found, d.jobs.size(),
      d.from_cache ? fmt::format(" ({} from {})", d.from_cache, in.corners_cache.string()) : ""));
  if (d.found == 0) {
    std::set<std::string> folders;
    for (const auto& [c, f] : d.jobs)
      folders.insert(std::filesystem::path(in.images.files[c][f]).parent_path().string());
    throw Error(fmt::format(
        "{}: the target '{}' ({}) was found in none of the {} images; check the target file "
        "(inner corners, not squares)",
        fmt::join(folders, ", "), target.name, in.target.string(), d.jobs.size()));
  }

  const CalibrationResult r = calibrate(target, d.cameras, copt);
  out.rig = updated_rig(in, r);
  out.wrote = names;

  // Report.
  CameraReportInput rep;
  rep.camera_names = names;
  rep.images = in.images.files;
  rep.inputs = {{"target", in.target.string()}, {"model", o.model}};
  std::vector<double> distances;
  for (const auto& T : r.T_cam0_board) {
    if (T) distances.push_back(T->t.norm());
  }
  rep.uncertainty_distance_m = median(distances);
  for (size_t c = 0; c < n_cams; ++c) {
    rep.uncertainty.push_back(
        projection_uncertainty(r, static_cast<int>(c), rep.uncertainty_distance_m));
    const int at = r.intrinsics_covariance_index[c],
              nk = static_cast<int>(r.cameras[c].stddev.size());
    rep.uncertainty_intrinsics_only.push_back(projection_uncertainty_intrinsics_only(
        r.cameras[c].model, r.covariance.block(at, at, nk, nk), rep.uncertainty_distance_m));
  }
  out.report = cameras_json(r, rep);
  std::optional<FitAtStored> at_rig;
  if (o.fit_at_rig) {
    // The given rig's lenses and stereo poses, when it has every camera with this lens model.
    std::vector<rig::CameraModel> models;
    std::vector<SE3> poses;
    std::string missing;
    for (size_t c = 0; c < n_cams && in.rig; ++c) {
      const rig::Sensor* s = rig::find_sensor(*in.rig, names[c]);
      if (!s || s->type != rig::SensorType::camera || s->camera.fx <= 0 ||
          s->camera.distortion_model != copt.model ||
          s->camera.distortion_coeffs.size() != r.cameras[c].model.distortion_coeffs.size()) {
        missing = names[c];
        break;
      }
      models.push_back(s->camera);
      poses.push_back(rig::T_a_b(*in.rig, names[c], names[0]));
    }
    if (!in.rig || !missing.empty()) {
      out.notes.push_back(fmt::format(
          "the rig has no {} with this lens model ({}): the images are not fitted to it",
          missing.empty() ? "camera" : missing, o.model));
    } else {
      at_rig = fit_at_stored(target, d.cameras, models, poses, copt);
      nlohmann::json per_camera;
      for (size_t c = 0; c < n_cams; ++c) per_camera[names[c]] = at_rig->camera_rms_2d_px[c];
      out.report["at_rig"] = {
          {"definition",
           "the detections fitted to the given rig's lenses and stereo poses, only the boards' "
           "poses free (outliers rejected as in the calibration): RMS over the inlier corners"},
          {"rms_2d_px", at_rig->rms_2d_px},
          {"camera_rms_2d_px", per_camera},
          {"corners", at_rig->corners},
          {"outliers", at_rig->outliers},
          {"views", at_rig->views}};
    }
  }
  for (const std::string& n : in.images.notes) out.report["notes"].push_back(n);
  std::vector<std::string> all_images;
  std::vector<Detection> all_detections;
  for (const auto& [c, f] : d.jobs)
    all_images.push_back(in.images.files[c][f]), all_detections.push_back(d.cameras[c].frames[f]);
  for (size_t c = 0; c < n_cams; ++c) {
    for (const std::string& w : coverage_warnings(r, static_cast<int>(c), names[c],
                                                  d.cameras[c].width, d.cameras[c].height))
      out.warnings.push_back(w);
  }
  if (n_cams == 2) {
    const nlohmann::json rect =
        stereo_rectification(r, d, in.images.files, o.bayer, out.report_files);
    if (!rect.is_null()) {
      out.report["stereo_rectification"] = rect;
      if (rect["exceeds_noise"].get<bool>()) {
        const double rms = rect["row_difference_rms_px"], expected = rect["expected_rms_px"];
        out.warnings.push_back(fmt::format(
            "rectified with this estimate, the corners both cameras saw differ by {:.3f} px RMS "
            "in row, more than twice the {:.3f} px their noise gives: the stereo extrinsic or a "
            "lens does not fit these views (cameras not triggered together while the board "
            "moved, or a lens model too simple)",
            rms, expected));
      }
    }
  }
  out.report_files.push_back(
      {"corners.vnl", corners_vnl(target, all_images, all_detections, o.saddle_fit)});
  out.report_files.push_back({"residuals.csv", residuals_csv(r, names)});
  out.report_files.push_back({"cameras.json", report::json_text(out.report)});
  report::finish_report(out, "cameras.json");
  for (size_t c = 0; c < n_cams; ++c) {
    const int w = d.cameras[c].width, h = d.cameras[c].height;
    for (size_t f = 0; f < n_frames; ++f) {
      if (d.cameras[c].frames[f].found) {
        out.report_files.push_back(
            {fmt::format("{}_corners.png", names[c]),
             report::encode_png(corners_png(io::read_gray(in.images.files[c][f], o.bayer),
                                            d.cameras[c].frames[f]))});
        break;
      }
    }
    out.report_files.push_back(
        {fmt::format("{}_residuals.png", names[c]),
         report::encode_png(residuals_png(r, static_cast<int>(c), w, h, 100.0))});
    out.report_files.push_back({fmt::format("{}_coverage.png", names[c]),
                                report::encode_png(coverage_png(r, static_cast<int>(c), w, h))});
    out.report_files.push_back({fmt::format("{}_uncertainty.png", names[c]),
                                report::encode_png(uncertainty_png(rep.uncertainty[c], w, h))});
  }

  for (const std::string& line : summary_lines(names, r, rep)) out.summary.push_back(line);
  out.notes = r.notes;
  for (const std::string& n : in.images.notes) out.notes.push_back(n);
  // mrcal's tools on this result: <camera>.cameramodel with the solve's optimization_inputs.
  if (const std::string why = io::mrcal_unsupported(r, target, names); why.empty()) {
    for (io::OutputFile& f : io::mrcal_cameramodels(r, target, names))
      out.report_files.push_back(std::move(f));
  } else {
    out.notes.push_back("no <camera>.cameramodel for mrcal's tools in the report: " + why);
  }
  out.residuals = {{"rms_2d_px", r.rms_2d_px, "px"},
                   {"rms_coord_px", r.rms_coord_px, "px"},
                   {"outlier_corners", static_cast<double>(r.n_outliers), ""},
                   {"corners", static_cast<double>(r.residuals.size()), ""}};
  if (at_rig) out.residuals.push_back({"rms_2d_at_rig_px", at_rig->rms_2d_px, "px"});
  if (r.board_warp_m) {
    out.sigmas.push_back({"board_warp.x", r.board_warp_stddev_m->x(), "m"});
    out.sigmas.push_back({"board_warp.y", r.board_warp_stddev_m->y(), "m"});
  }
  // The sigmas and their correlations, from the blocks of the solve's covariance: each lens's
  // fx fy cx cy, then each camera pose after camera 0's (its rotation tangent is Ceres'
  // quaternion one, half the angle: scaled to rigcal's).
  static const char* kIntrinsics[] = {"fx", "fy", "cx", "cy"};
  for (size_t c = 0; c < n_cams; ++c) {
    std::vector<std::string> keys;
    for (int i = 0; i < 4; ++i) {
      keys.push_back(fmt::format("{}.{}", names[c], kIntrinsics[i]));
      out.sigmas.push_back({keys.back(), r.cameras[c].stddev[i], "px"});
    }
    const Eigen::Index at = r.intrinsics_covariance_index[c];
    out.correlations.push_back(
        report::correlation_of(names[c], keys, r.covariance.block(at, at, 4, 4)));
  }
  for (size_t c = 1; c < n_cams; ++c) {
    const Eigen::Index at = r.pose_covariance_index[c];
    Eigen::Matrix<double, 6, 6> covariance = r.covariance.block(at, at, 6, 6);
    covariance.topRows<3>() *= 2.0;
    covariance.leftCols<3>() *= 2.0;
    report::add_pose_uncertainty(out.sigmas, out.correlations,
                                 fmt::format("T_{}_{}", names[c], names[0]), covariance);
  }
  out.inputs.push_back({"target", in.target});
  for (size_t c = 0; c < n_cams; ++c) {
    for (const std::string& f : in.images.files[c]) {
      if (!f.empty()) out.inputs.push_back({"images " + names[c], f});
    }
  }
  return out;
}

}  // namespace rigcal::camera
