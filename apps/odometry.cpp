// rigcal odometry: the LiDAR's trajectory from its scans, point-to-plane ICP with deskew and the
// covariance of every step (doc/odometry.md).
#include <fmt/format.h>

#include <memory>

#include "cli.h"
#include "rigcal/core/text.h"
#include "rigcal/io/files.h"
#include "rigcal/io/odometry_io.h"
#include "rigcal/io/trajectory_io.h"
#include "rigcal/lidar/step.h"
#include "step_output.h"

namespace rigcal::cli {
namespace odometry_command {

struct Options {
  std::string recording, out, covariances, report, sensor = "os0-128";
  std::optional<double> voxel_size_m, min_range_m, max_range_m;
  bool no_deskew = false, sweep_motion = false;
};

void run(const Options& o) {
  lidar::OdometryConfig config = lidar::odometry_preset(o.sensor);
  if (o.voxel_size_m) config.voxel_size_m = *o.voxel_size_m;
  if (o.min_range_m) config.min_range_m = *o.min_range_m;
  if (o.max_range_m) config.max_range_m = *o.max_range_m;
  config.deskew = !o.no_deskew;
  config.estimate_sweep_motion = o.sweep_motion;
  const std::string covariances =
      o.covariances.empty() ? io::step_covariances_beside(o.out).string() : o.covariances;
  std::vector<io::OutputFile> files = {{o.out, ""}, {covariances, ""}};
  if (!o.report.empty()) files.push_back({o.report + "/odometry.json", ""});
  const std::filesystem::path scans = lidar::scans_folder(o.recording, console_progress());
  io::refuse_outputs_over_inputs(files, {{"scans", scans}});

  const lidar::OdometryRun run = lidar::run_odometry(scans, config, console_progress());
  files[0].content = io::trajectory_to_tum(run.T_odom_lidar);
  files[1].content = io::step_covariances_to_text(lidar::step_covariances(run));
  const nlohmann::json report = lidar::odometry_report(run);
  if (!o.report.empty()) {
    files[2].content = report.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
    for (auto& [name, svg] : lidar::odometry_figures(report))
      files.push_back({o.report + "/" + name, std::move(svg)});
  }
  io::write_files_atomic(files);

  const nlohmann::json& summary = report["summary"];
  fmt::print("scans: {} ({} registered), path length {:.2f} m, {:.1f} ms a scan (max {:.1f} ms)\n",
             run.scans.string(), run.T_odom_lidar.size(), summary["path_length_m"].get<double>(),
             1e3 * summary["registration_seconds_mean"].get<double>(),
             1e3 * summary["registration_seconds_max"].get<double>());
  fmt::print("degenerate steps: {}, not converged: {}, scans skipped: {}\n",
             summary["degenerate_steps"].get<size_t>(),
             summary["not_converged_steps"].get<size_t>(), summary["skipped_scans"].get<size_t>());
  for (const std::string& n : run.notes) fmt::print("note: {}\n", n);
  fmt::print("wrote {} (T_odom_lidar at each scan's stamp, TUM) and {}{}\n", o.out, covariances,
             o.report.empty()
                 ? ""
                 : fmt::format("; report {}/odometry.json and its figures (.svg)", o.report));
}

}  // namespace odometry_command

void add_odometry(CLI::App& app) {
  using namespace odometry_command;
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "odometry",
      "The LiDAR's trajectory from its scans (doc/odometry.md): each sweep deskewed with its\n"
      "per-point times and registered point-to-plane against a local voxel map. Writes OUT\n"
      "(TUM: T_odom_lidar at each scan's stamp, the sweep's first point, VBR's convention) and\n"
      "the covariance of every step T_prev_cur (text, one line a step), all or nothing.");
  cmd->add_option("recording", o->recording,
                  "a scans folder (data/ + timestamps.txt), a recording with ouster_points/, a "
                  "session, a ROS1 bag, an Ouster capture or a KITTI sequence (velodyne/ + "
                  "times.txt)")
      ->required();
  cmd->add_option("--out", o->out, "output trajectory (TUM)")->required();
  cmd->add_option("--covariances", o->covariances,
                  "output step covariances (default: OUT without extension + _covariances.txt)");
  cmd->add_option("--report", o->report,
                  "report folder: odometry.json (one row a step) and its figures: residuals, "
                  "inliers, degeneracy, timing (.svg)");
  cmd->add_option("--sensor", o->sensor,
                  "preset: os0-128 (hand-held, 0.5 m voxels, 50 m) | os1-64 (car, 1 m, 100 m)")
      ->check(CLI::IsMember(lidar::preset_names()))
      ->capture_default_str();
  cmd->add_option("--voxel-size", o->voxel_size_m, "map voxel size, m (overrides the preset)")
      ->check(finite_number(false) & CLI::PositiveNumber);
  cmd->add_option("--min-range", o->min_range_m, "points nearer than this are dropped, m")
      ->check(finite_number(true));
  cmd->add_option("--max-range", o->max_range_m, "points farther than this are dropped, m")
      ->check(finite_number(false) & CLI::PositiveNumber);
  cmd->add_flag("--no-deskew", o->no_deskew, "register the points as measured");
  cmd->add_flag("--sweep-motion", o->sweep_motion,
                "estimate each sweep's own motion with its pose (continuous time, 12 parameters) "
                "instead of taking the step before it: for a walker's bob and sway");
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::cli
