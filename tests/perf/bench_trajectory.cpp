// Speed of the trajectory benchmark on 1,000,000 timestamped poses (doc/performance.md):
// association + SE(3) alignment + ATE + KITTI RPE, in memory; and file parsing.
//   build/bin/rigcal_perf_trajectory                       (Google Benchmark)
//   build/bin/rigcal_perf_trajectory --write DIR [N] [--hz H] [--epoch S]
//       writes DIR/gt.txt, DIR/est.txt (TUM) and DIR/gt_kitti.txt, DIR/est_kitti.txt (the same
//       poses as KITTI rows): N poses (1,000,000) at H Hz (10), at 10 m/s, stamps from S s (0)
//   build/bin/rigcal_perf_trajectory --smoke               (10,000 poses: make test runs this)
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <cstring>

#include "../unit/synthetic_drive.h"
#include "rigcal/bench/evaluate.h"
#include "rigcal/io/files.h"
#include "rigcal/io/trajectory_io.h"
#include "smoke.h"

namespace {

using namespace rigcal;

// --smoke: every size divided by this (make test runs each benchmark once, small).
size_t g_size_divisor = 1;

std::pair<Trajectory, Trajectory> make_pair(size_t n, double hz = 10, int64_t epoch_s = 0) {
  return testing::synthetic_drive(n, hz, epoch_s);
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
    const std::string dir = argv[2];
    size_t n = 1'000'000;
    double hz = 10;
    int64_t epoch_s = 0;
    for (int i = 3; i < argc; ++i) {
      if (std::strcmp(argv[i], "--hz") == 0 && i + 1 < argc) {
        hz = std::stod(argv[++i]);
      } else if (std::strcmp(argv[i], "--epoch") == 0 && i + 1 < argc) {
        epoch_s = std::stoll(argv[++i]);
      } else {
        n = std::stoul(argv[i]);
      }
    }
    const auto [gt, est] = make_pair(n, hz, epoch_s);
    auto kitti = [](const Trajectory& t) {
      std::string out;
      out.reserve(t.size() * 200);
      for (const SE3& T : t.T_world_body) {
        const Eigen::Matrix4d m = T.matrix();
        out += fmt::format(
            "{:.9e} {:.9e} {:.9e} {:.9e} {:.9e} {:.9e} {:.9e} {:.9e} {:.9e} {:.9e} "
            "{:.9e} {:.9e}\n",
            m(0, 0), m(0, 1), m(0, 2), m(0, 3), m(1, 0), m(1, 1), m(1, 2), m(1, 3), m(2, 0),
            m(2, 1), m(2, 2), m(2, 3));
      }
      return out;
    };
    rigcal::io::write_files_atomic({{dir + "/gt.txt", rigcal::io::trajectory_to_tum(gt)},
                                    {dir + "/est.txt", rigcal::io::trajectory_to_tum(est)},
                                    {dir + "/gt_kitti.txt", kitti(gt)},
                                    {dir + "/est_kitti.txt", kitti(est)}});
    fmt::print("wrote {}/{{gt,est}}.txt (TUM) and {{gt,est}}_kitti.txt, {} poses each at {:g} Hz\n",
               dir, n, hz);
    return 0;
  }
  if (rigcal::perf::take_smoke_flag(argc, argv)) g_size_divisor = 100;
  return rigcal::perf::run_benchmarks(argc, argv);
}
