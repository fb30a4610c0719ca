// Speed of the hand-eye step (doc/performance.md): 30 minutes of 10 Hz LiDAR odometry and 100 Hz
// GNSS/INS poses (the simulator, hand-held, sample rig), in memory: motion pairs, closed form,
// refinement with covariance. The peer in the same run: OpenCV's calibrateHandEye (Park) on the
// first 300 of the same stations (it forms a motion from every two stations: 44,850 here; on all
// 1800 it would be 1.6 million).
//   build/bin/rigcal_perf_hand_eye
//   build/bin/rigcal_perf_hand_eye --smoke      (2 minutes instead of 30: make test runs this)
#include <benchmark/benchmark.h>

#include <Eigen/Core>
#include <cstring>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "rigcal/hand_eye/hand_eye.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/sim/session.h"
#include "smoke.h"

namespace {

using namespace rigcal;

bool g_smoke = false;

struct Input {
  Trajectory lidar, gnss;
  double offset_s = 0;
};

const Input& thirty_minutes() {
  static const Input in = [] {
    const rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
    sim::SimConfig cfg;
    cfg.trajectory_duration_s = g_smoke ? 120.0 : 1800.0;
    const sim::TrajectoryPart part = sim::simulate_trajectories(rig, cfg);
    return Input{part.odometry, part.gnss, rig::sensor(rig, part.gnss_name).time_offset};
  }();
  return in;
}

void BM_RigcalHandEyeThirtyMinutes(benchmark::State& state) {
  const Input& in = thirty_minutes();
  for (auto _ : state) {
    hand_eye::PairOptions po;
    po.time_offset_s = in.offset_s;
    const auto pairs = hand_eye::motion_pairs(in.lidar, in.gnss, po);
    const hand_eye::ClosedForm cf = hand_eye::closed_form(pairs);
    const hand_eye::Refined r = hand_eye::refine(pairs, cf.T_gnss_lidar);
    benchmark::DoNotOptimize(r.T_gnss_lidar.t);
    state.counters["pairs"] = static_cast<double>(pairs.size());
  }
}
BENCHMARK(BM_RigcalHandEyeThirtyMinutes)->Unit(benchmark::kMillisecond);

void BM_OpenCvParkThreeHundredStations(benchmark::State& state) {
  const Input& in = thirty_minutes();
  hand_eye::PairOptions po;
  po.time_offset_s = in.offset_s;
  po.stride_s = 0;  // end to end: they chain into stations
  po.spacings_s = {1.0};
  const auto pairs = hand_eye::motion_pairs(in.lidar, in.gnss, po);
  std::vector<cv::Mat> Rg, tg, Rc, tc;
  SE3 G, L;
  for (size_t k = 0; k <= 300 && k <= pairs.size(); ++k) {
    cv::Mat a, b, c, d;
    const SE3 Li = L.inverse();
    cv::eigen2cv(G.R, a), cv::eigen2cv(G.t, b), cv::eigen2cv(Li.R, c), cv::eigen2cv(Li.t, d);
    Rg.push_back(a), tg.push_back(b), Rc.push_back(c), tc.push_back(d);
    if (k < pairs.size()) G = G * pairs[k].B, L = L * pairs[k].A;
  }
  for (auto _ : state) {
    cv::Mat R, t;
    cv::calibrateHandEye(Rg, tg, Rc, tc, R, t, cv::CALIB_HAND_EYE_PARK);
    benchmark::DoNotOptimize(R.data);
  }
}
BENCHMARK(BM_OpenCvParkThreeHundredStations)->Unit(benchmark::kMillisecond);

}  // namespace

// --smoke (first argument): a short stream instead, for make test's run of each benchmark.
int main(int argc, char** argv) {
  g_smoke = rigcal::perf::take_smoke_flag(argc, argv);
  return rigcal::perf::run_benchmarks(argc, argv);
}
