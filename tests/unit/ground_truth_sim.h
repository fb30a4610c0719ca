#pragma once
// A simulated ground-truth recording (`rigcal simulate --what ground-truth`) through
// `rigcal ground-truth --markers --map` (its fixes CSV, with their states and sigmas, at the
// simulator's ENU origin), scored against the simulator's truth: the trajectory in
// the ENU frame without any alignment (the ground truth's whole error, its anchoring by the
// fixes included), its sigmas' honesty, and the markers' distances.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "cli_run.h"
#include "rigcal/bench/evaluate.h"
#include "rigcal/core/se3.h"
#include "rigcal/core/text.h"
#include "rigcal/io/odometry_io.h"
#include "rigcal/io/trajectory_io.h"
#include "rigcal/rig/rig.h"
#include "rigcal/rig/rig_yaml.h"

namespace rigcal::testing {

struct GroundTruthScore {
  int status = -1;
  std::string out, err;
  size_t poses = 0;
  double ate_rms_m = 0, ate_max_m = 0;  // against the truth in ENU, no alignment
  double ate_horizontal_rms_m = 0, ate_vertical_rms_m = 0;
  double within_3_sigma = 0;  // of the position components
  size_t markers = 0, markers_found = 0;
  double marker_rms_m = 0, marker_max_m = 0;
  double sim_seconds = 0, gt_seconds = 0;
  nlohmann::json report;
  // The ground-truth command as it ran, without its outputs (`--out` and the rest): to run it
  // again with other options.
  std::string gt_inputs;
  // With `stages`: RPE over 10 m of path (rms, m) of the ground truth, of stage 1 (the pose
  // graph of rigcal's odometry and the fixes), of rigcal's odometry alone and of the GNSS/INS
  // alone (its poses through the true lever arm, its multipath outliers left out); stage 1's ATE
  // in ENU.
  double rpe10_m = 0, rpe10_stage1_m = 0, rpe10_odometry_m = 0, rpe10_gnss_m = 0;
  double ate_stage1_rms_m = 0, ate_stage1_max_m = 0;
  // The fixes' own bound: the pose graph of the true motions (variances of 1e-10 m^2 and
  // 1e-14 rad^2 a step) and the same fixes: what any estimator of the motions, however good,
  // gets in ENU from these fixes.
  double ate_exact_motions_rms_m = 0;
};

// RPE over 10 m of the estimate's path, consecutive pairs (rigcal bench's delta), rms, m.
inline double rpe_10m(const Trajectory& truth, const Trajectory& estimate) {
  bench::EvalOptions o;
  o.delta = 10;
  o.delta_unit = bench::DeltaUnit::meters;
  const bench::EvalResult r = bench::evaluate(truth, estimate, o);
  return bench::find_rpe(r, "delta")->trans.rmse;
}

// The ENU positions' errors against the truth, rms and max.
inline std::pair<double, double> ate_enu(const Trajectory& estimate, const Trajectory& world,
                                         const SE3& T_enu_world) {
  double sum2 = 0, worst = 0;
  for (size_t k = 0; k < estimate.size() && k < world.size(); ++k) {
    const double e = (estimate.T_world_body[k].t - T_enu_world * world.T_world_body[k].t).norm();
    sum2 += e * e;
    worst = std::max(worst, e);
  }
  return {std::sqrt(sum2 / double(std::max<size_t>(1, estimate.size()))), worst};
}

// `config_yaml`: the simulator's settings on top of the ground-truth part's defaults;
// `gt_args`: more options of `rigcal ground-truth`, in which `@rec` stands for the simulated
// recording's folder (`--attitude @rec/trajectories/gnss_ins.tum`).
inline GroundTruthScore simulated_ground_truth(const std::filesystem::path& dir, uint64_t seed,
                                               const std::string& config_yaml,
                                               const std::string& gt_args = "",
                                               bool stages = false) {
  namespace fs = std::filesystem;
  GroundTruthScore s;
  fs::remove_all(dir);
  fs::create_directories(dir);
  // A command that failed ends the scoring with its status and message.
  auto failed = [&s](const CliRun& r) {
    if (r.status == 0) return false;
    s.status = r.status;
    s.err = r.err;
    return true;
  };
  std::ofstream(dir / "sim.yaml") << config_yaml;
  const CliRun sim =
      rigcal_cli(fmt::format("simulate --what ground-truth --seed {} --config {} "
                             "--out {}",
                             seed, (dir / "sim.yaml").string(), (dir / "rec").string()),
                 dir);
  s.sim_seconds = sim.seconds;
  if (failed(sim)) return s;
  const fs::path rec = dir / "rec";
  const nlohmann::json truth_json = nlohmann::json::parse(slurp(rec / "truth.json"));
  // The fixes with their states and sigmas, in the simulator's ENU frame (its origin).
  const nlohmann::json& origin = truth_json["trajectories"]["enu_origin"];
  const std::string gnss_input =
      fmt::format("--gnss {}/trajectories/gnss_fixes.csv --enu-origin {},{},{}", rec.string(),
                  origin["latitude_deg"].get<double>(), origin["longitude_deg"].get<double>(),
                  origin["height_m"].get<double>());
  std::string extra = gt_args;
  for (size_t at = extra.find("@rec"); at != std::string::npos; at = extra.find("@rec", at))
    extra.replace(at, 4, rec.string());
  std::string args = extra;
  if (stages) {
    // rigcal's odometry once, for every stage.
    const CliRun odometry = rigcal_cli(
        fmt::format("odometry {} --out {}/odometry.tum", rec.string(), dir.string()), dir);
    if (failed(odometry)) return s;
    args += fmt::format(" --odometry {}/odometry.tum", dir.string());
    const Trajectory truth = io::read_trajectory(rec / "trajectories/truth_lidar.tum").trajectory;
    std::vector<io::StepCovariance> exact;
    for (size_t k = 0; k + 1 < truth.size(); ++k) {
      Eigen::Matrix<double, 6, 6> c = Eigen::Matrix<double, 6, 6>::Zero();
      c.diagonal() << 1e-14, 1e-14, 1e-14, 1e-10, 1e-10, 1e-10;
      exact.push_back({truth.stamps[k], truth.stamps[k + 1], c});
    }
    std::ofstream(dir / "exact.tum") << io::trajectory_to_tum(truth);
    std::ofstream(dir / "exact_covariances.txt") << io::step_covariances_to_text(exact);
    const CliRun bound =
        rigcal_cli(fmt::format("ground-truth {0} --rig {0}/truth.yaml {3} --out {1}/exact_gt.txt "
                               "--odometry {1}/exact.tum --no-bundle-adjustment {2}",
                               rec.string(), dir.string(), extra, gnss_input),
                   dir);
    if (failed(bound)) return s;
    const CliRun stage1 =
        rigcal_cli(fmt::format("ground-truth {0} --rig {0}/truth.yaml {2} --out {1}/stage1.txt "
                               "--odometry {1}/odometry.tum --no-bundle-adjustment",
                               rec.string(), dir.string(), gnss_input),
                   dir);
    if (failed(stage1)) return s;
  }
  s.gt_inputs =
      fmt::format("ground-truth {0} --rig {0}/truth.yaml {1} {2}", rec.string(), gnss_input, args);
  const CliRun run =
      rigcal_cli(fmt::format("{0} --markers {1}/trajectories/markers.csv --out {2}/gt.txt --report "
                             "{2}/report --map {2}/map.ply",
                             s.gt_inputs, rec.string(), dir.string()),
                 dir);
  s.status = run.status;
  s.out = run.out;
  s.err = run.err;
  s.gt_seconds = run.seconds;
  if (run.status != 0) return s;
  s.report = nlohmann::json::parse(slurp(dir / "report/ground_truth.json"));
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = truth_json["trajectories"]["T_enu_world"][r][c];
  SE3 T_enu_world;
  T_enu_world.R = m.topLeftCorner<3, 3>();
  T_enu_world.t = m.topRightCorner<3, 1>();
  const Trajectory gt = io::read_trajectory(dir / "gt.txt").trajectory;
  const Trajectory world = io::read_trajectory(rec / "trajectories/truth_lidar.tum").trajectory;
  // The sigmas: stamp, then x y z (m) and three rotations.
  std::istringstream sigmas(slurp(dir / "gt_sigmas.txt"));
  std::string line;
  std::getline(sigmas, line);
  s.poses = gt.size();
  double sum2 = 0, sum2_h = 0;
  size_t within = 0, components = 0;
  for (size_t k = 0; k < gt.size() && k < world.size(); ++k) {
    const Eigen::Vector3d e = gt.T_world_body[k].t - T_enu_world * world.T_world_body[k].t;
    sum2 += e.squaredNorm();
    sum2_h += e.head<2>().squaredNorm();
    s.ate_max_m = std::max(s.ate_max_m, e.norm());
    if (!std::getline(sigmas, line)) continue;
    const std::vector<std::string_view> f = split_fields(line);
    for (int i = 0; i < 3; ++i) {
      within += std::abs(e(i)) < 3 * parse_double(f[size_t(1 + i)], "sigma");
      ++components;
    }
  }
  const double n = double(std::max<size_t>(1, gt.size()));
  s.ate_rms_m = std::sqrt(sum2 / n);
  s.ate_horizontal_rms_m = std::sqrt(sum2_h / n);
  s.ate_vertical_rms_m = std::sqrt((sum2 - sum2_h) / n);
  s.within_3_sigma = components ? double(within) / double(components) : 0.0;
  if (stages) {
    s.rpe10_m = rpe_10m(world, gt);
    const Trajectory stage1 = io::read_trajectory(dir / "stage1.txt").trajectory;
    s.rpe10_stage1_m = rpe_10m(world, stage1);
    std::tie(s.ate_stage1_rms_m, s.ate_stage1_max_m) = ate_enu(stage1, world, T_enu_world);
    s.rpe10_odometry_m = rpe_10m(world, io::read_trajectory(dir / "odometry.tum").trajectory);
    s.ate_exact_motions_rms_m =
        ate_enu(io::read_trajectory(dir / "exact_gt.txt").trajectory, world, T_enu_world).first;
    // The GNSS/INS poses as LiDAR poses (the true lever arm), on the base clock.
    const rig::Rig rig = rig::read_rig_file(rec / "truth.yaml");
    const rig::Sensor* gnss = rig::find_sensor(rig, "gnss");
    const SE3 T_gnss_lidar =
        gnss->T_base_sensor.inverse() * rig::find_sensor(rig, rig.base_frame)->T_base_sensor;
    // Its multipath outliers left out (the simulator flags them): the GNSS at its best.
    const Trajectory T_enu_gnss = io::read_trajectory(rec / "trajectories/gnss_ins.tum").trajectory;
    std::vector<bool> outlier(T_enu_gnss.size(), false);
    for (const nlohmann::json& i : truth_json["trajectories"]["gnss_outlier_indices"])
      outlier[i.get<size_t>()] = true;
    Trajectory T_enu_lidar;
    for (size_t k = 0; k < T_enu_gnss.size(); ++k) {
      if (outlier[k]) continue;
      T_enu_lidar.stamps.push_back(rig::on_base_clock(*gnss, T_enu_gnss.stamps[k]));
      T_enu_lidar.T_world_body.push_back(T_enu_gnss.T_world_body[k] * T_gnss_lidar);
    }
    s.rpe10_gnss_m = rpe_10m(world, T_enu_lidar);
  }
  const nlohmann::json& markers = s.report["markers"];
  s.markers = markers["markers"].get<size_t>();
  s.markers_found = markers["found"].get<size_t>();
  s.marker_rms_m = markers["distance_error_rms_m"].get<double>();
  s.marker_max_m = markers["distance_error_max_m"].get<double>();
  return s;
}

}  // namespace rigcal::testing
