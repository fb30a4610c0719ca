#include "rigcal/hand_eye/step.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>

#include "rigcal/core/error.h"
#include "rigcal/core/se3.h"
#include "rigcal/core/stats.h"
#include "rigcal/core/text.h"
#include "rigcal/core/version.h"
#include "rigcal/hand_eye/report.h"
#include "rigcal/io/files.h"
#include "rigcal/io/gnss_fixes.h"
#include "rigcal/io/odometry_io.h"
#include "rigcal/io/session.h"
#include "rigcal/lidar/step.h"
#include "rigcal/report/json.h"
#include "rigcal/report/rotation.h"
#include "rigcal/rig/rig_yaml.h"

namespace rigcal::hand_eye {
namespace {

io::TrajectoryReadOptions read_options(const StepOptions& o) {
  io::TrajectoryReadOptions read;
  read.duplicates = o.duplicates;
  return read;
}

// The GNSS/INS trajectory: poses as they are, or fixes (latitude, longitude, height, attitude)
// turned into a local ENU frame at the first fix.
Trajectory read_gnss(const StepInputs& in, const StepOptions& o,
                     const io::TrajectoryReadOptions& read, std::vector<std::string>& notes) {
  if (!io::is_gnss_fixes_file(in.gnss)) return io::read_trajectory(in.gnss, read).trajectory;
  if (o.attitude.empty()) {
    throw Error(fmt::format(
        "{} holds GNSS fixes: give --attitude enu (yaw counter-clockwise from east) or ned "
        "(heading clockwise from north, body x forward, z down); see doc/hand-eye.md",
        in.gnss.string()));
  }
  const io::GnssFixes fixes = io::read_gnss_fixes(in.gnss, io::attitude_from_string(o.attitude));
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
  return fixes.T_enu_gnss;
}

// What the LiDAR's trajectory came from, for the report.
std::string lidar_name(const StepInputs& in) {
  return in.lidar_scans.empty()
             ? in.lidar.string()
             : fmt::format("lidar_odometry.tum (rigcal's odometry on {})", in.lidar_scans.string());
}

// No estimate: the report says why, with the inputs and the notes so far.
report::StepResult undetermined(report::StepResult out, const StepInputs& in, std::string reason,
                                std::string remedy) {
  out.status = report::StepStatus::undetermined;
  out.reason = std::move(reason);
  out.remedy = std::move(remedy);
  const nlohmann::json j = {
      {"tool_version", version_string()},
      {"inputs", {{"lidar", lidar_name(in)}, {"gnss", in.gnss.string()}, {"rig", in.rig_source}}},
      {"notes", out.notes}};
  out.report_files = {{"hand_eye.json", report::json_text(j)}};
  report::finish_report(out, "hand_eye.json");
  return out;
}

}  // namespace

std::vector<RefineOptions::Fixed> parse_translation_constraints(
    const std::vector<std::string>& specs, bool with_sigma) {
  std::vector<RefineOptions::Fixed> out;
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

namespace {

// The estimate from the LiDAR's trajectory `lidar` (read from in.lidar or made from its scans).
report::StepResult estimate(const StepInputs& in, const StepOptions& o, const Trajectory& lidar,
                            report::StepResult out, const report::Progress& progress) {
  out.step = "hand_eye";
  double offset_s = 0.0;
  SE3 T_base_lidar;
  std::optional<SE3> prior_T_gnss_lidar;
  double prior_offset_s = 0;
  if (in.rig) {
    out.rig = *in.rig;
    const rig::Sensor* g = rig::find_sensor(*in.rig, o.sensor);
    const rig::Sensor* l = rig::find_sensor(*in.rig, o.lidar_sensor);
    if (!g) throw Error(fmt::format("--sensor {}: no such sensor in {}", o.sensor, in.rig_source));
    if (!l)
      throw Error(
          fmt::format("--lidar-sensor {}: no such sensor in {}", o.lidar_sensor, in.rig_source));
    offset_s = g->time_offset - l->time_offset;
    T_base_lidar = l->T_base_sensor;
    prior_T_gnss_lidar = g->T_base_sensor.inverse() * T_base_lidar;
    prior_offset_s = offset_s;
  }
  const io::TrajectoryReadOptions read = read_options(o);
  std::vector<std::string>& notes = out.notes;
  report::tell(progress, "reading the GNSS/INS trajectory", 0, 1);
  const Trajectory gnss = read_gnss(in, o, read, notes);
  report::tell(progress, "reading the GNSS/INS trajectory", 1, 1);
  if (lidar.size() < 2 || gnss.size() < 2) throw Error("each trajectory needs at least 2 poses");

  // The clock offset from the two trajectories' angular velocities (doc/time-offset.md), around
  // the rig's value: t_lidar = t_gnss + offset.
  // Without estimate_offset it is still estimated, to say when the rig's value disagrees.
  time_sync::TimeSyncResult sync;
  if (o.estimate_offset) {
    sync = estimate_clock_offset(lidar, gnss, offset_s);
  } else {
    try {
      sync = estimate_clock_offset(lidar, gnss, offset_s);
    } catch (const Error& e) {
      sync.verdict = "error";
      sync.reason = e.what();
    }
  }
  if (o.estimate_offset) {
    if (sync.verdict != "ok") {
      return undetermined(
          out, in,
          fmt::format("the clock offset cannot be estimated: {}: {}", sync.verdict, sync.reason),
          "turn the rig about changing axes while both trajectories are recorded, or give the "
          "GNSS/INS time_offset in the rig and do not estimate it");
    }
    offset_s = sync.offset_s;
    out.summary.push_back(
        fmt::format("clock offset: t_lidar = t_gnss + {:.6f} s (1-sigma {:.3f} ms, NCC {:.3f})",
                    offset_s, 1e3 * sync.sigma_s, sync.peak_ncc));
  } else if (sync.verdict == "ok" &&
             std::abs(sync.offset_s - offset_s) > std::max(3 * sync.sigma_s, 1e-3)) {
    notes.push_back(fmt::format(
        "the trajectories' angular velocities put the clocks {:+.3f} ms (1-sigma {:.3f} ms) from "
        "the rig's offset (t_lidar = t_gnss + {:.6f} s), which is used as it is: estimate the "
        "offset (--estimate-offset) unless the rig's value is known to be right",
        1e3 * (sync.offset_s - offset_s), 1e3 * sync.sigma_s, offset_s));
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
  PairOptions po = o.pairs;
  po.time_offset_s = offset_s;
  const std::vector<double> spacings = pair_lengths(po);
  report::tell(progress, "motion pairs", 0, 1);
  const std::vector<MotionPair> pairs = motion_pairs(lidar, gnss, po);
  if (pairs.size() < 3) {
    throw Error(fmt::format(
        "{} motion pairs of {} s rotating at least {} deg: too few or too small motions (at least "
        "3 are needed; rotate the rig about changing axes, or lower --min-rotation)",
        pairs.size(), fmt::join(spacings, " and "), po.min_rotation_deg));
  }
  // A rigid mount turns both sensors by the same angle over the same interval: pairs whose
  // angles disagree by far are not this rig's motion (a static or foreign odometry, or clocks
  // apart by more than the pairs' length).
  std::vector<double> angle_ratios;
  for (const MotionPair& p : pairs)
    angle_ratios.push_back(rotation_angle(p.A.R) / rotation_angle(p.B.R));
  const double angle_ratio = median(angle_ratios);
  if (!(angle_ratio > kMinAngleRatio && angle_ratio < 1 / kMinAngleRatio)) {
    throw Error(fmt::format(
        "{} against {}: the LiDAR odometry turns {:.3g} times as far as the GNSS/INS over the same "
        "intervals (median of {} motion pairs; a rigid mount turns both alike): a static or "
        "foreign odometry, or clocks apart by more than the pairs' length (the rig's time_offset, "
        "--estimate-offset)",
        lidar_name(in), in.gnss.string(), angle_ratio, pairs.size()));
  }
  const ClosedForm cf = closed_form(pairs, o.max_sigma_m);
  const Observability& ob = cf.observability;
  if (ob.rotation_singular_values[1] < kMinRotationSpread * ob.rotation_singular_values[0]) {
    const Eigen::Vector3d& n = ob.dominant_axis;
    return undetermined(
        out, in,
        fmt::format("every motion pair turns about one axis, [{:.3f} {:.3f} {:.3f}] (GNSS/INS "
                    "frame; rotation singular values {:.3g} {:.3g} {:.3g} rad): the rotation "
                    "about it is not determined",
                    n.x(), n.y(), n.z(), ob.rotation_singular_values[0],
                    ob.rotation_singular_values[1], ob.rotation_singular_values[2]),
        "record motion that turns about a second axis (pitch or roll the rig), or keep the rig's "
        "rotation");
  }

  // Directions the data do not determine: a fix along them, or the prior rig's value, or no
  // answer for them.
  RefineOptions ro = o.refine;
  ro.estimate_time_offset = o.estimate_offset;
  if (o.estimate_offset) {
    notes.push_back(fmt::format(
        "clock offset estimated from the trajectories' angular velocities: t_lidar = t_gnss + "
        "{:.6f} s, 1-sigma {:.6f} s, peak NCC {:.3f}",
        offset_s, sync.sigma_s, sync.peak_ncc));
  }
  if (ob.near_planar) {
    const Eigen::Vector3d& n = ob.dominant_axis;
    notes.push_back(fmt::format(
        "near-planar motion: the rotation axes stay within a narrow cone about [{:.3f} {:.3f} "
        "{:.3f}] (GNSS/INS frame; rotation singular values {:.3f} {:.3f} {:.3f} rad, the third "
        "below {} of the first): the rotation about it is poorly conditioned and the translation "
        "along it weakly determined (1-sigma below)",
        n.x(), n.y(), n.z(), ob.rotation_singular_values[0], ob.rotation_singular_values[1],
        ob.rotation_singular_values[2], kNearPlanarRatio));
  }
  const Held held = hold_unobservable(ob, prior_T_gnss_lidar, ro.fixed);
  // Why a direction is not estimated: the motion is near-planar and it is the plane's normal, or
  // its 1-sigma is too large.
  auto why = [&](int i) {
    return ob.near_planar && std::abs(ob.translation_directions.col(i).dot(ob.dominant_axis)) > 0.9
               ? std::string("near-planar motion, the plane's normal")
               : fmt::format("1-sigma {:.3f} m above --max-sigma {} m", ob.translation_sigma_m[i],
                             o.max_sigma_m);
  };
  if (!held.uncovered.empty()) {
    std::vector<std::string> reasons;
    for (int i : held.uncovered) {
      const Eigen::Vector3d d = ob.translation_directions.col(i);
      reasons.push_back(
          fmt::format("the motion does not determine the translation along [{:.3f} {:.3f} {:.3f}] "
                      "(GNSS/INS frame; {})",
                      d.x(), d.y(), d.z(), why(i)));
    }
    return undetermined(out, in, fmt::format("{}", fmt::join(reasons, "; ")),
                        "give --fix (e.g. z=0.35), --prior (z=0.35,0.02) or a --rig whose "
                        "extrinsic holds it, or record motion that turns about that direction");
  }
  for (int i : held.from_prior) {
    const Eigen::Vector3d d = ob.translation_directions.col(i);
    notes.push_back(fmt::format(
        "translation along [{:.3f} {:.3f} {:.3f}] (GNSS/INS frame) is not determined by the "
        "motion ({}): kept from the rig, {:.4f} m; give --fix or --prior to set it",
        d.x(), d.y(), d.z(), why(i), d.dot(prior_T_gnss_lidar->t)));
  }
  report::tell(progress, "refining", 0, 1);
  const Refined r = refine(pairs, cf.T_gnss_lidar, ro);
  report::tell(progress, "refining", 1, 1);
  const SE3& X = r.T_gnss_lidar;
  if (o.estimate_offset) {
    // The angular-velocity estimate, refined with the extrinsic (the pairs' LiDAR motion moved
    // with the clock to first order).
    offset_s += r.time_offset_correction_s;
    notes.push_back(fmt::format(
        "clock offset refined with the extrinsic: t_lidar = t_gnss + {:.6f} s, 1-sigma {:.6f} s "
        "({:+.3f} ms from the angular velocities' estimate)",
        offset_s, r.time_offset_sigma_s, 1e3 * r.time_offset_correction_s));
  }
  const Eigen::Vector3d &sig_r = r.rotation_sigma_deg, &sig_t = r.translation_sigma_m;
  size_t outliers = 0;
  for (bool b : r.outlier) outliers += b;
  out.warnings = fit_warnings(r);

  out.summary.push_back(fmt::format(
      "{} motion pairs of {} s, {} (LiDAR {} poses, GNSS/INS {} poses); {} left out of the "
      "closed form by the consensus",
      pairs.size(), fmt::join(spacings, " and "),
      po.stride_s > 0 ? fmt::format("each length every {} s", po.stride_s) : "end to end",
      lidar.size(), gnss.size(), cf.rejected));
  for (const Refined::PairNoise& n : r.pair_noise) {
    out.summary.push_back(
        fmt::format("pairs of {:.2f} s: {} inliers, noise {:.4f} deg and {:.4f} m per component",
                    n.length_s, n.pairs, n.rotation_deg, n.translation_m));
  }
  out.summary.push_back(fmt::format(
      "observability: rotation singular values {:.3f} {:.3f} {:.3f} rad; translation 1-sigma along "
      "its principal directions {:.4f} {:.4f} {:.4f} m",
      ob.rotation_singular_values[0], ob.rotation_singular_values[1],
      ob.rotation_singular_values[2], ob.translation_sigma_m[0], ob.translation_sigma_m[1],
      ob.translation_sigma_m[2]));
  out.summary.push_back(
      fmt::format("T_{}_{}: t = [{:.4f} {:.4f} {:.4f}] ± [{:.4f} {:.4f} {:.4f}] m, {}; {} outlier "
                  "pairs",
                  o.sensor, o.lidar_sensor, X.t.x(), X.t.y(), X.t.z(), sig_t.x(), sig_t.y(),
                  sig_t.z(), report::rotation_text(X.R, sig_r, o.sensor), outliers));
  out.summary.push_back(
      fmt::format("odometry scale {:.5f} ± {:.5f} (GNSS/INS distance over LiDAR distance)",
                  r.odometry_scale, r.odometry_scale_sigma));

  HandEyeInputs rin{lidar_name(in), in.gnss.string(),    in.rig_source, offset_s, spacings,
                    po.stride_s,    po.min_rotation_deg, o.max_sigma_m, notes};
  out.report_files = hand_eye_report_files("", rin, pairs, cf, r, lidar, gnss);
  report::finish_report(out, "hand_eye.json");

  if (in.rig) {
    // The GNSS/INS placed from the LiDAR; what is rigidly attached to it moves with it.
    // The GNSS/INS itself whole (pose, and clock below); what is attached to it, its pose.
    out.wrote = rig::move_rigidly(out.rig, o.sensor, T_base_lidar * X.inverse());
    for (size_t i = 1; i < out.wrote.size(); ++i) {
      if (out.wrote[i] == o.lidar_sensor) {
        throw Error(fmt::format(
            "{}: attached_to {} in {}: the LiDAR would move with the GNSS/INS it is calibrated "
            "against; attach the GNSS/INS to the LiDAR's mount only through the estimate",
            o.lidar_sensor, o.sensor, in.rig_source));
      }
      out.wrote[i] += ".T_b";
    }
    if (o.estimate_offset) rig::set_clock_from(out.rig, o.sensor, o.lidar_sensor, offset_s);
  }
  const std::string name = fmt::format("T_{}_{}", o.sensor, o.lidar_sensor);
  report::add_pose_uncertainty(out.sigmas, out.correlations, name, r.covariance);
  if (o.estimate_offset)
    out.sigmas.push_back({o.sensor + ".time_offset", r.time_offset_sigma_s, "s"});
  out.residuals = {{"pairs", static_cast<double>(pairs.size()), ""},
                   {"outlier_pairs", static_cast<double>(outliers), ""},
                   {"noise_scale", r.noise_scale, ""},
                   {"odometry_scale", r.odometry_scale, ""},
                   {"pair_rotation_median_deg", median(r.pair_rotation_residual_deg), "deg"},
                   {"pair_translation_median_m", median(r.pair_translation_residual_m), "m"}};
  if (o.fit_at_rig && prior_T_gnss_lidar) {
    // The same kind of pairs on the rig's clock, against its extrinsic: medians, robust to the
    // odd outlier pair as the estimate's are.
    PairOptions at = po;
    at.time_offset_s = prior_offset_s;
    std::vector<double> rot_deg, trans_m;
    const SE3& Y = *prior_T_gnss_lidar;
    for (const MotionPair& p : motion_pairs(lidar, gnss, at)) {
      rot_deg.push_back(rotation_angle((Y.R * p.A.R).transpose() * (p.B.R * Y.R)) * 180 / M_PI);
      trans_m.push_back((p.B.R * Y.t + p.B.t - Y.R * p.A.t - Y.t).norm());
    }
    if (!rot_deg.empty()) {
      out.residuals.push_back({"pair_rotation_median_at_rig_deg", median(rot_deg), "deg"});
      out.residuals.push_back({"pair_translation_median_at_rig_m", median(trans_m), "m"});
    }
  }
  return out;
}

}  // namespace

StepInputs step_inputs(const std::filesystem::path& odometry, const std::filesystem::path& scans,
                       const std::filesystem::path& gnss, const std::filesystem::path& session,
                       const std::filesystem::path& rig, const std::filesystem::path& out,
                       const report::Progress& progress) {
  StepInputs in;
  in.lidar = odometry, in.gnss = gnss, in.rig_source = rig.string();
  if (!odometry.empty() && !scans.empty()) throw Error("give --lidar or --scans, not both");
  if (!scans.empty()) in.lidar_scans = lidar::scans_folder(scans, progress);
  if (!session.empty()) {  // what the session names, unless given
    const io::Session s = io::read_session(session, progress);
    if (in.lidar.empty() && in.lidar_scans.empty()) in.lidar = s.odometry;
    if (in.gnss.empty()) in.gnss = s.gnss;
  }
  if ((in.lidar.empty() && in.lidar_scans.empty()) || in.gnss.empty())
    throw Error(
        "give --lidar (or --scans) and --gnss, or a --session whose session.yaml names "
        "odometry and gnss");
  io::refuse_outputs_over_inputs({{out, ""}}, {{"--lidar", in.lidar},
                                               {"--scans", in.lidar_scans},
                                               {"--gnss", in.gnss}});  // --rig may be --out
  if (!rig.empty()) in.rig = rig::read_rig_file(rig);
  return in;
}

report::StepResult estimate_extrinsic(const StepInputs& in, const StepOptions& o,
                                      const report::Progress& progress) {
  report::StepResult out;
  if (in.lidar_scans.empty()) {
    out.inputs = {{"lidar odometry", in.lidar}, {"gnss", in.gnss}};
    report::tell(progress, "reading the LiDAR odometry", 0, 1);
    const Trajectory lidar = io::read_trajectory(in.lidar, read_options(o)).trajectory;
    report::tell(progress, "reading the LiDAR odometry", 1, 1);
    return estimate(in, o, lidar, std::move(out), progress);
  }
  // rigcal's own odometry on the scans, with the preset the rig's LiDAR names.
  out.inputs = {{"lidar scans", in.lidar_scans}, {"gnss", in.gnss}};
  const std::string preset = lidar::choose_preset(
      o.odometry_preset, in.rig ? rig::find_sensor(*in.rig, o.lidar_sensor) : nullptr, out.notes);
  lidar::OdometryConfig config = lidar::odometry_preset(preset);
  config.estimate_sweep_motion = o.odometry_sweep_motion;
  const lidar::OdometryRun run = lidar::run_odometry(in.lidar_scans, config, progress);
  const nlohmann::json odometry = lidar::odometry_report(run);
  const nlohmann::json& s = odometry["summary"];
  out.summary.push_back(fmt::format(
      "LiDAR odometry (rigcal's, preset {}{}): {} scans registered of {}, path {:.2f} m, {:.1f} ms "
      "a scan, {} degenerate steps (odometry.json)",
      preset, o.odometry_sweep_motion ? ", each sweep's motion" : "", run.T_odom_lidar.size(),
      run.steps.size(), s["path_length_m"].get<double>(),
      1e3 * s["registration_seconds_mean"].get<double>(), s["degenerate_steps"].get<size_t>()));
  for (const std::string& n : run.notes) out.notes.push_back("odometry: " + n);
  out = estimate(in, o, run.T_odom_lidar, std::move(out), progress);
  out.report_files.push_back({"lidar_odometry.tum", io::trajectory_to_tum(run.T_odom_lidar)});
  out.report_files.push_back({"lidar_odometry_covariances.txt",
                              io::step_covariances_to_text(lidar::step_covariances(run))});
  out.report_files.push_back({"odometry.json", odometry.dump(1) + "\n"});
  return out;
}

}  // namespace rigcal::hand_eye
