#include "rigcal/lidar_camera/step.h"

#include <fmt/format.h>

#include <cmath>

#include "rigcal/camera/detect.h"
#include "rigcal/core/error.h"
#include "rigcal/io/image_io.h"
#include "rigcal/io/image_sets.h"
#include "rigcal/io/point_cloud_io.h"
#include "rigcal/io/target_yaml.h"
#include "rigcal/lidar_camera/report.h"
#include "rigcal/report/rotation.h"

namespace rigcal::lidar_camera {
namespace fs = std::filesystem;

StepInputs pairs_from_recording(const fs::path& dir, const rig::Rig& rig, const StepOptions& o) {
  StepInputs in;
  in.rig = rig;
  const io::StampedFolder images =
      io::read_stamped_folder(dir / (o.camera == "cam_l" ? "camera_left" : "camera_right"), ".png");
  const io::StampedFolder scans = io::read_stamped_folder(dir / "ouster_points", ".bin");
  if (images.files.empty()) throw Error(fmt::format("{}: no images", dir.string()));
  if (scans.files.empty()) throw Error(fmt::format("{}: no scans", dir.string()));
  auto on_base_clock = [&](std::vector<Time> t, const std::string& sensor) {
    const Time offset = Time::from_seconds(rig::sensor(rig, sensor).time_offset);
    for (Time& x : t) x = x + offset;
    return t;
  };
  const std::vector<std::optional<size_t>> scan_of =
      io::pair_by_stamp(on_base_clock(images.stamps, o.camera),
                        on_base_clock(scans.stamps, o.lidar), Time::from_seconds(o.max_dt_s));
  for (size_t k = 0; k < scan_of.size(); ++k) {
    if (!scan_of[k]) {
      in.notes.push_back(
          fmt::format("{}: no scan within {} s, skipped", images.files[k], o.max_dt_s));
      continue;
    }
    in.images.push_back(images.files[k]), in.scans.push_back(scans.files[*scan_of[k]]);
  }
  if (in.images.empty()) {
    throw Error(
        fmt::format("{}: no image has a scan within {} s (--max-dt)", dir.string(), o.max_dt_s));
  }
  return in;
}

StepInputs pairs_from_globs(const std::string& images, const std::string& scans,
                            const rig::Rig& rig) {
  StepInputs in;
  in.rig = rig;
  const std::vector<std::string> image_glob = io::glob_files(images),
                                 scan_glob = io::glob_files(scans);
  if (image_glob.empty()) throw Error(fmt::format("no images match {}", images));
  if (scan_glob.empty()) throw Error(fmt::format("no scans match {}", scans));
  // Paired by the frame number in the names; an image or a scan without its partner is an error.
  const io::ImageSet set = io::pair_by_frame_number({{"images", image_glob}, {"scans", scan_glob}});
  for (size_t k = 0; k < set.files[0].size(); ++k) {
    const std::string &img = set.files[0][k], &scan = set.files[1][k];
    if (img.empty() || scan.empty()) {
      throw Error(fmt::format("{} has no {} with the same frame number", img.empty() ? scan : img,
                              img.empty() ? "image" : "scan"));
    }
    in.images.push_back(img), in.scans.push_back(scan);
  }
  return in;
}

report::StepResult calibrate_lidar_camera(const StepInputs& in, const StepOptions& o,
                                          const report::Progress& progress) {
  rig::Rig rig = in.rig;
  const rig::Sensor* cam_sensor = rig::find_sensor(rig, o.camera);
  if (!cam_sensor || cam_sensor->type != rig::SensorType::camera)
    throw Error(fmt::format("--camera {}: no such camera in {}", o.camera, in.rig_source));
  if (!rig::find_sensor(rig, o.lidar))
    throw Error(fmt::format("--lidar {}: no such sensor in {}", o.lidar, in.rig_source));
  const rig::CameraModel cam = cam_sensor->camera;
  const camera::Target target = io::read_target_file(in.target);
  const camera::Outline outline = camera::outline(target);
  BoardSearch search;
  search.board_width_m = o.board_width_m.value_or(outline.width());
  search.board_height_m = o.board_height_m.value_or(outline.height());
  if (o.roi) search.roi = *o.roi;

  std::vector<PairInput> pairs(in.images.size());
  std::vector<cv::Mat> shown(in.images.size());
  for (size_t k = 0; k < in.images.size(); ++k) {
    report::tell(progress, "pair", k + 1, in.images.size());
    const cv::Mat gray = io::read_gray(in.images[k], o.bayer);
    if (gray.cols != cam.width || gray.rows != cam.height) {
      throw Error(fmt::format("{}: {} x {} px, the rig's {} is {} x {}", in.images[k], gray.cols,
                              gray.rows, o.camera, cam.width, cam.height));
    }
    shown[k] = gray;
    const camera::Detection det = camera::detect(gray, target);
    if (det.found && det.pixels.size() == camera::object_points(target).size())
      pairs[k].camera = board_in_camera(cam, target, det.pixels, o.corner_sigma_px);
    pairs[k].scan = io::read_point_cloud(in.scans[k]);
  }
  std::optional<SE3> prior;
  if (o.camera != o.lidar) {
    const SE3 T = rig::T_a_b(rig, o.camera, o.lidar);
    if (!T.t.isZero()) prior = T;  // a rig with the camera placed already
  }
  size_t in_images = 0;
  for (const PairInput& p : pairs) in_images += p.camera.has_value();
  const Calibration c = [&] {
    try {
      return calibrate(pairs, search, prior);
    } catch (const Error& e) {
      // Which data: the folders, and how many images showed the board (the scans' boards are
      // searched inside calibrate).
      const std::string images_dir =
          std::filesystem::path(in.images.front()).parent_path().string();
      const std::string scans_dir = std::filesystem::path(in.scans.front()).parent_path().string();
      throw Error(fmt::format("{} and {}: {} (the target {} was found in {} of {} images)",
                              images_dir, scans_dir, e.what(), in.target.string(), in_images,
                              pairs.size()));
    }
  }();
  const Solution& s = c.solution;

  report::StepResult out;
  out.step = "lidar_camera";
  for (size_t k = 0; k < c.pairs.size(); ++k)
    out.summary.push_back(fmt::format("pair {:2d}: {}", k + 1, c.pairs[k].note));
  const SE3& T = s.T_camera_lidar;
  out.summary.push_back(fmt::format(
      "T_{}_{}: t = [{:.4f} {:.4f} {:.4f}] ± [{:.4f} {:.4f} {:.4f}] m, {}", o.camera, o.lidar,
      T.t.x(), T.t.y(), T.t.z(), s.translation_sigma_m.x(), s.translation_sigma_m.y(),
      s.translation_sigma_m.z(), report::rotation_text(T.R, s.rotation_sigma_deg, o.camera)));
  out.summary.push_back(fmt::format(
      "observability: normals' singular values {:.3f} {:.3f} {:.3f}, condition {:.1f}; noise "
      "scale {:.2f}",
      s.observability.singular_values[0], s.observability.singular_values[1],
      s.observability.singular_values[2], s.observability.condition, s.noise_scale));
  out.notes = in.notes;
  out.warnings = outlier_warnings(s);
  // The boards at the given rig's extrinsic, when asked: their whitened level and RMS.
  nlohmann::json at_rig;
  double noise_scale_at = 0, angle_rms_deg = 0, distance_rms_m = 0;
  const std::optional<SE3> fit_at = o.fit_at ? o.fit_at : prior;
  if (o.fit_at_rig && fit_at) {
    std::vector<BoardPair> used;
    for (size_t k = 0; k < pairs.size(); ++k) {
      if (c.pairs[k].used)
        used.push_back({pairs[k].camera->plane, c.pairs[k].lidar.plane, c.pairs[k].lidar.points});
    }
    const std::vector<PairResidual> residuals = residuals_at(used, *fit_at);
    const double n = std::max<double>(1, residuals.size());
    nlohmann::json chi2 = nlohmann::json::array();
    for (const PairResidual& r : residuals) {
      noise_scale_at += r.chi2 / (3 * n);
      angle_rms_deg += r.normal_angle_deg * r.normal_angle_deg / n;
      distance_rms_m += r.distance_m * r.distance_m / n;
      chi2.push_back(r.chi2);
    }
    noise_scale_at = std::sqrt(noise_scale_at);
    angle_rms_deg = std::sqrt(angle_rms_deg), distance_rms_m = std::sqrt(distance_rms_m);
    at_rig["at_rig"] = {
        {"definition",
         "the boards of the pairs used, at the given rig's extrinsic (not re-estimated): "
         "noise_scale = sqrt(sum chi2 / (3 pairs)), 1 when they fit as their covariances say"},
        {"noise_scale", noise_scale_at},
        {"normal_angle_rms_deg", angle_rms_deg},
        {"distance_rms_m", distance_rms_m},
        {"pair_chi2", chi2}};
  } else if (o.fit_at_rig) {
    out.notes.push_back(fmt::format("the rig places no {} against {}: nothing to fit the boards to",
                                    o.camera, o.lidar));
  }

  LidarCameraInputs rin{in.images,
                        in.scans,
                        in.target.string(),
                        in.rig_source,
                        o.camera,
                        search.board_width_m,
                        search.board_height_m};
  out.report_files = lidar_camera_report_files("", rin, pairs, c, cam, shown);
  report::finish_report(out, "lidar_camera.json", at_rig);

  // The camera placed from the LiDAR: T_b(camera) = T_b(lidar) T_camera_lidar^-1; every other
  // camera keeps its pose relative to this one (the stereo extrinsic).
  const SE3 T_b_cam_old = rig::sensor(rig, o.camera).T_base_sensor;
  const SE3 T_b_cam = rig::sensor(rig, o.lidar).T_base_sensor * T.inverse();
  for (rig::Sensor& other : rig.sensors) {
    if (other.type == rig::SensorType::camera && other.name != o.camera) {
      other.T_base_sensor = T_b_cam * T_b_cam_old.inverse() * other.T_base_sensor;
      out.wrote.push_back(other.name);
    }
  }
  rig::sensor(rig, o.camera).T_base_sensor = T_b_cam;
  out.wrote.push_back(o.camera);
  out.rig = rig;

  size_t used = 0;
  for (const PairOutcome& p : c.pairs) used += p.used;
  out.residuals = {{"pairs_used", static_cast<double>(used), ""},
                   {"pairs", static_cast<double>(c.pairs.size()), ""},
                   {"noise_scale", s.noise_scale, ""},
                   {"condition", s.observability.condition, ""}};
  if (!at_rig.is_null()) {
    out.residuals.push_back({"noise_scale_at_rig", noise_scale_at, ""});
    out.residuals.push_back({"normal_angle_rms_at_rig_deg", angle_rms_deg, "deg"});
    out.residuals.push_back({"distance_rms_at_rig_m", distance_rms_m, "m"});
  }
  const std::string name = fmt::format("T_{}_{}", o.camera, o.lidar);
  report::add_pose_uncertainty(out.sigmas, out.correlations, name, s.covariance);
  out.inputs.push_back({"target", in.target});
  for (size_t k = 0; k < in.images.size(); ++k) {
    out.inputs.push_back({"images", in.images[k]});
    out.inputs.push_back({"scans", in.scans[k]});
  }
  return out;
}

}  // namespace rigcal::lidar_camera
