// Speed and accuracy of the LiDAR odometry (doc/performance.md, doc/odometry.md) on the
// simulator's street drive (a car at 5 m/s), in memory, for the two sensors of the VBR rig: an
// OS0-128 at 10 Hz (about 200,000 points a sweep, the os0-128 preset) and an OS1-64 at 20 Hz
// (about 50,000, the os1-64 preset). The peer in the same run: Open3D 0.16's point-to-plane ICP
// (Debian's libopen3d-dev), each sweep registered to the previous one (Open3D has no map and no
// deskew), on the same voxel sampling, normals from the 8 nearest points, the same
// constant-velocity guess.
// Counters: scans a second, and the mean and max per-step translation error against the truth (mm).
//   build/bin/rigcal_perf_odometry
//   build/bin/rigcal_perf_odometry --smoke      (5 sweeps instead of 30: make test runs this)
//   build/bin/rigcal_perf_odometry --long-drive [SCANS]   (only the long drive below)
// The long drive: OS1-64 sweeps made one at a time and registered as they come (never stored),
// 1200 by default (a minute at 20 Hz, 300 m); the map's size and the process's resident memory
// at the end of each quarter, and the end point's error over the path's length.
#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>

#include <fstream>
#include <map>

#include "rigcal/lidar/odometry.h"
#include "rigcal/lidar/preprocess.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/sim/session.h"
#include "smoke.h"

