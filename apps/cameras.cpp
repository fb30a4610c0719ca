// rigcal cameras: intrinsics of one or two cameras and their stereo extrinsic (doc/cameras.md).
#include <fmt/format.h>

#include <filesystem>
#include <memory>

#include "cli.h"
#include "rigcal/camera/step.h"
#include "rigcal/core/error.h"
#include "rigcal/io/session.h"
#include "step_output.h"

namespace rigcal::cli {
namespace cameras_command {

struct Options {
  std::string target, session, model = "pinhole-radtan", rig, out, report, bayer;
  std::vector<std::string> cameras;  // NAME=GLOB
  double k_sigma = 4.0;
  bool board_warp = false;
  bool saddle_fit = false;
};

io::ImageSet images(const Options& o) {
  if (!o.session.empty()) {
    return io::read_session_images(
        io::recording_for(io::read_session(o.session, console_progress()), "cameras"));
  }
  if (o.cameras.empty()) throw Error("give --camera NAME=GLOB (once per camera) or --session DIR");
  std::vector<std::pair<std::string, std::vector<std::string>>> cams;
  for (const std::string& spec : o.cameras) {
    const size_t eq = spec.find('=');
    if (eq == std::string::npos || eq == 0)
      throw Error(fmt::format("--camera '{}': expected NAME=GLOB", spec));
    std::vector<std::string> files = io::glob_files(spec.substr(eq + 1));
    if (files.empty())
      throw Error(
          fmt::format("camera {}: no file matches '{}'", spec.substr(0, eq), spec.substr(eq + 1)));
    cams.emplace_back(spec.substr(0, eq), files);
  }
  return io::pair_by_frame_number(cams);
}

void run(const Options& o) {
  camera::StepOptions so;
  so.model = o.model;
  so.outlier_sigma = o.k_sigma;
  so.board_warp = o.board_warp;
  so.saddle_fit = o.saddle_fit;
  so.bayer = io::bayer_from_string(o.bayer);
  camera::StepInputs in;
  in.target = o.target;
  in.images = images(o);
  // --rig and --out may name one file: the rig updated in place (atomically).
  std::vector<std::pair<std::string, std::filesystem::path>> inputs{{"--target", o.target}};
  for (const auto& files : in.images.files)
    for (const std::string& f : files) inputs.emplace_back("an image", f);
  io::refuse_outputs_over_inputs({{o.out, ""}}, inputs);  // before the work, not after
  if (!o.rig.empty()) in.rig = rig::read_rig_file(o.rig);
  in.corners_cache = std::filesystem::path(o.report) / "corners.vnl";
  const report::StepResult r = camera::calibrate_cameras(in, so, console_progress());
  finish_step(r, o.out, o.report);
  fmt::print("wrote {}; the page to read: {}/report.html\n", o.out, o.report);
}

}  // namespace cameras_command

void add_cameras(CLI::App& app) {
  using namespace cameras_command;
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "cameras",
      "Calibrate one or two cameras (intrinsics, and the stereo extrinsic) from images of a "
      "target\n"
      "(doc/cameras.md). Images pair by the frame number in their file names, or by timestamp\n"
      "with --session. Writes the rig (OUT.yaml) and a report folder: cameras.json (every figure\n"
      "with its definition), corners.vnl (detections, mrcal's format, reused on the next run),\n"
      "PNGs per camera: corners, residual vectors x100, coverage, projection uncertainty,\n"
      "NAME.cameramodel per camera with mrcal's optimization_inputs (mrcal's tools run on it),\n"
      "the stereo pair rectified; and report.html, the page to read (doc/report.md).");
  cmd->add_option("--target", o->target, "target YAML (targets/*.yaml; Kalibr's format)")
      ->required();
  cmd->add_option("--camera", o->cameras, "NAME=GLOB, e.g. cam_l='left/*.png' (once per camera)");
  cmd->add_option("--session", o->session,
                  "a session (its stereo/ recording) or a recording with camera_left/ and "
                  "camera_right/, or a bag, folder of bags or capture (doc/session.md)");
  cmd->add_option(
         "--model", o->model,
         "pinhole-radtan | pinhole-radtan5 | pinhole-equidistant (Kalibr's pinhole-equi);\n"
         "or per camera: cam_l=pinhole-radtan,cam_r=pinhole-equi (fitted together)")
      ->capture_default_str();
  cmd->add_option("--rig", o->rig, "rig to update (default: a new rig of these cameras)");
  cmd->add_option("--out", o->out, "output calibration YAML")->required();
  cmd->add_option("--report", o->report, "report folder")->required();
  cmd->add_option("--outlier-sigma", o->k_sigma,
                  "drop corners with a residual beyond this many sigma")
      ->check(finite_number(true) & CLI::Range(0.5, 100.0))
      ->capture_default_str();
  cmd->add_option("--bayer", o->bayer,
                  "raw Bayer images: rggb | bggr | grbg | gbrg (demosaiced to gray)");
  cmd->add_flag("--board-warp", o->board_warp,
                "solve the board's warp too (a printed board on a backing is not flat): two\n"
                "parabolas along the board's axes, as mrcal's calobject_warp; reported with "
                "its 1-sigma");
  cmd->add_flag("--saddle-fit", o->saddle_fit,
                "checkerboards: each corner also fitted as a blurred saddle to its grey values\n"
                "(no pixel locking; half the corner noise on simulated images, a real gain not\n"
                "yet shown: doc/cameras.md)");
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::cli
