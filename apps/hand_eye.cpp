// rigcal hand-eye: the GNSS/INS-to-LiDAR extrinsic from the two trajectories (doc/hand-eye.md).
#include "rigcal/hand_eye/hand_eye.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <memory>
#include <optional>

#include "cli.h"
#include "rigcal/core/error.h"
#include "rigcal/core/se3.h"
#include "rigcal/core/text.h"
#include "rigcal/io/files.h"
#include "rigcal/io/gnss_fixes.h"
#include "rigcal/io/hand_eye_report.h"
#include "rigcal/io/trajectory_io.h"
#include "rigcal/rig/rig_yaml.h"

namespace rigcal::cli {
namespace {

struct Options {
  std::string lidar, gnss, sensor = "gnss", lidar_sensor = "lidar", rig, out, report;
  std::string duplicates = "error", attitude;
  std::vector<std::string> fix;    // AXIS=VALUE, GNSS/INS frame
  std::vector<std::string> prior;  // AXIS=VALUE,SIGMA
  std::vector<double> spacings_s = hand_eye::PairOptions{}.spacings_s;
  double stride_s = 0.1, min_rotation_deg = 1.0, rotation_sigma_deg = 0.05,
         translation_sigma_m = 0.02, max_sigma_m = 0.05, gnss_smoothing_s = 0.05;
  bool estimate_offset = false;
};

// --fix AXIS=METRES, or (with_sigma) --prior AXIS=METRES,SIGMA.
std::vector<hand_eye::RefineOptions::Fixed> parse_fixes(const std::vector<std::string>& specs,
                                                        bool with_sigma) {
  std::vector<hand_eye::RefineOptions::Fixed> out;
  const char* option = with_sigma ? "--prior" : "--fix";
  for (const std::string& s : specs) {
    const size_t eq = s.find('=');
    const std::string axis = s.substr(0, eq);
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    if (axis == "x") d.x() = 1;
    if (axis == "y") d.y() = 1;
    if (axis == "z") d.z() = 1;
    std::vector<double> v;
    try {
      if (eq == std::string::npos) throw Error("");
      for (std::string_view f : split_fields(std::string_view(s).substr(eq + 1)))
        v.push_back(parse_double(f, option));
    } catch (const Error&) {
      d.setZero();
    }
    if (d.isZero() || v.size() != (with_sigma ? 2u : 1u) || (with_sigma && !(v[1] > 0))) {
      throw Error(with_sigma
                      ? fmt::format("--prior '{}': expected x=METRES,SIGMA (SIGMA > 0), "
                                    "y=... or z=...",
                                    s)
                      : fmt::format("--fix '{}': expected x=METRES, y=METRES or z=METRES", s));
    }
    out.push_back({d, v[0], with_sigma ? v[1] : 0.0});
  }
  return out;
}

void run(const Options& o) {
  if (!o.out.empty() && o.rig.empty())
    throw Error("--out writes the sensor's T_b into --rig: give it");
  rig::Rig rig;
  double offset_s = 0.0;
  SE3 T_base_lidar;
  std::optional<SE3> prior_T_gnss_lidar;
  if (!o.rig.empty()) {
    rig = rig::read_rig_file(o.rig);
    const rig::Sensor* g = rig::find_sensor(rig, o.sensor);
    const rig::Sensor* l = rig::find_sensor(rig, o.lidar_sensor);
    if (!g) throw Error(fmt::format("--sensor {}: no such sensor in {}", o.sensor, o.rig));
    if (!l)
      throw Error(fmt::format("--lidar-sensor {}: no such sensor in {}", o.lidar_sensor, o.rig));
    offset_s = g->time_offset - l->time_offset;
    T_base_lidar = l->T_base_sensor;
    prior_T_gnss_lidar = g->T_base_sensor.inverse() * T_base_lidar;
  }
  io::TrajectoryReadOptions read;
  read.duplicates = io::duplicates_from_string(o.duplicates);
  const Trajectory lidar = io::read_trajectory(o.lidar, read).trajectory;
  std::vector<std::string> notes;
  Trajectory gnss;
  if (io::is_gnss_fixes_file(o.gnss)) {
    // Fixes (latitude, longitude, height, attitude) to a local ENU frame at the first fix.
    if (o.attitude.empty()) {
      throw Error(fmt::format(
          "{} holds GNSS fixes: give --attitude enu (yaw counter-clockwise from east) or ned "
          "(heading clockwise from north, body x forward, z down); see doc/hand-eye.md",
          o.gnss));
    }
    const io::GnssFixes fixes = io::read_gnss_fixes(o.gnss, io::attitude_from_string(o.attitude));
    gnss = fixes.T_enu_gnss;
    std::string stds;
    if (fixes.median_horizontal_std_m)
      stds += fmt::format("; median std horizontal {:.3f} m", *fixes.median_horizontal_std_m);
    if (fixes.median_vertical_std_m)
      stds += fmt::format(", vertical {:.3f} m", *fixes.median_vertical_std_m);
    notes.push_back(fmt::format(
        "GNSS fixes converted to ENU (GeographicLib, WGS84) at the first fix: latitude {:.9f}, "
        "longitude {:.9f}, height {:.3f} m; attitude convention {}{}",
        fixes.origin.latitude_deg, fixes.origin.longitude_deg, fixes.origin.height_m, o.attitude,
        stds));
  } else {
    gnss = io::read_trajectory(o.gnss, read).trajectory;
  }
  if (lidar.size() < 2 || gnss.size() < 2) throw Error("each trajectory needs at least 2 poses");
  std::optional<time_sync::TimeSyncResult> sync;
  if (o.estimate_offset) {
    // The clock offset from the two trajectories' angular velocities (doc/time-offset.md), around
    // the rig's value: t_lidar = t_gnss + offset.
    sync = hand_eye::estimate_clock_offset(lidar, gnss, offset_s);
    if (sync->verdict != "ok") {
      fmt::print(stderr, "rigcal: the clock offset cannot be estimated: {}: {}; nothing written\n",
                 sync->verdict, sync->reason);
      throw Exit{3};
    }
    offset_s = sync->offset_s;
    fmt::print("clock offset: t_lidar = t_gnss + {:.6f} s (1-sigma {:.3f} ms, NCC {:.3f})\n",
               offset_s, 1e3 * sync->sigma_s, sync->peak_ncc);
  }
  const Time l0 = lidar.stamps.front(), l1 = lidar.stamps.back();
  const Time g0 = gnss.stamps.front() + Time::from_seconds(offset_s),
             g1 = gnss.stamps.back() + Time::from_seconds(offset_s);
  if (g1 <= l0 || l1 <= g0) {
    throw Error(fmt::format(
        "the trajectories do not overlap in time: LiDAR [{}, {}] s, GNSS/INS [{}, {}] s on the "
        "LiDAR clock (GNSS/INS time_offset {} s): check the clocks and --rig",
        to_seconds_text(l0), to_seconds_text(l1), to_seconds_text(g0), to_seconds_text(g1),
        offset_s));
  }
  hand_eye::PairOptions po;
  po.spacings_s = o.spacings_s;
  po.stride_s = o.stride_s;
  po.min_rotation_deg = o.min_rotation_deg;
  po.time_offset_s = offset_s;
  po.gnss_half_window_s = o.gnss_smoothing_s;
  const std::vector<double> spacings = hand_eye::pair_lengths(po);
  const std::vector<hand_eye::MotionPair> pairs = hand_eye::motion_pairs(lidar, gnss, po);
  if (pairs.size() < 3) {
    throw Error(fmt::format(
        "{} motion pairs of {} s rotating at least {} deg: too few or too small motions (at least "
        "3 are needed; rotate the rig about changing axes, or lower --min-rotation)",
        pairs.size(), fmt::join(spacings, " and "), o.min_rotation_deg));
  }
  const hand_eye::ClosedForm cf = hand_eye::closed_form(pairs, o.max_sigma_m);
  const hand_eye::Observability& ob = cf.observability;

  // Directions the data do not determine: a --fix along them, or the prior rig's value, or no
  // answer for them.
  hand_eye::RefineOptions ro;
  ro.rotation_sigma_deg = o.rotation_sigma_deg;
  ro.translation_sigma_m = o.translation_sigma_m;
  ro.fixed = parse_fixes(o.fix, false);
  for (const hand_eye::RefineOptions::Fixed& p : parse_fixes(o.prior, true)) ro.fixed.push_back(p);
  ro.estimate_time_offset = sync.has_value();
  if (sync) {
    notes.push_back(fmt::format(
        "clock offset estimated from the trajectories' angular velocities: t_lidar = t_gnss + "
        "{:.6f} s, 1-sigma {:.6f} s, peak NCC {:.3f}",
        offset_s, sync->sigma_s, sync->peak_ncc));
  }
  if (ob.near_planar) {
    const Eigen::Vector3d& n = ob.dominant_axis;
    notes.push_back(fmt::format(
        "near-planar motion: the rotation axes stay within a narrow cone about [{:.3f} {:.3f} "
        "{:.3f}] (GNSS/INS frame; rotation singular values {:.3f} {:.3f} {:.3f} rad, the third "
        "below {} of the first): the rotation about it is poorly conditioned and the translation "
        "along it weakly determined (1-sigma below)",
        n.x(), n.y(), n.z(), ob.rotation_singular_values[0], ob.rotation_singular_values[1],
        ob.rotation_singular_values[2], hand_eye::kNearPlanarRatio));
  }
  const hand_eye::Held held = hand_eye::hold_unobservable(ob, prior_T_gnss_lidar, ro.fixed);
  // Why a direction is not estimated: the motion is near-planar and it is the plane's normal, or
  // its 1-sigma is too large.
  auto why = [&](int i) {
    return ob.near_planar && std::abs(ob.translation_directions.col(i).dot(ob.dominant_axis)) > 0.9
               ? std::string("near-planar motion, the plane's normal")
               : fmt::format("1-sigma {:.3f} m above --max-sigma {} m", ob.translation_sigma_m[i],
                             o.max_sigma_m);
  };
  for (int i : held.uncovered) {
    const Eigen::Vector3d d = ob.translation_directions.col(i);
    fmt::print(stderr,
               "rigcal: the motion does not determine the translation along [{:.3f} {:.3f} "
               "{:.3f}] (GNSS/INS frame; {}): give --fix (e.g. z=0.35), --prior (z=0.35,0.02) "
               "or a --rig whose extrinsic holds it; nothing written\n",
               d.x(), d.y(), d.z(), why(i));
  }
  if (!held.uncovered.empty()) throw Exit{3};
  for (int i : held.from_prior) {
    const Eigen::Vector3d d = ob.translation_directions.col(i);
    notes.push_back(fmt::format(
        "translation along [{:.3f} {:.3f} {:.3f}] (GNSS/INS frame) is not determined by the "
        "motion ({}): kept from the rig, {:.4f} m; give --fix or --prior to set it",
        d.x(), d.y(), d.z(), why(i), d.dot(prior_T_gnss_lidar->t)));
  }
  const hand_eye::Refined r = hand_eye::refine(pairs, cf.T_gnss_lidar, ro);
  const SE3& X = r.T_gnss_lidar;
  if (sync) {
    // The angular-velocity estimate, refined with the extrinsic (the pairs' LiDAR motion moved
    // with the clock to first order).
    offset_s += r.time_offset_correction_s;
    notes.push_back(fmt::format(
        "clock offset refined with the extrinsic: t_lidar = t_gnss + {:.6f} s, 1-sigma {:.6f} s "
        "({:+.3f} ms from the angular velocities' estimate)",
        offset_s, r.time_offset_sigma_s, 1e3 * r.time_offset_correction_s));
  }
  const Eigen::Vector3d rpy = roll_pitch_yaw(X.R) * 180.0 / M_PI;
  const Eigen::Vector3d &sig_r = r.rotation_sigma_deg, &sig_t = r.translation_sigma_m;
  size_t outliers = 0;
  for (bool b : r.outlier) outliers += b;

  fmt::print(
      "{} motion pairs of {} s, {} (LiDAR {} poses, GNSS/INS {} poses); {} left out of the "
      "closed form by the consensus\n",
      pairs.size(), fmt::join(spacings, " and "),
      o.stride_s > 0 ? fmt::format("each length every {} s", o.stride_s) : "end to end",
      lidar.size(), gnss.size(), cf.rejected);
  for (const hand_eye::Refined::PairNoise& n : r.pair_noise) {
    fmt::print("pairs of {:.2f} s: {} inliers, noise {:.4f} deg and {:.4f} m per component\n",
               n.length_s, n.pairs, n.rotation_deg, n.translation_m);
  }
  fmt::print(
      "observability: rotation singular values {:.3f} {:.3f} {:.3f} rad; translation 1-sigma along "
      "its principal directions {:.4f} {:.4f} {:.4f} m\n",
      ob.rotation_singular_values[0], ob.rotation_singular_values[1],
      ob.rotation_singular_values[2], ob.translation_sigma_m[0], ob.translation_sigma_m[1],
      ob.translation_sigma_m[2]);
  fmt::print(
      "T_{}_{}: t = [{:.4f} {:.4f} {:.4f}] ± [{:.4f} {:.4f} {:.4f}] m, roll pitch yaw "
      "{:.3f} {:.3f} {:.3f} ± {:.3f} {:.3f} {:.3f} deg; {} outlier pairs\n",
      o.sensor, o.lidar_sensor, X.t.x(), X.t.y(), X.t.z(), sig_t.x(), sig_t.y(), sig_t.z(), rpy.x(),
      rpy.y(), rpy.z(), sig_r.x(), sig_r.y(), sig_r.z(), outliers);
  fmt::print("odometry scale {:.5f} ± {:.5f} (GNSS/INS distance over LiDAR distance)\n",
             r.odometry_scale, r.odometry_scale_sigma);
  for (const std::string& n : notes) fmt::print("note: {}\n", n);

  std::vector<io::OutputFile> files;
  if (!o.report.empty()) {
    io::HandEyeInputs in{
        o.lidar,       o.gnss, o.rig, offset_s, spacings, o.stride_s, o.min_rotation_deg,
        o.max_sigma_m, notes};
    files = io::hand_eye_report_files(o.report, in, pairs, cf, r, lidar, gnss);
  }
  if (!o.out.empty()) {
    rig::sensor(rig, o.sensor).T_base_sensor = T_base_lidar * X.inverse();
    if (sync) rig::set_clock_from(rig, o.sensor, o.lidar_sensor, offset_s);
    files.push_back({o.out, rig::rig_to_yaml(rig)});
  }
  io::write_files_atomic(files);
  if (!o.out.empty()) fmt::print("{}: T_b written to {}\n", o.sensor, o.out);
  if (!o.report.empty()) fmt::print("report: {}/hand_eye.json and PNGs\n", o.report);
}

}  // namespace

void add_hand_eye(CLI::App& app) {
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "hand-eye",
      "The GNSS/INS-to-LiDAR extrinsic from the LiDAR odometry and the GNSS/INS trajectory\n"
      "(doc/hand-eye.md): motion pairs, closed form, robust refinement, covariance, and the\n"
      "directions the motion does not determine (a car on a plane leaves the vertical offset\n"
      "free: give --fix z=METRES or --prior z=METRES,SIGMA, or the rig's value is kept and said\n"
      "so). Inputs: TUM, KITTI with times, EuRoC. Exit 0; 2 on bad input, 3 when a\n"
      "direction is undetermined and nothing fixes it: nothing written in either case.");
  cmd->add_option("--lidar", o->lidar, "LiDAR odometry trajectory (T_odom_lidar)")->required();
  cmd->add_option("--gnss", o->gnss,
                  "GNSS/INS trajectory (T_enu_gnss; TUM, KITTI, EuRoC, OpenCalib), or a CSV of "
                  "fixes with a header (time, latitude, longitude, height, roll, pitch, yaw), on "
                  "its own clock")
      ->required();
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
                  "trajectories.png");
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
      ->capture_default_str();
  cmd->add_option("--stride", o->stride_s,
                  "seconds between the starts of consecutive pairs (0: end to end); overlapping "
                  "pairs are not counted as independent in the covariance")
      ->capture_default_str();
  cmd->add_option(
         "--gnss-smoothing", o->gnss_smoothing_s,
         "each GNSS/INS pose from a local quadratic fit over the fixes within +- this many "
         "seconds (at least 5 of them; 0: the fixes as they are)")
      ->capture_default_str();
  cmd->add_option("--min-rotation", o->min_rotation_deg, "pairs rotating less are dropped (deg)")
      ->capture_default_str();
  cmd->add_option("--rotation-sigma", o->rotation_sigma_deg, "per-pair rotation noise (deg)")
      ->capture_default_str();
  cmd->add_option("--translation-sigma", o->translation_sigma_m, "per-pair translation noise (m)")
      ->capture_default_str();
  cmd->add_option("--max-sigma", o->max_sigma_m,
                  "a translation direction with a larger 1-sigma is not estimated (m)")
      ->capture_default_str();
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::cli
