// Speed of the ground truth's pose graph (doc/performance.md): an hour of 10 Hz scan poses from
// the simulator's hand-held walk (odometry with its step covariance) and its 100 Hz RTK fixes,
// in memory: the priors at the scans, the robust solve, the gate, the second solve and every
// pose's marginal covariance. No peer: none of the anchors builds this graph (the paper's code
// is not public); Ceres is the solver underneath.
//   build/bin/rigcal_perf_ground_truth
//   build/bin/rigcal_perf_ground_truth --smoke      (2 minutes instead of an hour: make test)
#include <benchmark/benchmark.h>

#include <cmath>
#include <map>

#include "rigcal/gt/pose_graph.h"
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

const Input& walk(double seconds) {
  static std::map<double, Input> cache;
  auto it = cache.find(seconds);
  if (it != cache.end()) return it->second;
  const rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  sim::SimConfig cfg;
  cfg.trajectory_duration_s = seconds;
  cfg.gnss.outages = {{0.4 * seconds, 0.4 * seconds + 20.0}};
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
  return cache.emplace(seconds, std::move(in)).first->second;
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

}  // namespace

int main(int argc, char** argv) {
  g_smoke = rigcal::perf::take_smoke_flag(argc, argv);
  return rigcal::perf::run_benchmarks(argc, argv);
}
