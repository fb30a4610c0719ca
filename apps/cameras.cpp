// rigcal cameras: intrinsics of one or two cameras and their stereo extrinsic (doc/cameras.md).
#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "cli.h"
#include "rigcal/camera/calibrate.h"
#include "rigcal/camera/uncertainty.h"
#include "rigcal/core/error.h"
#include "rigcal/core/stats.h"
#include "rigcal/core/text.h"
#include "rigcal/core/time.h"
#include "rigcal/core/version.h"
#include "rigcal/io/camera_report.h"
#include "rigcal/io/files.h"
#include "rigcal/io/image_sets.h"
#include "rigcal/io/target_yaml.h"
#include "rigcal/rig/rig_yaml.h"

namespace rigcal::cli {
namespace {

namespace fs = std::filesystem;

struct Options {
  std::string target, session, model = "pinhole-radtan", rig, out, report;
  std::vector<std::string> cameras;  // NAME=GLOB
  double k_sigma = 4.0;
  std::string bayer;  // "", rggb, bggr, grbg, gbrg
};

void run(const Options& o) {
  const camera::Target target = io::read_target_file(o.target);
  camera::CalibrationOptions copt;
  if (o.model == "pinhole-radtan")
    copt.model = rig::DistortionModel::radtan, copt.radtan_coefficients = 4;
  else if (o.model == "pinhole-radtan5")
    copt.model = rig::DistortionModel::radtan, copt.radtan_coefficients = 5;
  else if (o.model == "pinhole-equidistant")
    copt.model = rig::DistortionModel::equidistant;
  else
    throw Error(fmt::format(
        "--model: expected pinhole-radtan, pinhole-radtan5 or pinhole-equidistant, got '{}'",
        o.model));
  copt.outlier_k_sigma = o.k_sigma;

  io::ImageSet in;
  if (!o.session.empty()) {
    in = io::read_session_images(o.session);
  } else {
    if (o.cameras.empty())
      throw Error("give --camera NAME=GLOB (once per camera) or --session DIR");
    std::vector<std::pair<std::string, std::vector<std::string>>> cams;
    for (const std::string& spec : o.cameras) {
      const size_t eq = spec.find('=');
      if (eq == std::string::npos || eq == 0)
        throw Error(fmt::format("--camera '{}': expected NAME=GLOB", spec));
      std::vector<std::string> files = io::glob_files(spec.substr(eq + 1));
      if (files.empty())
        throw Error(fmt::format("camera {}: no file matches '{}'", spec.substr(0, eq),
                                spec.substr(eq + 1)));
      cams.emplace_back(spec.substr(0, eq), files);
    }
    in = io::pair_by_frame_number(cams);
  }
  const size_t n_cams = in.names.size(), n_frames = in.files[0].size();

  // Raw Bayer images (like VBR's): OpenCV names the pattern by the 2x2 block's second row.
  int bayer_code = -1;
  if (o.bayer == "rggb")
    bayer_code = cv::COLOR_BayerBG2GRAY;
  else if (o.bayer == "bggr")
    bayer_code = cv::COLOR_BayerRG2GRAY;
  else if (o.bayer == "grbg")
    bayer_code = cv::COLOR_BayerGB2GRAY;
  else if (o.bayer == "gbrg")
    bayer_code = cv::COLOR_BayerGR2GRAY;
  else if (!o.bayer.empty())
    throw Error(fmt::format("--bayer: expected rggb, bggr, grbg or gbrg, got '{}'", o.bayer));

  // Detections: from the cache when it was written for this target, else in parallel.
  std::map<std::string, camera::Detection> cache;
  const fs::path cache_path = fs::path(o.report) / "corners.vnl";
  if (fs::exists(cache_path)) cache = io::parse_corners_vnl(io::read_text_file(cache_path), target);
  std::vector<std::pair<size_t, size_t>> jobs;
  for (size_t c = 0; c < n_cams; ++c) {
    for (size_t f = 0; f < n_frames; ++f) {
      if (!in.files[c][f].empty()) jobs.emplace_back(c, f);
    }
  }
  std::vector<camera::CameraInput> cams(n_cams);
  for (size_t c = 0; c < n_cams; ++c) {
    cams[c].name = in.names[c];
    cams[c].frames.assign(n_frames, camera::Detection{});
  }
  std::vector<std::vector<cv::Size>> sizes(n_cams, std::vector<cv::Size>(n_frames));
  std::atomic<size_t> done{0};
  std::atomic<size_t> from_cache{0};
  std::mutex print;
  const bool tty = ::isatty(2);
  tbb::parallel_for(size_t(0), jobs.size(), [&](size_t j) {
    const auto [c, f] = jobs[j];
    const std::string& file = in.files[c][f];
    cv::Mat img = cv::imread(file, cv::IMREAD_GRAYSCALE);
    if (img.empty()) throw Error(fmt::format("{}: cannot read the image", file));
    if (bayer_code >= 0) {
      cv::Mat gray;
      cv::cvtColor(img, gray, bayer_code);  // raw mosaic to gray (edge-aware demosaicing)
      img = gray;
    }
    sizes[c][f] = img.size();
    if (auto it = cache.find(file); it != cache.end()) {
      cams[c].frames[f] = it->second;
      ++from_cache;
    } else {
      cams[c].frames[f] = camera::detect(img, target);
    }
    const size_t k = ++done;
    std::lock_guard<std::mutex> lock(print);
    if (tty) fmt::print(stderr, "\rdetecting the target: {}/{} images", k, jobs.size());
  });
  if (tty) fmt::print(stderr, "\n");
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
    cams[c].width = first.width;
    cams[c].height = first.height;
  }
  size_t found = 0;
  for (const auto& [c, f] : jobs) found += cams[c].frames[f].found;
  fmt::print(
      "target '{}' found in {} of {} images{}\n", target.name, found, jobs.size(),
      from_cache ? fmt::format(" ({} from {})", from_cache.load(), cache_path.string()) : "");
  if (found == 0)
    throw Error(
        fmt::format("the target '{}' was found in none of the {} images; check the target file "
                    "(inner corners, not squares)",
                    target.name, jobs.size()));

