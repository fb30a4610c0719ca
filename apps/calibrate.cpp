// rigcal calibrate SESSION --out DIR: the whole session, step by step, published once
// (doc/session.md).
#include "rigcal/session/calibrate.h"

#include <fmt/format.h>

#include <memory>

#include "cli.h"
#include "rigcal/lidar/odometry.h"
#include "step_output.h"

namespace rigcal::cli {
namespace calibrate_command {

struct Options {
  session::CalibrateOptions run;
  std::string rig, target, odometry, gnss, out, bayer;
  std::vector<std::string> fix, prior;  // hand-eye's
  bool no_estimate_offset = false, no_sweep_motion = false;
};

void run(Options o) {
  o.run.rig = o.rig, o.run.target = o.target, o.run.odometry = o.odometry, o.run.gnss = o.gnss;
  o.run.out = o.out;
  o.run.cameras.bayer = o.run.lidar_camera.bayer = io::bayer_from_string(o.bayer);
  o.run.hand_eye.estimate_offset = !o.no_estimate_offset;
  o.run.hand_eye.odometry_sweep_motion = !o.no_sweep_motion;
  o.run.hand_eye.refine.fixed = hand_eye::parse_translation_constraints(o.fix, false);
  for (const auto& p : hand_eye::parse_translation_constraints(o.prior, true))
    o.run.hand_eye.refine.fixed.push_back(p);
  const session::CalibrateResult r = session::calibrate(o.run, console_progress());
  const session::CalibrateText text = session::calibrate_text(r, o.out);
  for (const std::string& line : text.lines) fmt::print("{}\n", line);
  if (!text.error_line.empty()) fmt::print(stderr, "{}\n", text.error_line);
  if (r.exit_status != 0) throw Exit{r.exit_status};
}

}  // namespace calibrate_command

void add_calibrate(CLI::App& app) {
  using namespace calibrate_command;
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "Calibrate a whole session in one run (doc/session.md): cameras (stereo/), LiDAR-camera\n"
      "(lidar_camera/, the right camera), the IMU clock offsets (motion/), hand-eye GNSS/INS to\n"
      "LiDAR with the clock offset (motion/: rigcal's own odometry on its ouster_points/, or\n"
      "--odometry FILE). Writes OUT/calib.yaml once,\n"
      "atomically, with rigcal.steps (inputs and their sha256, tool version, sigmas, residuals),\n"
      "OUT/report.html (the page to read: verdict, numbers with sigmas, warnings, figures) and\n"
      "OUT/reports/<step>/. A rerun reuses each step whose inputs, rig entries and options\n"
      "are unchanged (OUT/cache/). Exit 0 every step that ran is ok (published when all ran);\n"
      "2 a step failed on bad input; 3 a step is undetermined by the data: the other steps'\n"
      "results are kept, nothing is published (an earlier OUT/calib.yaml is removed).");
  cmd->add_option(
         "session", o->run.session,
         "the session folder, a single recording, or a ROS1 bag, a folder of bags or an Ouster "
         "capture (CAPTURE.pcap + CAPTURE.json), converted on the fly into a temporary "
         "recording under $TMPDIR")
      ->required();
  cmd->add_option("--out", o->out, "output folder")->required();
  cmd->add_option("--rig", o->rig, "prior rig (default: session.yaml's rig, or SESSION/rig.yaml)");
  cmd->add_option("--target", o->target,
                  "target YAML (default: session.yaml's target, or SESSION/target.yaml)");
  cmd->add_option("--odometry", o->odometry,
                  "the motion recording's LiDAR odometry, T_odom_lidar (TUM, KITTI, EuRoC); "
                  "default: rigcal's own on the motion recording's ouster_points/");
  cmd->add_option("--odometry-preset", o->run.hand_eye.odometry_preset,
                  "rigcal's odometry preset: os0-128 | os1-64 (default: the rig LiDAR's model)")
      ->check(CLI::IsMember(lidar::preset_names()));
  cmd->add_flag("--no-sweep-motion", o->no_sweep_motion,
                "rigcal's odometry takes each sweep's motion from the step before instead of "
                "estimating it (doc/odometry.md)");
  cmd->add_option("--gnss", o->gnss,
                  "the GNSS/INS trajectory or fixes (default: motion/gnss/poses.tum or fixes.csv)");
  cmd->add_option("--attitude", o->run.hand_eye.attitude, "GNSS fixes only: enu | ned")
      ->check(CLI::IsMember({"enu", "ned"}));
  cmd->add_option("--from", o->run.from,
                  "rerun this step and the ones after it (the earlier ones from the cache)");
  cmd->add_option("--only", o->run.only,
                  "rerun only this step; the others from the cache where it holds them");
  cmd->add_option("--model", o->run.cameras.model,
                  "camera model: pinhole-radtan | pinhole-radtan5 | pinhole-equidistant (Kalibr's\n"
                  "pinhole-equi), or per camera NAME=MODEL,NAME=MODEL")
      ->capture_default_str();
  cmd->add_option("--bayer", o->bayer, "raw Bayer images: rggb | bggr | grbg | gbrg");
  cmd->add_flag("--board-warp", o->run.cameras.board_warp,
                "cameras: solve the board's warp too (mrcal's calobject_warp; doc/cameras.md)");
  cmd->add_flag("--saddle-fit", o->run.cameras.saddle_fit,
                "cameras: checkerboard corners also fitted as saddles (doc/cameras.md)");
  cmd->add_option("--lidar-camera", o->run.lidar_camera.camera,
                  "the camera of the LiDAR-camera step")
      ->capture_default_str();
  cmd->add_option("--fix", o->fix,
                  "hand-eye: hold a translation component (GNSS/INS frame), e.g. z=0.35 (a car's "
                  "vertical, which planar motion does not determine)");
  cmd->add_option("--prior", o->prior,
                  "hand-eye: a translation component's prior with its 1-sigma, e.g. z=0.35,0.02");
  cmd->add_flag("--no-estimate-offset", o->no_estimate_offset,
                "hand-eye: keep the rig's GNSS/INS clock offset (a disagreement the "
                "trajectories show is reported)");
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::cli
