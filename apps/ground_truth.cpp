// rigcal ground-truth: the LiDAR's trajectory from its odometry and the GNSS fixes through a pose
// graph, in the fixes' local ENU frame, with each pose's sigmas (doc/ground-truth.md).
#include <fmt/format.h>

#include <memory>

#include "cli.h"
#include "rigcal/gt/step.h"
#include "step_output.h"

namespace rigcal::cli {
namespace ground_truth_command {
namespace fs = std::filesystem;

struct Options {
  gt::InputFiles in;
  gt::StepOptions step;
  gt::CommandWords words;
  std::string out, sigmas, report, map;
};

void run(Options o) {
  o.words.map = !o.map.empty();
  gt::apply_command_words(o.words, o.step);
  const gt::CommandOutcome r =
      gt::ground_truth_command(o.in, o.step, o.out, o.sigmas, o.report, o.map, console_progress());
  fmt::print("{}", r.text);
  for (const std::string& line : r.undetermined) fmt::print(stderr, "{}\n", line);
  if (r.exit_status != 0) throw Exit{r.exit_status};
}

}  // namespace ground_truth_command

void add_ground_truth(CLI::App& app) {
  using namespace ground_truth_command;
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "ground-truth",
      "The LiDAR's ground-truth trajectory (doc/ground-truth.md): a pose graph over the scan\n"
      "poses (the odometry's steps, the GNSS fixes as priors through the lever arm), then the\n"
      "LiDAR bundle adjustment over overlapping windows of the scans, solved again. Writes OUT\n"
      "(VBR's <seq>_gt.txt: T_enu_lidar) and each pose's sigmas; the map and the survey\n"
      "markers' distances with --map / --markers. Exit 3 when the fixes leave something\n"
      "undetermined (said on stderr). A job array: --windows FROM:TO a task, --window-motions\n"
      "the join (doc/performance.md).");
  cmd->add_option("recording", o->in.recording,
                  "the recording: its gnss/ (poses.tum, fixes.csv or navsat.csv) and its scans "
                  "(ouster_points/, a capture, a session): the odometry's without --odometry, "
                  "the bundle adjustment's")
      ->required();
  cmd->add_option("--rig", o->in.rig, "the calibration: the GNSS sensor's T_b and time_offset")
      ->required();
  cmd->add_option("--out", o->out, "output trajectory (VBR ground-truth format)")->required();
  cmd->add_option("--sigmas", o->sigmas,
                  "output per-pose standard deviations (default: OUT without extension + "
                  "_sigmas.txt)");
  cmd->add_option("--odometry", o->in.odometry,
                  "an odometry trajectory (T_odom_lidar) instead of running rigcal's on the scans");
  cmd->add_option("--covariances", o->in.covariances,
                  "its step covariances (default: ODOMETRY without extension + _covariances.txt)");
  cmd->add_option("--gnss", o->in.gnss, "GNSS/INS poses (TUM, T_enu_gnss) or fixes (CSV)");
  cmd->add_option("--attitude", o->in.attitude,
                  "GNSS/INS poses (T_enu_ins; may be --gnss) whose rotations are priors on the "
                  "LiDAR's (a standing rig's heading, a straight path's roll)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--attitude-sigma-deg", o->words.attitude_sigma_deg,
                  "TILT,HEADING: the attitudes' sigmas, deg (roll and pitch; heading; default "
                  "0.1,0.5, conservative for an RTK INS: give the receiver's own)")
      ->delimiter(',')
      ->check(CLI::Range(1e-6, 180.0));
  cmd->add_option("--attitude-correlation", o->step.pose_graph.attitude_correlation_s,
                  "the attitudes' error correlation time, s: each prior weighs as 1 / (2 S x scan "
                  "rate) of an independent one (0: independent)")
      ->check(seconds_within(0, 3600))
      ->capture_default_str();
  cmd->add_option("--gnss-sensor", o->step.gnss_sensor, "the rig's GNSS sensor")
      ->capture_default_str();
  cmd->add_option("--enu-origin", o->words.enu_origin,
                  "LAT,LON,HEIGHT (degrees, degrees, ellipsoidal m): the fixes' ENU frame at this "
                  "origin instead of at the first fix (sessions that must share one frame; fixes "
                  "only, not GNSS/INS poses)");
  cmd->add_option("--odometry-preset", o->step.odometry_preset,
                  "rigcal's odometry preset (default: the rig LiDAR's model)")
      ->check(CLI::IsMember(lidar::preset_names()));
  cmd->add_option("--max-fix-gap", o->step.pose_graph.max_fix_gap_s,
                  "a scan gets a prior from the fixes around it when they are at most this far "
                  "apart, s")
      ->check(seconds_within(1e-6, 60))
      ->capture_default_str();
  cmd->add_option("--fix-correlation", o->words.fix_correlation,
                  "the fixes' error correlation time S, s (0: independent; auto: estimated from "
                  "the residuals of the solves, each solved again with it until it settles)")
      ->check(CLI::IsMember({"auto"}) | seconds_within(0, 600))
      ->capture_default_str();
  cmd->add_option("--fix-model", o->words.fix_model,
                  "how correlated fixes weigh: states (their error a Gauss-Markov state of "
                  "correlation time S at every scan, in units of each fix's sigmas, part of its "
                  "variance white: with --fix-correlation auto, S and that part the most likely, "
                  "else 10 %) or scaled (each prior weighs as 1 / (2 S x scan rate) of an "
                  "independent one)")
      ->check(CLI::IsMember({"states", "scaled"}))
      ->capture_default_str();
  cmd->add_option("--scans", o->in.scans,
                  "the scans (a folder, a capture, a recording; default: the recording's)");
  cmd->add_flag("--no-bundle-adjustment", o->words.no_bundle_adjustment,
                "stop at the pose graph (stage 1)");
  cmd->add_flag("--no-fusion", o->words.no_fusion,
                "take the bundle adjustment's motions alone into the second pose graph (default: "
                "each fused with the odometry's by covariance intersection where the two agree "
                "within their covariances)");
  cmd->add_flag("--photometric", o->step.ba.window.photometric.enabled,
                "add the photometric term to each window (range and intensity between the "
                "scans' spherical images, after the geometric rounds; doc/ground-truth.md "
                "measures what it adds)");
  cmd->add_option("--keyframes", o->words.keyframes,
                  "M,DEG: experimental, not for use: a scan is a keyframe of the bundle "
                  "adjustment once the rig moved M metres or turned DEG degrees since the last "
                  "(default 0,0: every scan); 0.3,5 halves a walk's time, and the ground truth is "
                  "then only as good as the odometry between keyframes (up to 0.17 m off on the "
                  "simulator's walks; doc/ground-truth.md, \"Keyframes\")")
      ->delimiter(',')
      ->check(CLI::Range(0.0, 1000.0));
  cmd->add_option("--window-scans", o->step.ba.window_scans, "keyframes a bundle-adjustment window")
      ->check(CLI::Range(size_t(2), size_t(1000)))
      ->capture_default_str();
  cmd->add_option("--window-overlap", o->step.ba.overlap_scans,
                  "keyframes each window shares with the previous one")
      ->check(CLI::Range(size_t(0), size_t(999)))
      ->capture_default_str();
  cmd->add_option("--windows", o->words.windows,
                  "FROM:TO: adjust only the windows FROM to TO - 1 (numbered from 0) and write "
                  "the motions they own to OUT (TUM) and OUT's _covariances.txt, nothing else: "
                  "one task of a job array (the same odometry, GNSS and options in every task)")
      ->delimiter(':');
  cmd->add_option("--window-motions", o->in.window_motions,
                  "the motions the tasks of --windows wrote (all of them, any order): joined in "
                  "place of the bundle adjustment, then the pose graph as usual")
      ->check(CLI::ExistingFile);
  cmd->add_option("--map", o->map,
                  "output map: the scans placed by the ground truth, one point a voxel (binary "
                  "PLY: x y z intensity, the ENU frame)");
  cmd->add_option("--map-voxel", o->step.map_config.voxel_size_m, "the map's voxel, m")
      ->check(CLI::Range(0.01, 10.0))
      ->capture_default_str();
  cmd->add_option("--markers", o->in.markers,
                  "survey markers to check the map against (CSV: id,x,y,z in any frame, or "
                  "id_a,id_b,distance in m): found as clusters of bright points, their distances "
                  "compared with the survey's");
  cmd->add_option("--marker-intensity", o->step.map_config.bright_intensity,
                  "the intensity a marker's points reach (default: 10x the first scan's median)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--report", o->report,
                  "report folder: ground_truth.json (one row a prior, one a window), "
                  "report.html (the page to read)");
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::cli
