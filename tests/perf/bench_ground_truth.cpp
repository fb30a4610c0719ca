// Speed of the ground truth (doc/performance.md).
// BM_PoseGraph: the pose graph over an hour of 10 Hz scan poses from the simulator's hand-held
// walk (odometry with its step covariance) and its 100 Hz RTK fixes, in memory: the priors at
// the scans, the robust solve, the gate, the second solve and every pose's marginal covariance.
// BM_BundleAdjustment/M: stage 2 on M minutes of the simulator's walk, its sweeps made on the
// fly (nothing on disk; 64 beams x 1024 columns over the OS0's 90 deg unless
// RIGCAL_PERF_FULL_OS0=1 asks for 128 x 2048): the pose graph of the simulated odometry and
// fixes, the windows' bundle adjustment, the pose graph of their motions. The time the
// simulator takes to make the sweeps is measured apart and taken out (`sweeps_s`): reading
// real scans costs far less. Run one size a process for its peak memory (the process's).
// No peer: none of the anchors builds this graph (the paper's code is not public); Ceres is the
// solver underneath.
//   build/bin/rigcal_perf_ground_truth --benchmark_filter=PoseGraph
//   /usr/bin/time -v build/bin/rigcal_perf_ground_truth --benchmark_filter=BundleAdjustment/2
//   build/bin/rigcal_perf_ground_truth --smoke      (small inputs: make test)
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <map>

#include "rigcal/gt/pose_graph.h"
#include "rigcal/gt/sequence_ba.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/sim/session.h"
#include "smoke.h"