  const camera::CalibrationResult r = camera::calibrate(target, cams, copt);

  // The rig: intrinsics of every camera; cameras after the first placed through the stereo
  // extrinsic, the first keeping its T_b.
  rig::Rig rig;
  if (!o.rig.empty()) {
    rig = rig::read_rig_file(o.rig);
  } else {
    rig.base_frame = in.names[0];
    rig.notes.push_back(fmt::format("no --rig: {} is the base frame", in.names[0]));
  }
  for (size_t c = 0; c < n_cams; ++c) {
    rig::Sensor* s = rig::find_sensor(rig, in.names[c]);
    if (!s) {
      rig.sensors.push_back({});
      s = &rig.sensors.back();
      s->name = in.names[c];
      s->type = rig::SensorType::camera;
    }
    if (s->type != rig::SensorType::camera)
      throw Error(fmt::format("sensor '{}' of the rig is not a camera", s->name));
    s->camera = r.cameras[c].model;
  }
  const SE3 T_b_cam0 = rig::sensor(rig, in.names[0]).T_base_sensor;
  for (size_t c = 1; c < n_cams; ++c)
    rig::sensor(rig, in.names[c]).T_base_sensor = T_b_cam0 * r.T_cam_cam0[c].inverse();

  // Report.
  io::CameraReportInput rep;
  rep.camera_names = in.names;
  rep.images = in.files;
  rep.inputs = {{"target", o.target}, {"model", o.model}};
  std::vector<double> distances;
  for (const auto& T : r.T_cam0_board) {
    if (T) distances.push_back(T->t.norm());
  }
  rep.uncertainty_distance_m = median(distances);
  const int nk = static_cast<int>(r.cameras[0].stddev.size());
  for (size_t c = 0; c < n_cams; ++c) {
    rep.uncertainty.push_back(
        camera::projection_uncertainty(r, static_cast<int>(c), rep.uncertainty_distance_m));
    rep.uncertainty_intrinsics_only.push_back(camera::projection_uncertainty_intrinsics_only(
        r.cameras[c].model, r.covariance.block(c * nk, c * nk, nk, nk),
        rep.uncertainty_distance_m));
  }
  nlohmann::json j = io::cameras_json(r, rep);
  for (const std::string& n : in.notes) j["notes"].push_back(n);
  std::vector<io::OutputFile> files;
  files.push_back({o.out, rig::rig_to_yaml(rig)});
  std::vector<std::string> all_images;
  std::vector<camera::Detection> all_detections;
  for (const auto& [c, f] : jobs)
    all_images.push_back(in.files[c][f]), all_detections.push_back(cams[c].frames[f]);
  const fs::path rd = o.report;
  files.push_back({rd / "corners.vnl", io::corners_vnl(target, all_images, all_detections)});
  files.push_back({rd / "cameras.json", j.dump(2) + "\n"});
  for (size_t c = 0; c < n_cams; ++c) {
    const int w = cams[c].width, h = cams[c].height;
    for (size_t f = 0; f < n_frames; ++f) {
      if (cams[c].frames[f].found) {
        files.push_back(
            {rd / fmt::format("{}_corners.png", in.names[c]),
             io::encode_png(io::corners_png(cv::imread(in.files[c][f], cv::IMREAD_GRAYSCALE),
                                            cams[c].frames[f]))});
        break;
      }
    }
    files.push_back({rd / fmt::format("{}_residuals.png", in.names[c]),
                     io::encode_png(io::residuals_png(r, static_cast<int>(c), w, h, 100.0))});
    files.push_back({rd / fmt::format("{}_coverage.png", in.names[c]),
                     io::encode_png(io::coverage_png(r, static_cast<int>(c), w, h))});
    files.push_back({rd / fmt::format("{}_uncertainty.png", in.names[c]),
                     io::encode_png(io::uncertainty_png(rep.uncertainty[c], w, h))});
  }
  io::write_files_atomic(files);

