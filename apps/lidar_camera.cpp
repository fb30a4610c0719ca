// rigcal lidar-camera: T_camera_lidar from image + scan pairs of the board (doc/lidar-camera.md).
#include <fmt/format.h>

#include <memory>

#include "cli.h"
#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/io/session.h"
#include "rigcal/lidar_camera/step.h"
#include "step_output.h"

namespace rigcal::cli {
namespace lidar_camera_command {

struct Options {
  std::string target, session, images, scans, rig, out, report, roi, board_size, bayer;
  lidar_camera::StepOptions step;
};

// "a,b,c,d,e,f" -> numbers, named in errors by `what`.
std::vector<double> numbers(const std::string& text, size_t n, const std::string& what) {
  std::vector<double> v;
  for (std::string_view f : split_fields(text)) v.push_back(parse_double(f, what));
  if (v.size() != n) throw Error(fmt::format("{} '{}': expected {} numbers", what, text, n));
  return v;
}

void run(Options o) {
  if (o.rig.empty()) throw Error("--rig is needed: the camera's intrinsics come from it");
  const rig::Rig rig = rig::read_rig_file(o.rig);
  o.step.bayer = io::bayer_from_string(o.bayer);
  if (!o.board_size.empty()) {
    const std::vector<double> v = numbers(o.board_size, 2, "--board-size");
    o.step.board_width_m = v[0], o.step.board_height_m = v[1];
  }
  if (!o.roi.empty()) {
    const std::vector<double> v = numbers(o.roi, 6, "--roi");
    o.step.roi = {{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
  }
  for (const std::string& name : {o.step.camera, o.step.lidar}) {
    if (!rig::find_sensor(rig, name))
      throw Error(fmt::format("--{} {}: no such sensor in {}",
                              name == o.step.camera ? "camera" : "lidar", name, o.rig));
  }
  // The pairs: a recording's camera and ouster_points folders paired by stamp on the base clock,
  // or the two globs paired by the frame number in the names.
  lidar_camera::StepInputs in;
  if (!o.session.empty()) {
    if (!o.images.empty() || !o.scans.empty())
      throw Error("give --session DIR, or --images GLOB and --scans GLOB, not both");
    in = lidar_camera::pairs_from_recording(
        io::recording_for(io::read_session(o.session, console_progress()), "lidar_camera"), rig,
        o.step);
  } else {
    if (o.images.empty() || o.scans.empty())
      throw Error("give --session DIR, or --images GLOB and --scans GLOB");
    in = lidar_camera::pairs_from_globs(o.images, o.scans, rig);
  }
  for (const std::string& n : in.notes) fmt::print("{}\n", n);
  in.notes.clear();
  in.target = o.target;
  in.rig_source = o.rig;
  // --rig and --out may name one file: the rig updated in place (atomically).
  std::vector<std::pair<std::string, std::filesystem::path>> inputs{{"--target", o.target}};
  for (size_t k = 0; k < in.images.size(); ++k)
    inputs.emplace_back("an image", in.images[k]), inputs.emplace_back("a scan", in.scans[k]);
  io::refuse_outputs_over_inputs({{o.out, ""}}, inputs);  // before the work, not after
  const report::StepResult r = lidar_camera::calibrate_lidar_camera(in, o.step, console_progress());
  finish_step(r, o.out, o.report);
  if (!o.out.empty())
    fmt::print("{}: T_b written to {} (other cameras follow)\n", o.step.camera, o.out);
  if (!o.report.empty()) fmt::print("the page to read: {}/report.html\n", o.report);
}

}  // namespace lidar_camera_command

void add_lidar_camera(CLI::App& app) {
  using namespace lidar_camera_command;
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "lidar-camera",
      "T_camera_lidar from image + scan pairs of the board (doc/lidar-camera.md): the board's\n"
      "plane by PnP in each image, the board found in each scan without clicks (planar pieces\n"
      "of the board's size), a plane-to-plane solve with covariance. Scans: .bin (KITTI float32\n"
      "x y z i, or vbr-devkit's full fields) or .pcd (ascii/binary). Exit 0; 2 on bad input,\n"
      "too few boards or boards that do not determine the extrinsic: nothing written.");
  cmd->add_option("--target", o->target, "target YAML (the board's pattern)")->required();
  cmd->add_option("--camera", o->step.camera, "the rig's camera")->capture_default_str();
  cmd->add_option("--lidar", o->step.lidar, "the rig's LiDAR")->capture_default_str();
  cmd->add_option("--rig", o->rig, "rig with the camera's intrinsics; updated with --out")
      ->required();
  cmd->add_option(
      "--session", o->session,
      "a session (its lidar_camera/ recording), a recording, a bag or folder of bags: "
      "camera_right/ (camera_left/ for cam_l) and ouster_points/, each data/ + timestamps.txt; "
      "pairs by stamp on the base clock (the rig's time offsets applied)");
  cmd->add_option("--max-dt", o->step.max_dt_s,
                  "--session: an image takes the nearest scan within this many seconds")
      ->check(finite_number(true) & CLI::Range(1e-6, 3600.0))
      ->capture_default_str();
  cmd->add_option("--images", o->images,
                  "image glob; pairs are matched by the last number in the file names");
  cmd->add_option("--scans", o->scans, "scan glob");
  cmd->add_option("--out", o->out, "output calibration YAML");
  cmd->add_option("--bayer", o->bayer,
                  "raw Bayer images: rggb | bggr | grbg | gbrg (demosaiced to gray)");
  cmd->add_option("--report", o->report,
                  "report folder: lidar_camera.json, pair_NN.png, report.html (the page to read)");
  cmd->add_option("--board-size", o->board_size,
                  "the physical board W,H in m when larger than the target's outline (a backing "
                  "board)");
  cmd->add_option("--roi", o->roi,
                  "search the board only inside this box of the LiDAR frame: "
                  "xmin,ymin,zmin,xmax,ymax,zmax (m)");
  cmd->add_option("--corner-sigma", o->step.corner_sigma_px,
                  "corner noise for the camera plane's covariance (px; the residuals' level "
                  "when larger)")
      ->check(finite_number(true))
      ->capture_default_str();
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::cli