namespace {

using namespace rigcal;

bool g_smoke = false;
int g_long_drive_scans = 0;

struct Drive {
  std::vector<Scan> scans;
  std::vector<SE3> T_world_lidar;
};

Scan scan_of(const sim::Sweep& sweep) { return sim::scan_of(sweep.points, sweep.stamp); }

// 0: OS0-128 at 10 Hz; 1: OS1-64 at 20 Hz.
sim::SimConfig drive_config(int sensor, int scans) {
  sim::SimConfig cfg;
  cfg.scans = scans;
  cfg.lidar = sensor == 0 ? sim::os0_128() : sim::os1_64();
  return cfg;
}
lidar::OdometryConfig preset(int sensor) {
  return sensor == 0 ? lidar::os0_128_handheld() : lidar::os1_64_car();
}

const rig::Rig& sample_rig() {
  static const rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  return rig;
}

const Drive& drive(int sensor) {
  static std::map<int, Drive> drives;
  if (!drives.count(sensor)) {
    sim::SweepDrive street =
        sim::street_drive(sample_rig(), drive_config(sensor, g_smoke ? 5 : 30));
    Drive& d = drives[sensor];
    for (int k = 0; k < (g_smoke ? 5 : 30); ++k) {
      const sim::Sweep sweep = sim::next_sweep(street);
      d.scans.push_back(scan_of(sweep));
      d.T_world_lidar.push_back(sweep.T_world_lidar);
    }
  }
  return drives.at(sensor);
}

void error_counters(benchmark::State& state, const std::vector<SE3>& T_odom_lidar) {
  const Drive& d = drive(state.range(0));
  double sum = 0, max = 0;
  for (size_t k = 1; k < T_odom_lidar.size(); ++k) {
    const SE3 est = T_odom_lidar[k - 1].inverse() * T_odom_lidar[k];
    const SE3 tru = d.T_world_lidar[k - 1].inverse() * d.T_world_lidar[k];
    const double e = (tru.inverse() * est).t.norm();
    sum += e, max = std::max(max, e);
  }
  state.counters["step_error_mean_mm"] = 1e3 * sum / double(T_odom_lidar.size() - 1);
  state.counters["step_error_max_mm"] = 1e3 * max;
  state.counters["scans_a_second"] =
      benchmark::Counter(double(d.scans.size()), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_RigcalOdometry(benchmark::State& state) {
  const Drive& d = drive(state.range(0));
  std::vector<SE3> poses;
  for (auto _ : state) {
    lidar::Odometry o = lidar::start_odometry(preset(state.range(0)));
    for (const Scan& s : d.scans) lidar::register_scan(o, s);
    poses = o.T_odom_lidar.T_world_body;
  }
  error_counters(state, poses);
}

void BM_Open3dPointToPlaneScanToScan(benchmark::State& state) {
  namespace reg = open3d::pipelines::registration;
  const Drive& d = drive(state.range(0));
  const lidar::OdometryConfig c = preset(state.range(0));
  std::vector<SE3> poses;
  for (auto _ : state) {
    poses.assign(1, SE3::identity());
    std::shared_ptr<open3d::geometry::PointCloud> target;
    SE3 T_prev_cur;  // constant velocity
    for (const Scan& s : d.scans) {
      open3d::geometry::PointCloud cloud;
      cloud.points_ = lidar::deskewed_points(s, SE3::identity(), 0, c.min_range_m, c.max_range_m);
      auto frame = cloud.VoxelDownSample(0.5 * c.voxel_size_m);
      if (target) {
        auto source = frame->VoxelDownSample(1.5 * c.voxel_size_m);
        const reg::RegistrationResult r = reg::RegistrationICP(
            *source, *target, 1.0, T_prev_cur.matrix(), reg::TransformationEstimationPointToPlane(),
            reg::ICPConvergenceCriteria(1e-6, 1e-6, 50));
        T_prev_cur = SE3::from_matrix(r.transformation_);
        poses.push_back(poses.back() * T_prev_cur);
      }
      frame->EstimateNormals(open3d::geometry::KDTreeSearchParamKNN(8));
      target = frame;
    }
  }
  error_counters(state, poses);
}

// Resident memory of the process now (VmRSS), MB.
double resident_mb() {
  std::ifstream status("/proc/self/status");
  std::string key;
  double kb = 0;
  while (status >> key) {
    if (key == "VmRSS:") {
      status >> kb;
      break;
    }
  }
  return kb / 1024.0;
}

void BM_RigcalOdometryLongDrive(benchmark::State& state) {
  const int scans = g_long_drive_scans;
  for (auto _ : state) {
    sim::SweepDrive street = sim::street_drive(sample_rig(), drive_config(1, scans));
    lidar::Odometry o = lidar::start_odometry(lidar::os1_64_car());
    std::vector<SE3> T_world_lidar;
    for (int k = 0; k < scans; ++k) {
      const sim::Sweep sweep = sim::next_sweep(street);
      T_world_lidar.push_back(sweep.T_world_lidar);
      lidar::register_scan(o, scan_of(sweep));
      if ((k + 1) % (scans / 4) == 0) {
        const int q = (k + 1) / (scans / 4);
        state.counters[fmt::format("map_points_q{}", q)] = double(lidar::point_count(o.map));
        state.counters[fmt::format("resident_mb_q{}", q)] = resident_mb();
        std::fprintf(stderr, "long drive: %d of %d sweeps, map %zu points, %.0f MB resident\n",
                     k + 1, scans, lidar::point_count(o.map), resident_mb());
      }
    }
    const std::vector<SE3>& est = o.T_odom_lidar.T_world_body;
    const SE3 end_est = est.front().inverse() * est.back();
    const SE3 end_tru = T_world_lidar.front().inverse() * T_world_lidar.back();
    double length = 0;
    for (size_t k = 1; k < T_world_lidar.size(); ++k)
      length += (T_world_lidar[k].t - T_world_lidar[k - 1].t).norm();
    state.counters["path_m"] = length;
    state.counters["end_error_percent"] = 100 * (end_tru.inverse() * end_est).t.norm() / length;
  }
}

BENCHMARK(BM_RigcalOdometry)
    ->ArgName("os1_64")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_Open3dPointToPlaneScanToScan)
    ->ArgName("os1_64")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  g_smoke = rigcal::perf::take_smoke_flag(argc, argv);
  if (argc >= 2 && std::string(argv[1]) == "--long-drive") {
    g_long_drive_scans = argc >= 3 ? std::max(8, std::atoi(argv[2])) : 1200;
    benchmark::RegisterBenchmark("BM_RigcalOdometryLongDrive", BM_RigcalOdometryLongDrive)
        ->Iterations(1)
        ->Unit(benchmark::kSecond)
        ->UseRealTime();
    char filter[] = "--benchmark_filter=LongDrive";
    char* args[] = {argv[0], filter};
    int count = 2;
    benchmark::Initialize(&count, args);
    benchmark::RunSpecifiedBenchmarks();
    return 0;
  }
  return rigcal::perf::run_benchmarks(argc, argv);
}