  fmt::print(
      "RMS reprojection error: {:.4f} px per corner (2-D, OpenCV's), {:.4f} px per coordinate "
      "(mrcal's); {} outlier corners of {}\n",
      r.rms_2d_px, r.rms_coord_px, r.n_outliers, r.residuals.size());
  for (size_t c = 0; c < n_cams; ++c) {
    const auto& m = r.cameras[c].model;
    const auto& s = r.cameras[c].stddev;
    fmt::print(
        "{}: fx {:.3f} ± {:.3f}, fy {:.3f} ± {:.3f}, cx {:.3f} ± {:.3f}, cy {:.3f} ± {:.3f} px ({} "
        "views); projection 1-sigma at {:.2f} m: mean {:.3f}, max {:.3f} px\n",
        in.names[c], m.fx, s[0], m.fy, s[1], m.cx, s[2], m.cy, s[3], r.cameras[c].n_views,
        rep.uncertainty_distance_m, rep.uncertainty[c].mean_px, rep.uncertainty[c].max_px);
  }
  for (size_t c = 1; c < n_cams; ++c) {
    fmt::print(
        "T_{}_{}: baseline {:.5f} m, t = [{:.5f} {:.5f} {:.5f}] ± [{:.5f} {:.5f} {:.5f}] m, "
        "rotation ± [{:.4f} {:.4f} {:.4f}] deg\n",
        in.names[c], in.names[0], r.T_cam_cam0[c].t.norm(), r.T_cam_cam0[c].t.x(),
        r.T_cam_cam0[c].t.y(), r.T_cam_cam0[c].t.z(), r.translation_stddev_m[c].x(),
        r.translation_stddev_m[c].y(), r.translation_stddev_m[c].z(), r.rotation_stddev_deg[c].x(),
        r.rotation_stddev_deg[c].y(), r.rotation_stddev_deg[c].z());
  }
  for (const std::string& n : r.notes) fmt::print("note: {}\n", n);
  for (const std::string& n : in.notes) fmt::print("note: {}\n", n);
  fmt::print("wrote {} and {}/cameras.json, corners.vnl and PNGs\n", o.out, o.report);
}

}  // namespace

void add_cameras(CLI::App& app) {
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "cameras",
      "Calibrate one or two cameras (intrinsics, and the stereo extrinsic) from images of a "
      "target\n"
      "(doc/cameras.md). Images pair by the frame number in their file names, or by timestamp\n"
      "with --session. Writes the rig (OUT.yaml) and a report folder: cameras.json (every figure\n"
      "with its definition), corners.vnl (detections, mrcal's format, reused on the next run),\n"
      "and PNGs per camera: corners, residual vectors x100, coverage, projection uncertainty.");
  cmd->add_option("--target", o->target, "target YAML (targets/*.yaml; Kalibr's format)")
      ->required();
  cmd->add_option("--camera", o->cameras, "NAME=GLOB, e.g. cam_l='left/*.png' (once per camera)");
  cmd->add_option("--session", o->session, "a session folder with camera_left/ and camera_right/");
  cmd->add_option("--model", o->model, "pinhole-radtan | pinhole-radtan5 | pinhole-equidistant")
      ->capture_default_str();
  cmd->add_option("--rig", o->rig, "rig to update (default: a new rig of these cameras)");
  cmd->add_option("--out", o->out, "output calibration YAML")->required();
  cmd->add_option("--report", o->report, "report folder")->required();
  cmd->add_option("--outlier-sigma", o->k_sigma,
                  "drop corners with a residual beyond this many sigma")
      ->capture_default_str();
  cmd->add_option("--bayer", o->bayer,
                  "raw Bayer images: rggb | bggr | grbg | gbrg (demosaiced to gray)");
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::cli
