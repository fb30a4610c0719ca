// Speed of the trajectory benchmark on 1,000,000 timestamped poses (doc/performance.md):
// association + SE(3) alignment + ATE + KITTI RPE, in memory; and file parsing.
//   build/bin/rigcal_perf_trajectory                       (Google Benchmark)
//   build/bin/rigcal_perf_trajectory --write DIR [N]       (writes DIR/gt.txt, DIR/est.txt)
//   build/bin/rigcal_perf_trajectory --smoke               (10,000 poses: make test runs this)
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <cstring>
#include <random>

#include "rigcal/bench/evaluate.h"
#include "rigcal/io/files.h"
#include "rigcal/io/trajectory_io.h"
#include "smoke.h"

namespace {

using namespace rigcal;

// --smoke: every size divided by this (make test runs each benchmark once, small).
size_t g_size_divisor = 1;

// A 10 Hz drive (~1 m a frame), GT and an estimate with drift on stamps 1 ms later.
std::pair<Trajectory, Trajectory> make_pair(size_t n) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, 0.02);
  Trajectory gt, est;
  gt.stamps.reserve(n), gt.T_world_body.reserve(n), est.stamps.reserve(n),
      est.T_world_body.reserve(n);
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  double yaw = 0.0;
  for (size_t i = 0; i < n; ++i) {
    yaw += 0.02 * std::sin(1e-3 * static_cast<double>(i));
    p += Eigen::Vector3d(std::cos(yaw), std::sin(yaw),
                         0.01 * std::sin(1e-2 * static_cast<double>(i)));
    const SE3 T = SE3::from_rotation_vector(Eigen::Vector3d(0, 0, yaw), p);
    gt.stamps.push_back(Time::from_ns(static_cast<int64_t>(i) * 100'000'000));
    gt.T_world_body.push_back(T);
    est.stamps.push_back(Time::from_ns(static_cast<int64_t>(i) * 100'000'000 + 1'000'000));
    est.T_world_body.push_back(
        SE3::from_rotation_vector(Eigen::Vector3d(0, 0, yaw * 1.001),
                                  p * 1.002 + Eigen::Vector3d(noise(rng), noise(rng), noise(rng))));
  }
  return {gt, est};
}

void BM_AssociateAlignAteKittiRpe(benchmark::State& state) {
  const size_t n = static_cast<size_t>(state.range(0)) / g_size_divisor;
  const auto [gt, est] = make_pair(n);
  for (auto _ : state) {
    const bench::Matches m = bench::associate_evo(gt, est, Time::from_ns(10'000'000));
    std::vector<SE3> g, e;
    g.reserve(m.gt.size()), e.reserve(m.gt.size());
    for (size_t k = 0; k < m.gt.size(); ++k) {
      g.push_back(gt.T_world_body[m.gt[k]]);
      e.push_back(est.T_world_body[m.est[k]]);
    }
    const bench::AlignmentResult a = bench::align(g, e, bench::Alignment::se3);
    for (SE3& T : e) T = bench::apply(a, T);
    const bench::Stats ate = bench::statistics(bench::absolute_errors(g, e).trans);
    const bench::Drift rpe = bench::pooled_drift(bench::length_segments(
        g, e, {std::begin(bench::kKittiLengths), std::end(bench::kKittiLengths)}, 10));
    benchmark::DoNotOptimize(ate.rmse + rpe.trans_pct);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n));
}
BENCHMARK(BM_AssociateAlignAteKittiRpe)->Arg(1'000'000)->Unit(benchmark::kMillisecond);

void BM_ParseTum(benchmark::State& state) {
  const auto [gt, est] = make_pair(static_cast<size_t>(state.range(0)) / g_size_divisor);
  const std::string text = io::trajectory_to_tum(gt);
  for (auto _ : state) {
    benchmark::DoNotOptimize(io::parse_trajectory(text, "gt.txt").trajectory.size());
  }
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(text.size()));
}
BENCHMARK(BM_ParseTum)->Arg(1'000'000)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 3 && std::strcmp(argv[1], "--write") == 0) {
    const size_t n = argc >= 4 ? std::stoul(argv[3]) : 1'000'000;
    const auto [gt, est] = make_pair(n);
    rigcal::io::write_files_atomic(
        {{std::string(argv[2]) + "/gt.txt", rigcal::io::trajectory_to_tum(gt)},
         {std::string(argv[2]) + "/est.txt", rigcal::io::trajectory_to_tum(est)}});
    fmt::print("wrote {}/gt.txt and {}/est.txt, {} poses each\n", argv[2], argv[2], n);
    return 0;
  }
  if (rigcal::perf::take_smoke_flag(argc, argv)) g_size_divisor = 100;
  return rigcal::perf::run_benchmarks(argc, argv);
}