namespace {

using namespace rigcal;

bool g_smoke = false;

struct Input {
  gt::OdometryInput odometry;
  std::vector<gt::PositionFix> fixes;
  Eigen::Vector3d p_lidar_antenna;
};

// `correlation_s` > 0: the fixes' errors correlated over that time (first-order Gauss-Markov).
const Input& walk(double seconds, double correlation_s = 0.0) {
  static std::map<std::pair<double, double>, Input> cache;
  auto it = cache.find({seconds, correlation_s});
  if (it != cache.end()) return it->second;
  const rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  sim::SimConfig cfg;
  cfg.trajectory_duration_s = seconds;
  cfg.gnss.outages = {{0.4 * seconds, 0.4 * seconds + 20.0}};
  cfg.gnss.correlation_time_s = correlation_s;
  const sim::TrajectoryPart part = sim::simulate_trajectories(rig, cfg);
  const rig::Sensor& gnss = rig::sensor(rig, part.gnss_name);
  Input in;
  in.p_lidar_antenna = gnss.T_base_sensor.t;
  in.fixes = gt::position_fixes(part.gnss, {}, {}, gnss.time_offset, gt::PoseGraphConfig{});
  in.odometry.T_odom_lidar = part.odometry;
  const double r = cfg.odometry.rot_sigma_deg * M_PI / 180.0, t = cfg.odometry.trans_sigma_m;
  in.odometry.step_covariance.assign(
      part.odometry.size() - 1,
      (Eigen::Matrix<double, 6, 1>() << r * r, r * r, r * r, t * t, t * t, t * t)
          .finished()
          .asDiagonal());
  return cache.emplace(std::make_pair(seconds, correlation_s), std::move(in)).first->second;
}

void BM_PoseGraph(benchmark::State& state) {
  const Input& in = walk(g_smoke ? 120.0 : double(state.range(0)));
  for (auto _ : state) {
    const gt::PoseGraphResult r =
        gt::solve_pose_graph(in.odometry, in.fixes, in.p_lidar_antenna, gt::PoseGraphConfig{});
    benchmark::DoNotOptimize(r.covariance.data());
    state.counters["poses"] = double(r.T_enu_lidar.size());
    state.counters["priors"] = double(r.priors.size());
    state.counters["iterations"] = double(r.iterations);
  }
}
BENCHMARK(BM_PoseGraph)->Arg(600)->Arg(3600)->Unit(benchmark::kMillisecond)->Iterations(1);

// Fixes correlated over 5 s, their error a state at every scan, the correlation time and the
// white share by likelihood (the ground-truth step's default with --fix-correlation auto, its
// gate's solve given the 2 s a residual estimate gives).
void BM_PoseGraphFixStates(benchmark::State& state) {
  const Input& in = walk(g_smoke ? 120.0 : double(state.range(0)), 5.0);
  gt::PoseGraphConfig config;
  config.fix_correlation_s = 2.0;
  config.fix_correlation_by_likelihood = true;
  for (auto _ : state) {
    const gt::PoseGraphResult r =
        gt::solve_pose_graph(in.odometry, in.fixes, in.p_lidar_antenna, config);
    benchmark::DoNotOptimize(r.covariance.data());
    state.counters["poses"] = double(r.T_enu_lidar.size());
    state.counters["iterations"] = double(r.iterations);
    state.counters["tau_s"] = r.fix_correlation_s;
    state.counters["white"] = r.fix_white_fraction;
  }
}
BENCHMARK(BM_PoseGraphFixStates)->Arg(600)->Arg(3600)->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_BundleAdjustment(benchmark::State& state) {
  if (g_smoke && state.range(0) != 1) {  // one small run is enough to keep it from rotting
    for (auto _ : state) {
    }
    state.SetLabel("left out with --smoke");
    return;
  }
  const double minutes = g_smoke ? 0.1 : double(state.range(0));
  const rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  sim::SimConfig cfg;
  cfg.trajectory_duration_s = 60.0 * minutes;
  cfg.trajectory_motion = sim::MotionKind::walk;
  cfg.gnss.correlation_time_s = 5.0;
  const char* full = std::getenv("RIGCAL_PERF_FULL_OS0");
  if (!(full && std::string(full) == "1")) {
    cfg.lidar.beams = g_smoke ? 32 : 64;
    cfg.lidar.columns = g_smoke ? 512 : 1024;
  }
  const sim::TrajectoryPart part = sim::simulate_trajectories(rig, cfg);
  const rig::Sensor& gnss = rig::sensor(rig, part.gnss_name);
  const Eigen::Vector3d p_lidar_antenna = gnss.T_base_sensor.t;
  gt::PoseGraphConfig graph;
  graph.fix_correlation_s = 5.0;
  const std::vector<gt::PositionFix> fixes =
      gt::position_fixes(part.gnss, {}, {}, gnss.time_offset, graph);
  gt::OdometryInput odometry;
  odometry.T_odom_lidar = part.odometry;
  const double r = cfg.odometry.rot_sigma_deg * M_PI / 180.0, t = cfg.odometry.trans_sigma_m;
  odometry.step_covariance.assign(part.odometry.size() - 1, (Eigen::Matrix<double, 6, 1>() << r * r,
                                                             r * r, r * r, t * t, t * t, t * t)
                                                                .finished()
                                                                .asDiagonal());
  for (auto _ : state) {
    sim::SweepDrive drive = sim::trajectory_drive(rig, cfg, part);
    double sweep_seconds = 0;
    size_t made = 0;
    auto next_scan = [&]() -> std::optional<Scan> {
      if (made == part.truth_base.size()) return std::nullopt;
      const auto t0 = std::chrono::steady_clock::now();
      const sim::Sweep sweep = sim::next_sweep(drive);
      Scan scan = sim::scan_of(sweep.points, sweep.stamp);
      ++made;
      sweep_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      return scan;
    };
    const auto t0 = std::chrono::steady_clock::now();
    const gt::PoseGraphResult stage1 =
        gt::solve_pose_graph(odometry, fixes, p_lidar_antenna, graph);
    const gt::SequenceBaResult ba =
        gt::sequence_ba(next_scan, stage1.T_enu_lidar, odometry, gt::SequenceBaConfig{});
    const gt::PoseGraphResult final_graph =
        gt::solve_pose_graph(ba.motions, fixes, p_lidar_antenna, graph);
    benchmark::DoNotOptimize(final_graph.covariance.data());
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    state.counters["sweeps"] = double(made);
    state.counters["sweeps_s"] = sweep_seconds;
    state.counters["stage_s"] = wall - sweep_seconds;
    state.counters["s_per_sweep"] = (wall - sweep_seconds) / double(made);
    state.counters["windows"] = double(ba.windows.size());
    state.counters["keyframes"] = double(ba.keyframes.size());
  }
}
BENCHMARK(BM_BundleAdjustment)
    ->Arg(1)
    ->Arg(2)
    ->Arg(5)
    ->Arg(10)
    ->Unit(benchmark::kSecond)
    ->Iterations(1);

}  // namespace

int main(int argc, char** argv) {
  g_smoke = rigcal::perf::take_smoke_flag(argc, argv);
  return rigcal::perf::run_benchmarks(argc, argv);
}
