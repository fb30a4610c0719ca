// rigcal lidar-camera: T_camera_lidar from image + scan pairs of the board (doc/lidar-camera.md).
#include <fmt/format.h>

#include <algorithm>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "cli.h"
#include "rigcal/camera/detect.h"
#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/io/files.h"
#include "rigcal/io/image_sets.h"
#include "rigcal/io/lidar_camera_report.h"
#include "rigcal/io/point_cloud_io.h"
#include "rigcal/io/target_yaml.h"
#include "rigcal/lidar_camera/solve.h"
#include "rigcal/rig/rig_yaml.h"

namespace rigcal::cli {
namespace {

struct Options {
  std::string target, camera = "cam_r", lidar = "lidar", session, images, scans, rig, out, report,
                      roi, board_size;
  double corner_sigma_px = 0.1;
  double max_dt_s = 0.05;
};

// "a,b,c,d,e,f" -> numbers, named in errors by `what`.
std::vector<double> numbers(const std::string& text, size_t n, const std::string& what) {
  std::vector<double> v;
  for (std::string_view f : split_fields(text)) v.push_back(parse_double(f, what));
  if (v.size() != n) throw Error(fmt::format("{} '{}': expected {} numbers", what, text, n));
  return v;
}

void run(const Options& o) {
  if (o.rig.empty()) throw Error("--rig is needed: the camera's intrinsics come from it");
  rig::Rig rig = rig::read_rig_file(o.rig);
  const rig::Sensor* cam_sensor = rig::find_sensor(rig, o.camera);
  if (!cam_sensor || cam_sensor->type != rig::SensorType::camera)
    throw Error(fmt::format("--camera {}: no such camera in {}", o.camera, o.rig));
  if (!rig::find_sensor(rig, o.lidar))
    throw Error(fmt::format("--lidar {}: no such sensor in {}", o.lidar, o.rig));
  const rig::CameraModel cam = cam_sensor->camera;
  const camera::Target target = io::read_target_file(o.target);
  // The pairs: a session's camera and ouster_points folders paired by stamp (on the base clock,
  // within --max-dt), or the two globs paired by the frame number in the names.
  std::vector<std::string> image_files, scan_files;
  if (!o.session.empty()) {
    if (!o.images.empty() || !o.scans.empty())
      throw Error("give --session DIR, or --images GLOB and --scans GLOB, not both");
    // The session layout (doc/session.md): cam_l's images in camera_left, others' in
    // camera_right.
    const std::filesystem::path dir = std::filesystem::path(o.session) / "lidar_camera";
    const io::StampedFolder images = io::read_stamped_folder(
        dir / (o.camera == "cam_l" ? "camera_left" : "camera_right"), ".png");
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
        fmt::print("{}: no scan within {} s, skipped\n", images.files[k], o.max_dt_s);
        continue;
      }
      image_files.push_back(images.files[k]), scan_files.push_back(scans.files[*scan_of[k]]);
    }
    if (image_files.empty()) {
      throw Error(
          fmt::format("{}: no image has a scan within {} s (--max-dt)", dir.string(), o.max_dt_s));
    }
  } else {
    if (o.images.empty() || o.scans.empty())
      throw Error("give --session DIR, or --images GLOB and --scans GLOB");
    const std::vector<std::string> image_glob = io::glob_files(o.images),
                                   scan_glob = io::glob_files(o.scans);
    if (image_glob.empty()) throw Error(fmt::format("no images match {}", o.images));
    if (scan_glob.empty()) throw Error(fmt::format("no scans match {}", o.scans));
    // Paired by the frame number in the names; an image or a scan without its partner is an
    // error.
    const io::ImageSet set =
        io::pair_by_frame_number({{"images", image_glob}, {"scans", scan_glob}});
    for (size_t k = 0; k < set.files[0].size(); ++k) {
      const std::string &img = set.files[0][k], &scan = set.files[1][k];
      if (img.empty() || scan.empty()) {
        throw Error(fmt::format("{} has no {} with the same frame number", img.empty() ? scan : img,
                                img.empty() ? "image" : "scan"));
      }
      image_files.push_back(img), scan_files.push_back(scan);
    }
  }
  const camera::Outline outline = camera::outline(target);
  lidar_camera::BoardSearch search;
  search.board_width_m = outline.width();
  search.board_height_m = outline.height();
  if (!o.board_size.empty()) {
    const std::vector<double> v = numbers(o.board_size, 2, "--board-size");
    search.board_width_m = v[0], search.board_height_m = v[1];
  }
  if (!o.roi.empty()) {
    const std::vector<double> v = numbers(o.roi, 6, "--roi");
    search.roi = {{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
  }
  std::vector<lidar_camera::PairInput> pairs(image_files.size());
  std::vector<cv::Mat> shown(image_files.size());
  for (size_t k = 0; k < image_files.size(); ++k) {
    fmt::print(stderr, "\rpair {}/{}", k + 1, image_files.size());
    const cv::Mat img = cv::imread(image_files[k], cv::IMREAD_UNCHANGED);
    if (img.empty()) throw Error(fmt::format("{}: cannot read the image", image_files[k]));
    if (img.cols != cam.width || img.rows != cam.height) {
      throw Error(fmt::format("{}: {} x {} px, the rig's {} is {} x {}", image_files[k], img.cols,
                              img.rows, o.camera, cam.width, cam.height));
    }
    cv::Mat gray = img;
    if (img.channels() == 3) cv::cvtColor(img, gray, cv::COLOR_BGR2GRAY);
    if (img.channels() == 4) cv::cvtColor(img, gray, cv::COLOR_BGRA2GRAY);
    if (gray.depth() != CV_8U) gray.convertTo(gray, CV_8U, 1.0 / 256);
    shown[k] = gray;
    const camera::Detection det = camera::detect(gray, target);
    if (det.found && det.pixels.size() == camera::object_points(target).size())
      pairs[k].camera = lidar_camera::board_in_camera(cam, target, det.pixels, o.corner_sigma_px);
    pairs[k].scan = io::read_point_cloud(scan_files[k]);
  }
  fmt::print(stderr, "\n");
  std::optional<SE3> prior;
  if (o.camera != o.lidar) {
    const SE3 T = rig::T_a_b(rig, o.camera, o.lidar);
    if (!T.t.isZero()) prior = T;  // a rig with the camera placed already
  }
  const lidar_camera::Calibration c = lidar_camera::calibrate(pairs, search, prior);
  const lidar_camera::Solution& s = c.solution;
  for (size_t k = 0; k < c.pairs.size(); ++k)
    fmt::print("pair {:2d}: {}\n", k + 1, c.pairs[k].note);
  const SE3& T = s.T_camera_lidar;
  const Eigen::Vector3d rpy = roll_pitch_yaw(T.R) * 180.0 / M_PI;
  fmt::print(
      "T_{}_{}: t = [{:.4f} {:.4f} {:.4f}] ± [{:.4f} {:.4f} {:.4f}] m, roll pitch yaw {:.3f} "
      "{:.3f} {:.3f} ± {:.3f} {:.3f} {:.3f} deg\n",
      o.camera, o.lidar, T.t.x(), T.t.y(), T.t.z(), s.translation_sigma_m.x(),
      s.translation_sigma_m.y(), s.translation_sigma_m.z(), rpy.x(), rpy.y(), rpy.z(),
      s.rotation_sigma_deg.x(), s.rotation_sigma_deg.y(), s.rotation_sigma_deg.z());
  fmt::print(
      "observability: normals' singular values {:.3f} {:.3f} {:.3f}, condition {:.1f}; noise "
      "scale {:.2f}\n",
      s.observability.singular_values[0], s.observability.singular_values[1],
      s.observability.singular_values[2], s.observability.condition, s.noise_scale);

  std::vector<io::OutputFile> files;
  if (!o.report.empty()) {
    io::LidarCameraInputs in{image_files,          scan_files,           o.target, o.rig, o.camera,
                             search.board_width_m, search.board_height_m};
    files = io::lidar_camera_report_files(o.report, in, pairs, c, cam, shown);
  }
  if (!o.out.empty()) {
    // The camera placed from the LiDAR: T_b(camera) = T_b(lidar) T_camera_lidar^-1; every other
    // camera keeps its pose relative to this one (the stereo extrinsic).
    const SE3 T_b_cam_old = rig::sensor(rig, o.camera).T_base_sensor;
    const SE3 T_b_cam = rig::sensor(rig, o.lidar).T_base_sensor * T.inverse();
    for (rig::Sensor& other : rig.sensors) {
      if (other.type == rig::SensorType::camera && other.name != o.camera)
        other.T_base_sensor = T_b_cam * T_b_cam_old.inverse() * other.T_base_sensor;
    }
    rig::sensor(rig, o.camera).T_base_sensor = T_b_cam;
    files.push_back({o.out, rig::rig_to_yaml(rig)});
  }
  io::write_files_atomic(files);
  if (!o.out.empty()) fmt::print("{}: T_b written to {} (other cameras follow)\n", o.camera, o.out);
  if (!o.report.empty()) fmt::print("report: {}/lidar_camera.json and pair_NN.png\n", o.report);
}

}  // namespace

void add_lidar_camera(CLI::App& app) {
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "lidar-camera",
      "T_camera_lidar from image + scan pairs of the board (doc/lidar-camera.md): the board's\n"
      "plane by PnP in each image, the board found in each scan without clicks (planar pieces\n"
      "of the board's size), a plane-to-plane solve with covariance. Scans: .bin (KITTI float32\n"
      "x y z i) or .pcd (ascii/binary). Exit 0; 2 on bad input, too few boards or boards that\n"
      "do not determine the extrinsic: nothing written.");
  cmd->add_option("--target", o->target, "target YAML (the board's pattern)")->required();
  cmd->add_option("--camera", o->camera, "the rig's camera")->capture_default_str();
  cmd->add_option("--lidar", o->lidar, "the rig's LiDAR")->capture_default_str();
  cmd->add_option("--rig", o->rig, "rig with the camera's intrinsics; updated with --out")
      ->required();
  cmd->add_option("--session", o->session,
                  "session folder: lidar_camera/camera_right (camera_left for cam_l) and "
                  "lidar_camera/ouster_points, each data/ + timestamps.txt; pairs by stamp on the "
                  "base clock (the rig's time offsets applied)");
  cmd->add_option("--max-dt", o->max_dt_s,
                  "--session: an image takes the nearest scan within this many seconds")
      ->capture_default_str();
  cmd->add_option("--images", o->images,
                  "image glob; pairs are matched by the last number in the file names");
  cmd->add_option("--scans", o->scans, "scan glob");
  cmd->add_option("--out", o->out, "output calibration YAML");
  cmd->add_option("--report", o->report, "report folder: lidar_camera.json, pair_NN.png");
  cmd->add_option("--board-size", o->board_size,
                  "the physical board W,H in m when larger than the target's outline (a backing "
                  "board)");
  cmd->add_option("--roi", o->roi,
                  "search the board only inside this box of the LiDAR frame: "
                  "xmin,ymin,zmin,xmax,ymax,zmax (m)");
  cmd->add_option("--corner-sigma", o->corner_sigma_px,
                  "corner noise for the camera plane's covariance (px; the residuals' level "
                  "when larger)")
      ->capture_default_str();
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::cli
