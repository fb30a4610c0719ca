// Speed and accuracy of the LiDAR odometry (doc/performance.md, doc/odometry.md) on the
// simulator's street drive (OS0-128 at 10 Hz, about 200,000 points a sweep, a car at 5 m/s), in
// memory. The peer in the same run: Open3D 0.16's point-to-plane ICP (Debian's libopen3d-dev),
// each sweep registered to the previous one (Open3D has no map and no deskew), on the same
// voxel sampling, normals from the 8 nearest points, the same constant-velocity guess.
// Counters: scans a second, and the mean and max per-step translation error against the truth (mm).
//   build/bin/rigcal_perf_odometry
//   build/bin/rigcal_perf_odometry --smoke      (5 sweeps instead of 30: make test runs this)
#include <benchmark/benchmark.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>

#include "rigcal/lidar/odometry.h"
#include "rigcal/lidar/preprocess.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/sim/session.h"
#include "smoke.h"

namespace {

using namespace rigcal;

bool g_smoke = false;

struct Drive {
  std::vector<Scan> scans;
  std::vector<SE3> T_world_lidar;
};

const Drive& drive() {
  static const Drive d = [] {
    const rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
    sim::SimConfig cfg;
    cfg.scans = g_smoke ? 5 : 30;
    const sim::ScanPart part = sim::simulate_scans(rig, cfg);
    Drive out;
    for (size_t k = 0; k < part.scans.size(); ++k) {
      Scan s;
      s.stamp = part.stamps[k];
      for (const sim::LidarPoint& p : part.scans[k]) s.points.push_back({.p = p.p, .t_ns = p.t_ns});
      out.scans.push_back(std::move(s));
    }
    out.T_world_lidar = part.T_world_lidar;
    return out;
  }();
  return d;
}

void error_counters(benchmark::State& state, const std::vector<SE3>& T_odom_lidar) {
  const Drive& d = drive();
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
  const Drive& d = drive();
  std::vector<SE3> poses;
  for (auto _ : state) {
    lidar::Odometry o = lidar::start_odometry(lidar::os0_128_handheld());
    for (const Scan& s : d.scans) lidar::register_scan(o, s);
    poses = o.T_odom_lidar.T_world_body;
  }
  error_counters(state, poses);
}

void BM_Open3dPointToPlaneScanToScan(benchmark::State& state) {
  namespace reg = open3d::pipelines::registration;
  const Drive& d = drive();
  const lidar::OdometryConfig c = lidar::os0_128_handheld();
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

BENCHMARK(BM_RigcalOdometry)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Open3dPointToPlaneScanToScan)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  g_smoke = rigcal::perf::take_smoke_flag(argc, argv);
  return rigcal::perf::run_benchmarks(argc, argv);
}
