#include "rigcal/gt/step.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "rigcal/bench/metrics.h"
#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/core/version.h"
#include "rigcal/gt/report_html.h"
#include "rigcal/io/ground_truth_io.h"
#include "rigcal/io/odometry_io.h"
#include "rigcal/io/trajectory_io.h"
#include "rigcal/report/json.h"
#include "rigcal/rig/rig_yaml.h"

namespace rigcal::gt {
namespace fs = std::filesystem;

namespace {

// The GNSS sensor's stamps on the base clock.
Trajectory on_base_clock(Trajectory T_enu_gnss, const rig::Sensor& gnss) {
  for (Time& t : T_enu_gnss.stamps) t = rig::on_base_clock(gnss, t);
  return T_enu_gnss;
}

}  // namespace

std::vector<Matrix6d> covariances_of_steps(const Trajectory& T_odom_lidar,
                                           const std::vector<io::StepCovariance>& steps,
                                           const std::string& source) {
  std::unordered_map<int64_t, const io::StepCovariance*> by_prev;
  for (const io::StepCovariance& s : steps) by_prev[s.prev.ns] = &s;
  std::vector<Matrix6d> out;
  for (size_t k = 0; k + 1 < T_odom_lidar.size(); ++k) {
    const auto it = by_prev.find(T_odom_lidar.stamps[k].ns);
    if (it == by_prev.end() || it->second->cur != T_odom_lidar.stamps[k + 1]) {
      throw Error(fmt::format(
          "{}: no covariance for the step from {} s to {} s of the odometry (the covariances of "
          "another run?)",
          source, to_seconds_text(T_odom_lidar.stamps[k]),
          to_seconds_text(T_odom_lidar.stamps[k + 1])));
    }
    out.push_back(it->second->covariance);
  }
  return out;
}

namespace {

// A trajectory and its step covariances (`covariances`, or beside it), as the pose graph takes
// motions. `what_to_do` ends the error when the covariances are missing.
OdometryInput read_motions(const fs::path& trajectory, const fs::path& covariances_given,
                           const std::string& what_to_do) {
  const fs::path covariances =
      covariances_given.empty() ? io::step_covariances_beside(trajectory) : covariances_given;
  if (!fs::exists(covariances)) {
    throw Error(fmt::format(
        "{}: no step covariances (looked for {}): the pose graph weighs each step by its "
        "covariance; {}",
        trajectory.string(), covariances.string(), what_to_do));
  }
  OdometryInput motions;
  motions.T_odom_lidar = io::read_trajectory(trajectory).trajectory;
  motions.step_covariance = covariances_of_steps(
      motions.T_odom_lidar, io::read_step_covariances(covariances), covariances.string());
  return motions;
}

}  // namespace

GroundTruthRun run_ground_truth(const StepInputs& in, const StepOptions& o,
                                const report::Progress& progress) {
  const auto started = std::chrono::steady_clock::now();
  GroundTruthRun run;
  const rig::Sensor* gnss = rig::find_sensor(in.rig, o.gnss_sensor);
  const rig::Sensor* lidar = rig::find_sensor(in.rig, o.lidar_sensor);
  if (!gnss)
    throw Error(
        fmt::format("--gnss-sensor {}: no such sensor in {}", o.gnss_sensor, in.rig_source));
  if (!lidar)
    throw Error(
        fmt::format("--lidar-sensor {}: no such sensor in {}", o.lidar_sensor, in.rig_source));
  run.p_lidar_antenna = (lidar->T_base_sensor.inverse() * gnss->T_base_sensor).t;

  // The odometry: a file and its covariances, or rigcal's run.
  const bool chunk = o.ba.first_window > 0 || o.ba.end_window != std::numeric_limits<size_t>::max();
  if (o.ba.first_window >= o.ba.end_window)
    throw Error(
        fmt::format("windows {}:{}: FROM must be below TO", o.ba.first_window, o.ba.end_window));
  if (chunk && (!in.window_motions.empty() || !o.bundle_adjustment || in.scans.empty()))
    throw Error(
        "a chunk of windows is a piece of the bundle adjustment: it needs the scans, and neither "
        "chunks' motions to join nor --no-bundle-adjustment");
  OdometryInput odometry;
  if (!in.odometry.empty()) {
    report::tell(progress, "reading the odometry", 0, 1);
    odometry = read_motions(in.odometry, in.covariances,
                            "give --covariances, or let rigcal's odometry run on the scans");
    report::tell(progress, "reading the odometry", 1, 1);
  } else {
    if (in.scans.empty()) throw Error("no odometry and no scans: give one of them");
    run.odometry_preset = lidar::choose_preset(o.odometry_preset, lidar, run.notes);
    lidar::OdometryConfig config = lidar::odometry_preset(run.odometry_preset);
    config.estimate_sweep_motion = o.odometry_sweep_motion;
    run.odometry = lidar::run_odometry(in.scans, config, progress);
    for (const std::string& n : run.odometry->notes) run.notes.push_back("odometry: " + n);
    odometry.T_odom_lidar = run.odometry->T_odom_lidar;
    odometry.step_covariance = covariances_of_steps(
        odometry.T_odom_lidar, lidar::step_covariances(*run.odometry), "rigcal's odometry");
  }
  if (odometry.T_odom_lidar.size() < 2)
    throw Error(
        fmt::format("the odometry has {} poses: at least 2 needed", odometry.T_odom_lidar.size()));

  // The fixes: positions, on the base clock.
  report::tell(progress, "reading the GNSS", 0, 1);
  if (io::is_gnss_fixes_file(in.gnss)) {
    const io::GnssFixes f = io::read_gnss_fixes(in.gnss, std::nullopt, o.enu_origin);
    run.origin = f.origin;
    std::vector<FixQuality> quality;
    for (const io::FixType t : f.fix_type) {
      quality.push_back(t == io::FixType::rtk_fixed   ? FixQuality::rtk_fixed
                        : t == io::FixType::rtk_float ? FixQuality::rtk_float
                                                      : FixQuality::single);
    }
    run.fixes = position_fixes(on_base_clock(f.T_enu_gnss, *gnss), f.std_enu_m, f.status, 0.0,
                               o.pose_graph, quality, f.covariance_enu_m2);
    if (f.std_enu_m.empty()) {
      const PoseGraphConfig& c = o.pose_graph;
      run.notes.push_back(
          f.fix_type.empty() && f.status.empty()
              ? fmt::format("{} gives no standard deviations and no fix states: every fix taken "
                            "as RTK fixed (horizontal {} m, vertical {} m)",
                            in.gnss.string(), c.sigma_rtk_fixed.x(), c.sigma_rtk_fixed.y())
              : fmt::format("{} gives no standard deviations: each fix's sigmas (horizontal, "
                            "vertical) by its fix state: RTK fixed {} / {} m, float {} / {} m, "
                            "single {} / {} m",
                            in.gnss.string(), c.sigma_rtk_fixed.x(), c.sigma_rtk_fixed.y(),
                            c.sigma_rtk_float.x(), c.sigma_rtk_float.y(), c.sigma_single.x(),
                            c.sigma_single.y()));
    }
  } else {
    if (o.enu_origin) {
      throw Error(fmt::format(
          "{}: an ENU origin applies to fixes (a CSV of latitude, longitude, height); GNSS/INS "
          "poses are already in their own ENU frame",
          in.gnss.string()));
    }
    const Trajectory T_enu_gnss = io::read_trajectory(in.gnss).trajectory;
    run.fixes = position_fixes(on_base_clock(T_enu_gnss, *gnss), {}, {}, 0.0, o.pose_graph);
    run.notes.push_back(fmt::format(
        "{}: GNSS/INS poses without accuracies: their positions taken as RTK fixed (horizontal {} "
        "m, vertical {} m){}",
        in.gnss.string(), o.pose_graph.sigma_rtk_fixed.x(), o.pose_graph.sigma_rtk_fixed.y(),
        in.attitude == in.gnss ? ""
                               : "; their attitude is not used (--attitude takes it as priors)"));
  }
  if (!in.attitude.empty()) {
    if (gnss->gnss_frame != "ins") {
      throw Error(fmt::format(
          "--attitude {}: the rig's {} is a GNSS antenna (gnss_frame: {}), which has no attitude; "
          "attitudes need the GNSS/INS's INS frame as the rig's GNSS sensor",
          in.attitude.string(), o.gnss_sensor, gnss->gnss_frame));
    }
    const Trajectory T_enu_ins = io::read_trajectory(in.attitude).trajectory;
    const Eigen::Quaterniond q_ins_lidar =
        (gnss->T_base_sensor.inverse() * lidar->T_base_sensor).quaternion();
    try {
      run.attitudes = attitude_fixes(on_base_clock(T_enu_ins, *gnss), q_ins_lidar, 0.0,
                                     o.attitude_sigma_deg * M_PI / 180.0);
      run.attitude_correlation_s = o.pose_graph.attitude_correlation_s;
    } catch (const Error& e) {
      throw Error(fmt::format("{}: {}", in.attitude.string(), e.what()));
    }
  }
  report::tell(progress, "reading the GNSS", 1, 1);

  // The fixes' correlation time, when not given: from the residuals of a solve that takes them
  // as independent, then solved again with it.
  auto solve = [&](const OdometryInput& motions) {
    PoseGraphConfig config = o.pose_graph;
    if (config.fix_correlation_s >= 0)
      return solve_pose_graph(motions, run.fixes, run.p_lidar_antenna, config, run.attitudes);
    // A solve that takes the fixes as more independent than they are follows their drift, and
    // its residuals understate the correlation: estimated again from each solve's residuals
    // until it settles (within 10 %, at most 6 solves).
    config.fix_correlation_s = 0;
    PoseGraphResult g =
        solve_pose_graph(motions, run.fixes, run.p_lidar_antenna, config, run.attitudes);
    run.fix_correlation_estimated = true;
    for (int solves = 1; solves < 6; ++solves) {
      const double tau = estimate_fix_correlation(g.priors, run.fixes);
      if (std::abs(tau - config.fix_correlation_s) <= 0.1 * tau) break;
      config.fix_correlation_s = tau;
      g = solve_pose_graph(motions, run.fixes, run.p_lidar_antenna, config, run.attitudes);
    }
    // With the fixes' error as states, the time that makes the fixes most likely (the loop's
    // estimate still sets the gate's first solve).
    if (config.fix_error_states) {
      config.fix_correlation_by_likelihood = true;
      g = solve_pose_graph(motions, run.fixes, run.p_lidar_antenna, config, run.attitudes);
    }
    run.fix_correlation_s = g.fix_correlation_s;
    return g;
  };
  run.fix_correlation_s = o.pose_graph.fix_correlation_s;
  report::tell(progress, "solving the pose graph", 0, 1);
  run.graph = solve(odometry);
  report::tell(progress, "solving the pose graph", 1, 1);

  // Stage 2: the windows start from the graph's poses; their motions, in a graph again.
  if (!o.bundle_adjustment) {
    run.notes.push_back("bundle adjustment not asked for: the trajectory is the pose graph's");
  } else if (run.graph.T_enu_lidar.size() != odometry.T_odom_lidar.size()) {
    if (chunk) throw Error("the pose graph placed no poses: no windows to adjust");
    run.notes.push_back("the pose graph placed no poses: no bundle adjustment");
  } else if (!in.window_motions.empty()) {
    std::vector<OdometryInput> chunks;
    std::vector<std::string> sources;
    for (size_t c = 0; c < in.window_motions.size(); ++c) {
      report::tell(progress, "reading the chunks' motions", c, in.window_motions.size());
      chunks.push_back(
          read_motions(in.window_motions[c], {}, "a chunk writes them beside its motions"));
      sources.push_back(in.window_motions[c].string());
    }
    run.ba = join_window_motions(chunks, sources, odometry, run.graph.T_enu_lidar.T_world_body[0]);
    run.ba->config = o.ba;
    if (run.ba->motions_from_odometry > 0) {
      run.notes.push_back(fmt::format(
          "bundle adjustment: {} of {} motions in none of the {} chunks given: the odometry's "
          "kept (a chunk missing?)",
          run.ba->motions_from_odometry, run.ba->motions.step_covariance.size(), chunks.size()));
    }
  } else if (in.scans.empty()) {
    run.notes.push_back(
        "no scans given or found: no bundle adjustment, the trajectory is the pose graph's");
  } else {
    if (o.ba.keyframes_on()) {
      run.notes.push_back(
          "bundle adjustment with keyframes (experimental): the motions between keyframes are the "
          "windows', the scans between them placed along the odometry's path, and the odometry's "
          "motions priors in the windows: as good as the odometry is between keyframes (on the "
          "simulator's walks, poses up to 0.17 m off where it erred, beyond their sigmas), and "
          "not fused with the odometry again afterwards (doc/ground-truth.md, \"Keyframes\")");
    }
    lidar::ScanStream stream(in.scans);
    if (const std::optional<size_t> first =
            first_pose_of_window(odometry.T_odom_lidar, o.ba, o.ba.first_window);
        chunk && first) {
      stream.skip_before(odometry.T_odom_lidar.stamps[*first]);
    }
    run.ba =
        sequence_ba([&] { return stream.next(); }, run.graph.T_enu_lidar, odometry, o.ba, progress);
    if (chunk) {
      run.chunk_motions = owned_motions(*run.ba, run.graph.T_enu_lidar);
      run.seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      return run;
    }
    if (run.ba->motions_from_odometry > 0) {
      run.notes.push_back(fmt::format(
          "bundle adjustment: {} of {} motions kept from the odometry (their windows' information "
          "was singular: the report's windows say which)",
          run.ba->motions_from_odometry, run.ba->motions.step_covariance.size()));
    }
    if (run.ba->scans_unused > 0) {
      run.notes.push_back(
          fmt::format("bundle adjustment: {} scans stamped at no pose of the odometry, not used",
                      run.ba->scans_unused));
    }
  }
  // The adjusted motions (a whole run's, or the chunks' joined) in the pose graph again.
  if (run.ba) {
    report::tell(progress, "solving the pose graph of the adjusted motions", 0, 1);
    run.stage1 = std::move(run.graph);
    // With keyframes the windows hold the odometry's motions already (priors in them): fusing
    // them again would count the odometry twice in the gate, which takes the two as independent.
    if (o.fuse_odometry && !o.ba.keyframes_on()) {
      FusedMotions fused = fuse_motions(odometry, run.ba->motions);
      run.odometry_weight = std::move(fused.weight_a);
      run.fusion_disagreeing_fraction = fused.disagreeing_fraction;
      run.fused = fused.fused;
      if (!fused.fused) {
        run.notes.push_back(fmt::format(
            "the odometry's and the adjustment's motions differ by more than their covariances "
            "allow in {:.1f} % of the steps (1 % expected): one of them claims more than it has, "
            "so the adjustment's motions are taken alone",
            100 * fused.disagreeing_fraction));
      }
      run.graph = solve(fused.motions);
    } else {
      run.graph = solve(run.ba->motions);
    }
    report::tell(progress, "solving the pose graph of the adjusted motions", 1, 1);
  }
  // The map, placed by the result, and the markers in it.
  if ((o.map || in.markers) && in.scans.empty()) {
    run.notes.push_back("no scans: no map, and no markers' check");
  } else if ((o.map || in.markers) && run.graph.T_enu_lidar.size() < 2) {
    run.notes.push_back("the pose graph placed no poses: no map, and no markers' check");
  } else if (o.map || in.markers) {
    lidar::ScanStream stream(in.scans);
    run.map =
        build_map([&] { return stream.next(); }, run.graph.T_enu_lidar, o.map_config, progress);
    if (in.markers) {
      run.markers =
          check_markers(bright_clusters(run.map->bright, o.markers), *in.markers, o.markers);
      if (run.markers->found < in.markers->ids.size()) {
        run.notes.push_back(fmt::format(
            "markers: {} of the survey's {} found in the map (bright points at intensity {:.4g} "
            "or above: --marker-intensity)",
            run.markers->found, in.markers->ids.size(), run.map->bright_intensity));
      }
    }
  }
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return run;
}

nlohmann::json ground_truth_report(const GroundTruthRun& run, const StepInputs& in) {
  const PoseGraphResult& g = run.graph;
  nlohmann::json j;
  j["tool"] = {{"name", "rigcal ground-truth"}, {"version", version_string()}};
  j["inputs"] = {{"odometry", in.odometry.string()},
                 {"scans", in.scans.string()},
                 {"gnss", in.gnss.string()},
                 {"attitude", in.attitude.string()},
                 {"rig", in.rig_source}};
  if (run.odometry) j["inputs"]["odometry_preset"] = run.odometry_preset;
  j["frame"] = run.origin ? nlohmann::json{{"enu_origin",
                                            {{"latitude_deg", run.origin->latitude_deg},
                                             {"longitude_deg", run.origin->longitude_deg},
                                             {"height_m", run.origin->height_m}}}}
                          : nlohmann::json{{"enu", "the GNSS/INS poses' frame"}};
  j["lever_arm_m"] = report::vector_json(run.p_lidar_antenna);
  // Residuals of the priors kept, horizontal and vertical; the poses' sigmas.
  std::vector<double> horizontal, vertical, sigma_h, sigma_v, sigma_yaw;
  for (const PriorResidual& p : g.priors) {
    if (p.rejected) continue;
    horizontal.push_back(p.residual_enu.head<2>().norm());
    vertical.push_back(std::abs(p.residual_enu.z()));
  }
  for (const Matrix6d& c : g.covariance) {
    sigma_h.push_back(std::sqrt(c(3, 3) + c(4, 4)));
    sigma_v.push_back(std::sqrt(c(5, 5)));
    sigma_yaw.push_back(std::sqrt(c(2, 2)) * 180.0 / M_PI);
  }
  auto stats = [](const std::vector<double>& v) {
    if (v.empty()) return nlohmann::json();
    const bench::Stats s = bench::statistics(v);
    return nlohmann::json{{"rms", s.rmse}, {"median", s.median}, {"max", s.max}};
  };
  nlohmann::json outages = nlohmann::json::array();
  for (const auto& [from, to] : g.outages) {
    outages.push_back({{"from_s", to_seconds_text(from)},
                       {"to_s", to_seconds_text(to)},
                       {"duration_s", (to - from).seconds()}});
  }
  nlohmann::json undetermined = nlohmann::json::array();
  for (const Undetermined& u : g.undetermined)
    undetermined.push_back({{"what", u.what}, {"why", u.why}});
  const size_t fixed =
      size_t(std::count_if(run.fixes.begin(), run.fixes.end(), [](const PositionFix& f) {
        return f.quality == FixQuality::rtk_fixed;
      }));
  // The attitudes' residuals kept: tilt (about east and north) and heading (about up), deg.
  std::vector<double> tilt_deg, heading_deg;
  for (const AttitudeResidual& a : g.attitude_priors) {
    if (a.rejected) continue;
    tilt_deg.push_back(a.residual_enu.head<2>().norm() * 180.0 / M_PI);
    heading_deg.push_back(std::abs(a.residual_enu.z()) * 180.0 / M_PI);
  }
  nlohmann::json attitudes;
  if (!run.attitudes.empty()) {
    const Eigen::Matrix3d& c = run.attitudes.front().covariance;
    attitudes = {{"attitudes", run.attitudes.size()},
                 {"sigma_tilt_deg", std::sqrt(c(0, 0)) * 180.0 / M_PI},
                 {"sigma_heading_deg", std::sqrt(c(2, 2)) * 180.0 / M_PI},
                 {"correlation_s", run.attitude_correlation_s},
                 {"priors", g.attitude_priors.size()},
                 {"priors_rejected", g.attitudes_rejected},
                 {"residual_tilt_deg", stats(tilt_deg)},
                 {"residual_heading_deg", stats(heading_deg)}};
  }
  j["summary"] = {
      {"poses", g.T_enu_lidar.size()},
      {"path_length_m", g.T_enu_lidar.empty() ? 0.0 : path_length(g.T_enu_lidar)},
      {"fixes", run.fixes.size()},
      {"fixes_rtk_fixed", fixed},
      {"fixes_unused", g.fixes_unused},
      {"priors", g.priors.size()},
      {"priors_rejected", g.rejected},
      {"outages", outages},
      {"undetermined", undetermined},
      {"prior_residual_horizontal_m", stats(horizontal)},
      {"prior_residual_vertical_m", stats(vertical)},
      {"pose_sigma_horizontal_m", stats(sigma_h)},
      {"pose_sigma_vertical_m", stats(sigma_v)},
      {"pose_sigma_yaw_deg", stats(sigma_yaw)},
      {"fix_correlation_s", run.fix_correlation_s},
      {"fix_correlation",
       !run.fix_correlation_estimated ? "given"
       : g.fix_white_fraction > 0
           ? "the most likely, with the white share (the final solve's marginal likelihood)"
           : "estimated from the solves' prior residuals"},
      {"fix_white_share", g.fix_white_fraction},
      {"attitudes", attitudes},
      {"fix_model", !(run.fix_correlation_s > 0) ? "independent"
                    : g.fix_white_fraction > 0   ? "a Gauss-Markov error state at every scan"
                                                 : "each prior's covariance scaled"},
      {"solver_iterations", g.iterations},
      {"seconds", run.seconds}};
  if (run.ba) {
    const SequenceBaResult& ba = *run.ba;
    std::vector<double> before, after;
    nlohmann::json windows = nlohmann::json::array();
    for (const WindowSummary& w : ba.windows) {
      before.push_back(w.rms_before_m);
      after.push_back(w.rms_after_m);
      windows.push_back({{"first_pose", w.first_pose},
                         {"scans", w.scans},
                         {"rounds", w.rounds},
                         {"patches", w.patches},
                         {"residuals", w.residuals},
                         {"point_plane_rms_before_m", w.rms_before_m},
                         {"point_plane_rms_after_m", w.rms_after_m},
                         {"covariances", w.covariances},
                         {"seconds", w.seconds}});
      if (ba.config.window.photometric.enabled)
        windows.back()["photometric"] = {{"residuals", w.photometric_residuals},
                                         {"sigma_range_m", w.photometric_sigma_range_m},
                                         {"sigma_intensity", w.photometric_sigma_intensity}};
    }
    // How far the adjustment moved the poses from stage 1's.
    std::vector<double> moved_m, turned_deg;
    for (size_t k = 0; run.stage1 && k < g.T_enu_lidar.size(); ++k) {
      const SE3 d =
          run.stage1->T_enu_lidar.T_world_body[k].inverse() * g.T_enu_lidar.T_world_body[k];
      moved_m.push_back(d.t.norm());
      turned_deg.push_back(rotation_angle(d.R) * 180.0 / M_PI);
    }
    j["bundle_adjustment"] = {{"windows", ba.windows.size()},
                              {"keyframes", ba.keyframes.size()},
                              {"config",
                               {{"window_scans", ba.config.window_scans},
                                {"overlap_scans", ba.config.overlap_scans},
                                {"keyframe_distance_m", ba.config.keyframe_distance_m},
                                {"keyframe_angle_deg", ba.config.keyframe_angle_deg},
                                {"keyframe_max_gap", ba.config.keyframe_max_gap},
                                {"knots_per_sweep", ba.config.window.knots_per_sweep},
                                {"voxel_size_m", ba.config.window.voxel_size_m},
                                {"point_sigma_m", ba.config.window.point_sigma_m},
                                {"photometric", ba.config.window.photometric.enabled}}},
                              {"point_plane_rms_before_m", stats(before)},
                              {"point_plane_rms_after_m", stats(after)},
                              {"motions_from_odometry", ba.motions_from_odometry},
                              {"scans_unused", ba.scans_unused},
                              {"pose_change_from_stage1_m", stats(moved_m)},
                              {"rotation_change_from_stage1_deg", stats(turned_deg)},
                              {"seconds", ba.seconds},
                              {"planned_windows", ba.planned_windows},
                              {"per_window", std::move(windows)}};
    if (run.chunk_motions) {
      const Trajectory& T = run.chunk_motions->T_odom_lidar;
      j["bundle_adjustment"]["chunk"] = {
          {"first_window", ba.config.first_window},
          {"end_window", ba.config.end_window},
          {"motions", run.chunk_motions->step_covariance.size()},
          {"from_s",
           T.empty() ? nlohmann::json() : nlohmann::json(to_seconds_text(T.stamps.front()))},
          {"to_s",
           T.empty() ? nlohmann::json() : nlohmann::json(to_seconds_text(T.stamps.back()))}};
    }
    if (!in.window_motions.empty()) {
      nlohmann::json files = nlohmann::json::array();
      for (const fs::path& p : in.window_motions) files.push_back(p.string());
      j["bundle_adjustment"]["joined_chunks"] = std::move(files);
    }
    if (!run.odometry_weight.empty()) {
      const size_t odometry_first =
          size_t(std::count_if(run.odometry_weight.begin(), run.odometry_weight.end(),
                               [](double w) { return w > 0.5; }));
      j["bundle_adjustment"]["fusion_with_odometry"] = {
          {"method", "covariance intersection a step, weight w on the odometry's information"},
          {"odometry_weight", stats(run.odometry_weight)},
          {"steps_weighing_the_odometry_more", odometry_first},
          {"fused", run.fused},
          {"steps_beyond_99_percent_fraction", run.fusion_disagreeing_fraction}};
    }
  }
  if (run.map) {
    const LidarMap& m = *run.map;
    j["map"] = {{"voxel_size_m", m.voxel_size_m},
                {"points", m.points.size()},
                {"scans", m.scans},
                {"scan_points", m.scan_points},
                {"scans_unused", m.scans_unused},
                {"bright_intensity", m.bright_intensity},
                {"bright_points", m.bright.size()}};
  }
  if (run.markers) {
    const MarkerCheck& c = *run.markers;
    const MarkerSurvey& survey = *in.markers;
    nlohmann::json markers = nlohmann::json::array(), pairs = nlohmann::json::array(),
                   clusters = nlohmann::json::array();
    for (size_t i = 0; i < survey.ids.size(); ++i) {
      nlohmann::json row = {{"id", survey.ids[i]}, {"found", c.cluster_of[i] >= 0}};
      if (c.cluster_of[i] >= 0) {
        const BrightCluster& b = c.clusters[size_t(c.cluster_of[i])];
        row["centre_m"] = report::vector_json(b.centre);
        row["points"] = b.points;
        row["sigma_m"] = b.sigma_m;
      }
      markers.push_back(row);
    }
    for (const MarkerDistanceCheck& p : c.pairs) {
      pairs.push_back({{"a", survey.ids[p.a]},
                       {"b", survey.ids[p.b]},
                       {"measured_m", p.measured_m},
                       {"estimated_m", p.estimated_m},
                       {"error_m", p.estimated_m - p.measured_m},
                       {"sigma_m", p.sigma_m}});
    }
    for (const BrightCluster& b : c.clusters) {
      clusters.push_back({{"centre_m", report::vector_json(b.centre)},
                          {"points", b.points},
                          {"extent_m", b.extent_m}});
    }
    j["markers"] = {{"survey", in.markers_file.string()},
                    {"markers", survey.ids.size()},
                    {"found", c.found},
                    {"distance_error_rms_m", c.rms_error_m},
                    {"distance_error_max_m", c.max_error_m},
                    {"tolerance_m", c.tolerance_m},
                    {"per_marker", std::move(markers)},
                    {"pairs", std::move(pairs)},
                    {"bright_clusters", std::move(clusters)}};
  }
  j["notes"] = run.notes;
  for (const std::string& n : g.notes) j["notes"].push_back(n);
  nlohmann::json priors = nlohmann::json::array();
  for (const PriorResidual& p : g.priors) {
    priors.push_back({{"stamp_s", to_seconds_text(p.stamp)},
                      {"pose", p.node},
                      {"fix", p.fix},
                      {"residual_enu_m", report::vector_json(p.residual_enu)},
                      {"mahalanobis2", p.mahalanobis2},
                      {"rejected", p.rejected}});
  }
  j["priors"] = std::move(priors);
  if (!run.attitudes.empty()) {
    nlohmann::json rows = nlohmann::json::array();
    for (const AttitudeResidual& a : g.attitude_priors) {
      rows.push_back({{"stamp_s", to_seconds_text(a.stamp)},
                      {"pose", a.node},
                      {"attitude", a.fix},
                      {"residual_enu_deg", report::vector_json(a.residual_enu * 180.0 / M_PI)},
                      {"mahalanobis2", a.mahalanobis2},
                      {"rejected", a.rejected}});
    }
    j["attitude_priors"] = std::move(rows);
  }
  return j;
}

std::string ground_truth_summary(const GroundTruthRun& run, const nlohmann::json& report) {
  std::string out;
  const nlohmann::json& s = report["summary"];
  out +=
      fmt::format("poses: {}, path {:.1f} m; fixes: {} ({} RTK fixed), priors {} ({} rejected)\n",
                  s["poses"].get<size_t>(), s["path_length_m"].get<double>(),
                  s["fixes"].get<size_t>(), s["fixes_rtk_fixed"].get<size_t>(),
                  s["priors"].get<size_t>(), s["priors_rejected"].get<size_t>());
  if (const nlohmann::json& a = s["attitudes"]; !a.is_null()) {
    out += fmt::format(
        "GNSS/INS attitudes: {} (sigmas: tilt {} deg, heading {} deg), priors {} ({} "
        "rejected)",
        a["attitudes"].get<size_t>(), a["sigma_tilt_deg"].get<double>(),
        a["sigma_heading_deg"].get<double>(), a["priors"].get<size_t>(),
        a["priors_rejected"].get<size_t>());
    if (!a["residual_tilt_deg"].is_null()) {
      out += fmt::format("; residuals: tilt rms {:.3f} deg, heading rms {:.3f} deg",
                         a["residual_tilt_deg"]["rms"].get<double>(),
                         a["residual_heading_deg"]["rms"].get<double>());
    }
    out += "\n";
  }
  for (const auto& [from, to] : run.graph.outages)
    out += fmt::format("outage: {:.1f} s without a fix, bridged by the odometry\n",
                       (to - from).seconds());
  if (!s["prior_residual_horizontal_m"].is_null()) {
    out += fmt::format("prior residuals: horizontal rms {:.1f} mm, vertical rms {:.1f} mm\n",
                       1e3 * s["prior_residual_horizontal_m"]["rms"].get<double>(),
                       1e3 * s["prior_residual_vertical_m"]["rms"].get<double>());
  }
  out += fmt::format("the fixes' error correlation time: {:.1f} s ({}); their errors: {}",
                     run.fix_correlation_s, s["fix_correlation"].get<std::string>(),
                     s["fix_model"].get<std::string>());
  if (run.graph.fix_white_fraction > 0)
    out += fmt::format(", {:.2g} of their variance white", run.graph.fix_white_fraction);
  out += "\n";
  if (!s["pose_sigma_horizontal_m"].is_null()) {
    out += fmt::format(
        "pose sigmas: horizontal median {:.1f} mm (max {:.1f}), yaw median {:.3f} deg\n",
        1e3 * s["pose_sigma_horizontal_m"]["median"].get<double>(),
        1e3 * s["pose_sigma_horizontal_m"]["max"].get<double>(),
        s["pose_sigma_yaw_deg"]["median"].get<double>());
  }
  if (run.chunk_motions) {
    const nlohmann::json& chunk = report["bundle_adjustment"]["chunk"];
    const size_t first = chunk["first_window"], planned = run.ba->planned_windows;
    const size_t end = std::min(chunk["end_window"].get<size_t>(), planned);
    if (run.chunk_motions->step_covariance.empty()) {
      out += fmt::format(
          "bundle adjustment, a chunk: the plan has {} windows (numbered from 0), none in "
          "{}:{} (nothing written)\n",
          planned, first, chunk["end_window"].get<size_t>());
    } else {
      out += fmt::format(
          "bundle adjustment, a chunk: windows {}..{} of the plan's {} (numbered from 0) in "
          "{:.1f} s; they own the {} motions from {} s to {} s\n",
          first, end - 1, planned, run.ba->seconds, run.chunk_motions->step_covariance.size(),
          chunk["from_s"].get<std::string>(), chunk["to_s"].get<std::string>());
    }
  } else if (run.ba && run.ba->windows.empty()) {
    out += fmt::format(
        "bundle adjustment: the motions of {} chunks joined, {} of {} motions from them\n",
        report["bundle_adjustment"]["joined_chunks"].size(),
        run.ba->motions.step_covariance.size() - run.ba->motions_from_odometry,
        run.ba->motions.step_covariance.size());
  } else if (run.ba) {
    const nlohmann::json& b = report["bundle_adjustment"];
    out += fmt::format(
        "bundle adjustment: {} windows of {} keyframes ({} scans) in {:.1f} s; points off their "
        "planes rms {:.1f} mm before, {:.1f} mm after (median over the windows); poses moved "
        "{:.1f} mm rms from the pose graph's\n",
        run.ba->windows.size(), run.ba->keyframes.size(), run.ba->motions.T_odom_lidar.size(),
        run.ba->seconds, 1e3 * b["point_plane_rms_before_m"]["median"].get<double>(),
        1e3 * b["point_plane_rms_after_m"]["median"].get<double>(),
        1e3 * b["pose_change_from_stage1_m"]["rms"].get<double>());
  }
  if (run.fused) {
    const nlohmann::json& b = report["bundle_adjustment"];
    const size_t steps = run.odometry_weight.size();
    out += fmt::format(
        "motions: the adjustment's fused with the odometry's (covariance intersection), the "
        "odometry weighing more in {} of {} steps; {:.1f} % of the steps apart beyond the 99 % "
        "quantile of their covariances\n",
        b["fusion_with_odometry"]["steps_weighing_the_odometry_more"].get<size_t>(), steps,
        100 * run.fusion_disagreeing_fraction);
  }
  if (run.map) {
    out += fmt::format("map: {} points in {} m voxels from {} scans\n", run.map->points.size(),
                       run.map->voxel_size_m, run.map->scans);
  }
  if (run.markers) {
    const MarkerCheck& c = *run.markers;
    out += fmt::format(
        "markers: {} of {} found; distances between them against the survey's: rms "
        "{:.1f} mm, max {:.1f} mm ({} pairs)\n",
        c.found, c.cluster_of.size(), 1e3 * c.rms_error_m, 1e3 * c.max_error_m, c.pairs.size());
  }
  for (const nlohmann::json& n : report["notes"])
    out += fmt::format("note: {}\n", n.get<std::string>());
  return out;
}

std::filesystem::path default_gnss(const std::filesystem::path& recording) {
  for (const char* name : {"gnss/poses.tum", "gnss/fixes.csv", "gnss/navsat.csv"})
    if (fs::exists(recording / name)) return recording / name;
  throw Error(fmt::format("{}: no gnss/poses.tum, gnss/fixes.csv or gnss/navsat.csv; give --gnss",
                          recording.string()));
}

fs::path scans_of(const fs::path& recording, const fs::path& given, bool odometry_given,
                  bool wanted, const report::Progress& progress) {
  if (!given.empty()) return lidar::scans_folder(given, progress);
  if (!odometry_given) return lidar::scans_folder(recording, progress);
  if (!wanted) return {};
  try {  // the scans of the bundle adjustment and the map, when the recording has them
    return lidar::scans_folder(recording, progress);
  } catch (const Error&) {
    return {};
  }
}

StepInputs step_inputs(const InputFiles& files, const StepOptions& options,
                       const report::Progress& progress) {
  StepInputs in;
  in.rig = rig::read_rig_file(files.rig);
  in.rig_source = files.rig.string();
  in.gnss = files.gnss.empty() ? default_gnss(files.recording) : files.gnss;
  in.attitude = files.attitude;
  in.scans = scans_of(files.recording, files.scans, !files.odometry.empty(),
                      options.bundle_adjustment || options.map || !files.markers.empty(), progress);
  if (!files.odometry.empty()) in.odometry = files.odometry, in.covariances = files.covariances;
  if (!files.markers.empty()) {
    in.markers = io::read_marker_survey(files.markers);
    in.markers_file = files.markers;
  }
  in.window_motions = files.window_motions;
  return in;
}

void apply_command_words(const CommandWords& w, StepOptions& o) {
  o.bundle_adjustment = !w.no_bundle_adjustment;
  o.fuse_odometry = !w.no_fusion;
  o.map = w.map;
  o.attitude_sigma_deg = {w.attitude_sigma_deg.first, w.attitude_sigma_deg.second};
  std::tie(o.ba.keyframe_distance_m, o.ba.keyframe_angle_deg) = w.keyframes;
  if (!w.enu_origin.empty()) o.enu_origin = io::parse_geodetic_origin(w.enu_origin, "--enu-origin");
  o.pose_graph.fix_correlation_s =
      w.fix_correlation == "auto" ? -1.0 : parse_double(w.fix_correlation, "--fix-correlation");
  o.pose_graph.fix_error_states = w.fix_model == "states";
  if (w.windows != std::pair<size_t, size_t>{0, 0})
    std::tie(o.ba.first_window, o.ba.end_window) = w.windows;
}

GroundTruthPaths ground_truth_paths(const fs::path& out, const fs::path& sigmas,
                                    const fs::path& report_dir, const fs::path& map,
                                    const StepInputs& in) {
  GroundTruthPaths paths;
  paths.trajectory = out;
  paths.sigmas = sigmas.empty()
                     ? fs::path(fs::path(out).replace_extension("").string() + "_sigmas.txt")
                     : sigmas;
  if (!report_dir.empty()) paths.report = report_dir / "ground_truth.json";
  paths.map = map;
  io::refuse_outputs_over_inputs({{paths.trajectory, ""},
                                  {paths.sigmas, ""},
                                  {paths.report, ""},
                                  {paths.map, ""},
                                  {io::step_covariances_beside(out), ""}},
                                 {{"gnss", in.gnss},
                                  {"attitude", in.attitude},
                                  {"markers", in.markers_file},
                                  {"odometry", in.odometry},
                                  {"covariances", in.covariances},
                                  {"scans", in.scans},
                                  {"rig", in.rig_source}});
  return paths;
}

std::vector<io::OutputFile> ground_truth_files(const GroundTruthRun& run,
                                               const nlohmann::json& report,
                                               const GroundTruthPaths& paths) {
  const PoseGraphResult& g = run.graph;
  std::vector<io::OutputFile> files;
  if (!paths.report.empty()) {
    files.push_back({paths.report,
                     report.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n"});
    // The page a person reads, and the top view it shows, beside the JSON.
    const std::filesystem::path dir = paths.report.parent_path();
    const std::string top = g.T_enu_lidar.empty() ? "" : trajectory_top_svg(g);
    if (!top.empty()) files.push_back({dir / "trajectory_top.svg", top});
    files.push_back({dir / "report.html", ground_truth_html(report, top)});
  }
  if (run.chunk_motions) {
    const Trajectory& T = run.chunk_motions->T_odom_lidar;
    if (!T.empty() && !paths.trajectory.empty()) {
      std::vector<io::StepCovariance> steps;
      for (size_t k = 0; k + 1 < T.size(); ++k)
        steps.push_back({T.stamps[k], T.stamps[k + 1], run.chunk_motions->step_covariance[k]});
      files.push_back({paths.trajectory, io::trajectory_to_tum(T)});
      files.push_back(
          {io::step_covariances_beside(paths.trajectory), io::step_covariances_to_text(steps)});
    }
    return files;
  }
  if (!g.T_enu_lidar.empty() && !paths.trajectory.empty())
    files.push_back({paths.trajectory, io::ground_truth_to_text(g.T_enu_lidar)});
  if (!g.T_enu_lidar.empty() && !g.covariance.empty() && !paths.sigmas.empty())
    files.push_back({paths.sigmas, io::pose_sigmas_to_text(g.T_enu_lidar, g.covariance)});
  if (!paths.map.empty() && run.map)
    files.push_back({paths.map, io::point_cloud_to_ply(run.map->points, run.map->intensity)});
  return files;
}

CommandOutcome ground_truth_command(const InputFiles& files, const StepOptions& options,
                                    const std::filesystem::path& out,
                                    const std::filesystem::path& sigmas,
                                    const std::filesystem::path& report_dir,
                                    const std::filesystem::path& map,
                                    const report::Progress& progress) {
  const StepInputs in = step_inputs(files, options, progress);
  const GroundTruthPaths paths = ground_truth_paths(out, sigmas, report_dir, map, in);
  const GroundTruthRun run = run_ground_truth(in, options, progress);
  const PoseGraphResult& g = run.graph;
  const nlohmann::json report = ground_truth_report(run, in);
  CommandOutcome o;
  o.text = ground_truth_summary(run, report);
  const std::vector<io::OutputFile> written = ground_truth_files(run, report, paths);
  io::write_files_atomic(written);
  if (run.chunk_motions) {
    for (const io::OutputFile& f : written) o.text += fmt::format("wrote {}\n", f.path.string());
    return o;
  }
  for (const Undetermined& u : g.undetermined)
    o.undetermined.push_back(fmt::format("undetermined: {}: {}", u.what, u.why));
  if (!g.T_enu_lidar.empty()) {
    o.text +=
        fmt::format("wrote {} (T_enu_lidar at each scan's stamp, VBR's ground-truth format){}{}\n",
                    out.string(), g.covariance.empty() ? "" : ", " + paths.sigmas.string(),
                    report_dir.empty() ? "" : "; report " + paths.report.string());
  }
  o.exit_status = g.T_enu_lidar.empty() || !g.undetermined.empty() ? 3 : 0;
  return o;
}

}  // namespace rigcal::gt
