// rigcal hand-eye: the GNSS/INS-to-LiDAR extrinsic from the two trajectories (doc/hand-eye.md).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <memory>

#include "cli.h"
#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/hand_eye/step.h"
#include "rigcal/io/session.h"
#include "rigcal/lidar/step.h"
#include "step_output.h"

namespace rigcal::cli {
namespace hand_eye_command {

struct Options {
  std::string lidar, scans, odometry_preset, gnss, session, sensor = "gnss", lidar_sensor = "lidar",
                                                            rig, out, report;
  std::string duplicates = "error", attitude;
  std::vector<std::string> fix;    // AXIS=VALUE, GNSS/INS frame
  std::vector<std::string> prior;  // AXIS=VALUE,SIGMA
  std::vector<double> spacings_s = hand_eye::PairOptions{}.spacings_s;
  double stride_s = 0.1, min_rotation_deg = 1.0, rotation_sigma_deg = 0.05,
         translation_sigma_m = 0.02, max_sigma_m = 0.05, gnss_smoothing_s = 0.05;
  bool estimate_offset = false, no_sweep_motion = false;
};

void run(const Options& o) {
  if (!o.out.empty() && o.rig.empty())
    throw Error("--out writes the sensor's T_b into --rig: give it");
  hand_eye::StepOptions so;
  so.sensor = o.sensor, so.lidar_sensor = o.lidar_sensor;
  so.duplicates = io::duplicates_from_string(o.duplicates);
  so.attitude = o.attitude;
  so.pairs.spacings_s = o.spacings_s;
  so.pairs.stride_s = o.stride_s;
  so.pairs.min_rotation_deg = o.min_rotation_deg;
  so.pairs.gnss_half_window_s = o.gnss_smoothing_s;
  so.refine.rotation_sigma_deg = o.rotation_sigma_deg;
  so.refine.translation_sigma_m = o.translation_sigma_m;
  so.refine.fixed = hand_eye::parse_translation_constraints(o.fix, false);
  for (const hand_eye::RefineOptions::Fixed& p :
       hand_eye::parse_translation_constraints(o.prior, true))
    so.refine.fixed.push_back(p);
  so.max_sigma_m = o.max_sigma_m;
  so.estimate_offset = o.estimate_offset;
  so.odometry_preset = o.odometry_preset;
  so.odometry_sweep_motion = !o.no_sweep_motion;
  const hand_eye::StepInputs in =
      hand_eye::step_inputs(o.lidar, o.scans, o.gnss, o.session, o.rig, o.out, console_progress());
  const report::StepResult r = hand_eye::estimate_extrinsic(in, so, console_progress());
  finish_step(r, o.out, o.report);
  if (!o.out.empty()) fmt::print("{}: T_b written to {}\n", fmt::join(r.wrote, ", "), o.out);
  if (!o.report.empty()) fmt::print("the page to read: {}/report.html\n", o.report);
}

}  // namespace hand_eye_command

void add_hand_eye(CLI::App& app) {
  using namespace hand_eye_command;
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "hand-eye",
      "The GNSS/INS-to-LiDAR extrinsic from the LiDAR odometry and the GNSS/INS trajectory\n"
      "(doc/hand-eye.md): motion pairs, closed form, robust refinement, covariance, and the\n"
      "directions the motion does not determine (a car on a plane leaves the vertical offset\n"
      "free: give --fix z=METRES or --prior z=METRES,SIGMA, or the rig's value is kept and said\n"
      "so). Inputs: TUM, KITTI with times, EuRoC. Exit 0; 2 on bad input, 3 when a\n"
      "direction is undetermined and nothing fixes it: nothing written in either case.");
  cmd->add_option("--lidar", o->lidar, "LiDAR odometry trajectory (T_odom_lidar)");
  cmd->add_option("--scans", o->scans,
                  "or the LiDAR's scans (as `rigcal odometry` takes them): rigcal's odometry "
                  "runs first; its trajectory joins the report");
  cmd->add_option("--odometry-preset", o->odometry_preset,
                  "with --scans: os0-128 | os1-64 (default: the rig LiDAR's model)")
      ->check(CLI::IsMember(lidar::preset_names()));
  cmd->add_flag("--no-sweep-motion", o->no_sweep_motion,
                "with --scans: each sweep's motion from the step before, not estimated");
  cmd->add_option("--gnss", o->gnss,
                  "GNSS/INS trajectory (T_enu_gnss; TUM, KITTI, EuRoC, OpenCalib), or a CSV of "
                  "fixes with a header (time, latitude, longitude, height, roll, pitch, yaw), on "
                  "its own clock");
  cmd->add_option(
      "--session", o->session,
      "a session, recording, bag or folder of bags (doc/session.md): --lidar and --gnss from its "
      "session.yaml (odometry, gnss) or <motion>/gnss/, unless given");
  cmd->add_option("--attitude", o->attitude,
                  "GNSS fixes CSV only: enu (R = Rz(yaw) Ry(pitch) Rx(roll), yaw from east, "
                  "counter-clockwise) or ned (heading from north, clockwise; body x forward, z "
                  "down)")
      ->check(CLI::IsMember({"enu", "ned"}));
  cmd->add_option("--duplicate-stamps", o->duplicates,
                  "poses with equal stamps (a 100 Hz Vicon log stamped to 10 ms): error | drop "
                  "(keep the first) | keep")
      ->capture_default_str();
  cmd->add_option("--sensor", o->sensor, "the rig's GNSS/INS sensor")->capture_default_str();
  cmd->add_option("--lidar-sensor", o->lidar_sensor, "the rig's LiDAR")->capture_default_str();
  cmd->add_option("--rig", o->rig, "rig: clock offsets, prior extrinsic; updated with --out");
  cmd->add_option("--out", o->out, "output calibration YAML (the sensor's T_b)");
  cmd->add_option("--report", o->report,
                  "report folder: hand_eye.json, residuals.png, "
                  "trajectories.png, report.html (the page to read)");
  cmd->add_option("--fix", o->fix, "hold a translation component (GNSS/INS frame): z=0.35");
  cmd->add_option("--prior", o->prior,
                  "a translation component's prior with its 1-sigma (GNSS/INS frame, m): "
                  "z=0.35,0.02; weighed with the motion, and carried into the covariance");
  cmd->add_flag("--estimate-offset", o->estimate_offset,
                "estimate the clock offset from the trajectories' angular velocities (around "
                "the rig's value, +-1 s) and write it as the sensor's time_offset");
  cmd->add_option("--spacing", o->spacings_s,
                  "seconds between a pair's two poses; several lengths comma-separated, each "
                  "weighed with its own noise level (default 0.3,1: short pairs catch a hand-held "
                  "rig's sway, 1 s pairs its turns)")
      ->delimiter(',')
      ->check(seconds_within(0.001, 1e6))
      ->capture_default_str();
  cmd->add_option("--stride", o->stride_s,
                  "seconds between the starts of consecutive pairs (0: end to end); overlapping "
                  "pairs are not counted as independent in the covariance")
      ->check(seconds_within(0, 1e6))
      ->capture_default_str();
  cmd->add_option(
         "--gnss-smoothing", o->gnss_smoothing_s,
         "each GNSS/INS pose from a local quadratic fit over the fixes within +- this many "
         "seconds (at least 5 of them; 0: the fixes as they are)")
      ->check(seconds_within(0, 1e6))
      ->capture_default_str();
  cmd->add_option("--min-rotation", o->min_rotation_deg, "pairs rotating less are dropped (deg)")
      ->check(finite_number(false))
      ->capture_default_str();
  cmd->add_option("--rotation-sigma", o->rotation_sigma_deg, "per-pair rotation noise (deg)")
      ->check(finite_number(true))
      ->capture_default_str();
  cmd->add_option("--translation-sigma", o->translation_sigma_m, "per-pair translation noise (m)")
      ->check(finite_number(true))
      ->capture_default_str();
  cmd->add_option("--max-sigma", o->max_sigma_m,
                  "a translation direction with a larger 1-sigma is not estimated (m)")
      ->check(finite_number(true))
      ->capture_default_str();
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::cli
