// rigcal ground-truth: the LiDAR's trajectory from its odometry and the GNSS fixes through a pose
// graph, in the fixes' local ENU frame, with each pose's sigmas (doc/ground-truth.md).
#include <fmt/format.h>

#include <memory>

#include "cli.h"
#include "rigcal/core/error.h"
#include "rigcal/gt/step.h"
#include "rigcal/io/files.h"
#include "rigcal/io/ground_truth_io.h"
#include "rigcal/io/odometry_io.h"
#include "rigcal/io/trajectory_io.h"
#include "rigcal/rig/rig_yaml.h"
#include "step_output.h"

namespace rigcal::cli {
namespace {
namespace fs = std::filesystem;

struct Options {
  std::string recording, rig, out, sigmas, odometry, covariances, gnss, report, scans;
  std::string gnss_sensor = "gnss", odometry_preset;
  double max_fix_gap_s = 0.5, fix_correlation_s = 0.0;
  bool no_bundle_adjustment = false;
  size_t window_scans = gt::SequenceBaConfig{}.window_scans;
  size_t window_overlap = gt::SequenceBaConfig{}.overlap_scans;
};

fs::path default_gnss(const fs::path& recording) {
  for (const char* name : {"gnss/poses.tum", "gnss/fixes.csv", "gnss/navsat.csv"})
    if (fs::exists(recording / name)) return recording / name;
  throw Error(fmt::format("{}: no gnss/poses.tum, gnss/fixes.csv or gnss/navsat.csv; give --gnss",
                          recording.string()));
}

void run(const Options& o) {
  gt::StepInputs in;
  in.rig = rig::read_rig_file(o.rig);
  in.rig_source = o.rig;
  in.gnss = o.gnss.empty() ? default_gnss(o.recording) : fs::path(o.gnss);
  if (!o.scans.empty()) {
    in.scans = lidar::scans_folder(o.scans, console_progress());
  } else if (o.odometry.empty()) {
    in.scans = lidar::scans_folder(o.recording, console_progress());
  } else if (!o.no_bundle_adjustment) {
    try {  // the scans of the bundle adjustment, when the recording has them
      in.scans = lidar::scans_folder(o.recording, console_progress());
    } catch (const Error&) {
    }
  }
  if (!o.odometry.empty()) in.odometry = o.odometry, in.covariances = o.covariances;
  gt::StepOptions options;
  options.gnss_sensor = o.gnss_sensor;
  options.odometry_preset = o.odometry_preset;
  options.pose_graph.max_fix_gap_s = o.max_fix_gap_s;
  options.pose_graph.fix_correlation_s = o.fix_correlation_s;
  options.bundle_adjustment = !o.no_bundle_adjustment;
  options.ba.window_scans = o.window_scans;
  options.ba.overlap_scans = o.window_overlap;
  const std::string sigmas =
      o.sigmas.empty() ? fs::path(o.out).replace_extension("").string() + "_sigmas.txt" : o.sigmas;
  std::vector<io::OutputFile> files = {{o.out, ""}, {sigmas, ""}};
  if (!o.report.empty()) files.push_back({o.report + "/ground_truth.json", ""});
  io::refuse_outputs_over_inputs(files, {{"gnss", in.gnss},
                                         {"odometry", in.odometry},
                                         {"covariances", in.covariances},
                                         {"scans", in.scans},
                                         {"rig", o.rig}});

  const gt::GroundTruthRun run = gt::run_ground_truth(in, options, console_progress());
  const gt::PoseGraphResult& g = run.graph;
  const nlohmann::json report = gt::ground_truth_report(run, in);
  const nlohmann::json& s = report["summary"];
  fmt::print("poses: {}, path {:.1f} m; fixes: {} ({} RTK fixed), priors {} ({} rejected)\n",
             s["poses"].get<size_t>(), s["path_length_m"].get<double>(), s["fixes"].get<size_t>(),
             s["fixes_rtk_fixed"].get<size_t>(), s["priors"].get<size_t>(),
             s["priors_rejected"].get<size_t>());
  for (const auto& [from, to] : g.outages)
    fmt::print("outage: {:.1f} s without a fix, bridged by the odometry\n", (to - from).seconds());
  if (!s["prior_residual_horizontal_m"].is_null()) {
    fmt::print("prior residuals: horizontal rms {:.1f} mm, vertical rms {:.1f} mm\n",
               1e3 * s["prior_residual_horizontal_m"]["rms"].get<double>(),
               1e3 * s["prior_residual_vertical_m"]["rms"].get<double>());
  }
  if (!s["pose_sigma_horizontal_m"].is_null()) {
    fmt::print("pose sigmas: horizontal median {:.1f} mm (max {:.1f}), yaw median {:.3f} deg\n",
               1e3 * s["pose_sigma_horizontal_m"]["median"].get<double>(),
               1e3 * s["pose_sigma_horizontal_m"]["max"].get<double>(),
               s["pose_sigma_yaw_deg"]["median"].get<double>());
  }
  if (run.ba) {
    const nlohmann::json& b = report["bundle_adjustment"];
    fmt::print(
        "bundle adjustment: {} windows in {:.1f} s; points off their planes rms {:.1f} mm before, "
        "{:.1f} mm after (median over the windows); poses moved {:.1f} mm rms from the pose "
        "graph's\n",
        run.ba->windows.size(), run.ba->seconds,
        1e3 * b["point_plane_rms_before_m"]["median"].get<double>(),
        1e3 * b["point_plane_rms_after_m"]["median"].get<double>(),
        1e3 * b["pose_change_from_stage1_m"]["rms"].get<double>());
  }
  for (const nlohmann::json& n : report["notes"]) fmt::print("note: {}\n", n.get<std::string>());
  if (!o.report.empty()) files[2].content = report.dump(1) + "\n";
  auto say_undetermined = [&g] {
    for (const gt::Undetermined& u : g.undetermined)
      fmt::print(stderr, "undetermined: {}: {}\n", u.what, u.why);
  };
  if (g.T_enu_lidar.empty()) {
    // Nothing placed: the report only.
    say_undetermined();
    if (!o.report.empty()) io::write_files_atomic({files[2]});
    throw Exit{3};
  }
  files[0].content = io::ground_truth_to_text(g.T_enu_lidar);
  if (g.covariance.empty())
    files.erase(files.begin() + 1);
  else
    files[1].content = io::pose_sigmas_to_text(g.T_enu_lidar, g.covariance);
  io::write_files_atomic(files);
  fmt::print("wrote {} (T_enu_lidar at each scan's stamp, VBR's ground-truth format){}{}\n", o.out,
             g.covariance.empty() ? "" : ", " + sigmas,
             o.report.empty() ? "" : fmt::format("; report {}/ground_truth.json", o.report));
  if (!g.undetermined.empty()) {
    say_undetermined();
    throw Exit{3};
  }
}

}  // namespace

void add_ground_truth(CLI::App& app) {
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "ground-truth",
      "The LiDAR's ground-truth trajectory (doc/ground-truth.md): a pose graph over the scan\n"
      "poses with the odometry's steps weighted by their covariances and the GNSS fixes as\n"
      "position priors through the lever arm (robust solve, a chi-square gate, a second\n"
      "solve). Writes OUT (VBR's <seq>_gt.txt: T_enu_lidar, ENU at the first fix) and each\n"
      "pose's sigmas. Then, when the scans are there, the geometric LiDAR bundle adjustment:\n"
      "overlapping windows of scans, each sweep deskewed by the motion it estimates, the\n"
      "points brought onto planar patches; the windows' motions replace the odometry's in the\n"
      "pose graph, solved again with the same priors. Exit 3 when the fixes leave something\n"
      "undetermined (said on stderr). The photometric term is not built.");
  cmd->add_option("recording", o->recording,
                  "the recording: its gnss/ (poses.tum, fixes.csv or navsat.csv) and its scans "
                  "(ouster_points/, a capture, a session): the odometry's without --odometry, "
                  "the bundle adjustment's")
      ->required();
  cmd->add_option("--rig", o->rig, "the calibration: the GNSS sensor's T_b and time_offset")
      ->required();
  cmd->add_option("--out", o->out, "output trajectory (VBR ground-truth format)")->required();
  cmd->add_option("--sigmas", o->sigmas,
                  "output per-pose standard deviations (default: OUT without extension + "
                  "_sigmas.txt)");
  cmd->add_option("--odometry", o->odometry,
                  "an odometry trajectory (T_odom_lidar) instead of running rigcal's on the scans");
  cmd->add_option("--covariances", o->covariances,
                  "its step covariances (default: ODOMETRY without extension + _covariances.txt)");
  cmd->add_option("--gnss", o->gnss, "GNSS/INS poses (TUM, T_enu_gnss) or fixes (CSV)");
  cmd->add_option("--gnss-sensor", o->gnss_sensor, "the rig's GNSS sensor")->capture_default_str();
  cmd->add_option("--odometry-preset", o->odometry_preset,
                  "rigcal's odometry preset (default: the rig LiDAR's model)")
      ->check(CLI::IsMember(lidar::preset_names()));
  cmd->add_option("--max-fix-gap", o->max_fix_gap_s,
                  "a scan gets a prior from the fixes around it when they are at most this far "
                  "apart, s")
      ->check(seconds_within(1e-6, 60))
      ->capture_default_str();
  cmd->add_option("--fix-correlation", o->fix_correlation_s,
                  "the fixes' error correlation time, s: priors within it count as one "
                  "(0: independent)")
      ->check(seconds_within(0, 600))
      ->capture_default_str();
  cmd->add_option("--scans", o->scans,
                  "the scans (a folder, a capture, a recording; default: the recording's)");
  cmd->add_flag("--no-bundle-adjustment", o->no_bundle_adjustment,
                "stop at the pose graph (stage 1)");
  cmd->add_option("--window-scans", o->window_scans, "scans a bundle-adjustment window")
      ->check(CLI::Range(size_t(2), size_t(1000)))
      ->capture_default_str();
  cmd->add_option("--window-overlap", o->window_overlap,
                  "scans each window shares with the previous one")
      ->check(CLI::Range(size_t(0), size_t(999)))
      ->capture_default_str();
  cmd->add_option("--report", o->report,
                  "report folder: ground_truth.json, one row a prior, one a window");
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::cli
