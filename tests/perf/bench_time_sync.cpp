// Speed of the time-offset step (doc/performance.md): one hour of two 100 Hz gyro streams of a
// simulated hand-held motion, 20 ppm of drift, estimated end to end in memory (coarse FFT pass,
// fine pass, three-axis refinement, windows and drift, and the second pass that removes the
// drift; and the same without drift, one pass). The peer in the same run: the integer-lag
// correlation of |w| over +-1 s at 100 Hz that the VBR rig's 5 ms bound comes from (direct sums, as
// np.correlate computes them).
//   build/bin/rigcal_perf_time_sync
//   build/bin/rigcal_perf_time_sync --smoke     (2 minutes instead of an hour: make test runs this)
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstring>

#include "rigcal/rig/rig_yaml.h"
#include "rigcal/sim/imu.h"
#include "rigcal/sim/session.h"
#include "rigcal/time_sync/time_sync.h"
#include "smoke.h"

namespace {

using namespace rigcal;

bool g_smoke = false;

struct Streams {
  time_sync::AngularRates reference, other;
};

time_sync::AngularRates rates_of(const std::vector<sim::ImuSample>& samples) {
  time_sync::AngularRates r;
  for (const sim::ImuSample& s : samples) {
    r.stamps.push_back(s.stamp);
    r.rates.push_back(s.gyro);
  }
  return r;
}

Streams simulate_one_hour(double drift_ppm) {
  {
    rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
    rig::sensor(rig, "imu").time_offset = 0.0421;
    sim::SimConfig cfg;
    cfg.seed = 1;
    cfg.imu_duration_s = g_smoke ? 120.0 : 3600.0;
    cfg.imu.drift_ppm = drift_ppm;
    const sim::ImuPart part = sim::simulate_imu_part(rig, cfg);
    return Streams{rates_of(part.os_imu), rates_of(part.imu)};
  }
}

// With 20 ppm of drift (two passes: the second after removing the drift) and without.
const Streams& one_hour(bool drift = true) {
  static const Streams with_drift = simulate_one_hour(20.0), without = simulate_one_hour(0.0);
  return drift ? with_drift : without;
}

void BM_RigcalTimeOffsetOneHour(benchmark::State& state) {
  const Streams& s = one_hour();
  for (auto _ : state) {
    const time_sync::TimeSyncResult r = time_sync::estimate_time_offset(s.reference, s.other);
    benchmark::DoNotOptimize(r.offset_s);
    state.counters["offset_ms"] = 1e3 * r.offset_s;
    state.counters["drift_ppm"] = r.drift_ppm;
  }
}
BENCHMARK(BM_RigcalTimeOffsetOneHour)->Unit(benchmark::kMillisecond);

void BM_RigcalTimeOffsetOneHourNoDrift(benchmark::State& state) {
  const Streams& s = one_hour(false);
  for (auto _ : state) {
    const time_sync::TimeSyncResult r = time_sync::estimate_time_offset(s.reference, s.other);
    benchmark::DoNotOptimize(r.offset_s);
    state.counters["offset_ms"] = 1e3 * r.offset_s;
  }
}
BENCHMARK(BM_RigcalTimeOffsetOneHourNoDrift)->Unit(benchmark::kMillisecond);

// The integer-lag peer: both streams at their nominal 100 Hz sample index (no resampling),
// |w| mean-removed, the lag of the largest sum of products in +-100 samples.
void BM_PeerIntegerLagCorrelationOneHour(benchmark::State& state) {
  const Streams& s = one_hour();
  const size_t n = std::min(s.reference.rates.size(), s.other.rates.size());
  for (auto _ : state) {
    std::vector<double> a(n), b(n);
    double ma = 0, mb = 0;
    for (size_t i = 0; i < n; ++i) {
      a[i] = s.reference.rates[i].norm(), b[i] = s.other.rates[i].norm();
      ma += a[i] / n, mb += b[i] / n;
    }
    for (size_t i = 0; i < n; ++i) a[i] -= ma, b[i] -= mb;
    long best_lag = 0;
    double best = -INFINITY;
    for (long lag = -100; lag <= 100; ++lag) {
      double sum = 0;
      for (size_t i = 0; i < n; ++i) {
        const long j = static_cast<long>(i) + lag;
        if (j >= 0 && j < static_cast<long>(n)) sum += a[i] * b[j];
      }
      if (sum > best) best = sum, best_lag = lag;
    }
    benchmark::DoNotOptimize(best_lag);
    state.counters["lag_samples"] = static_cast<double>(best_lag);
  }
}
BENCHMARK(BM_PeerIntegerLagCorrelationOneHour)->Unit(benchmark::kMillisecond);

}  // namespace

// --smoke (first argument): a short stream instead, for make test's run of each benchmark.
int main(int argc, char** argv) {
  g_smoke = rigcal::perf::take_smoke_flag(argc, argv);
  return rigcal::perf::run_benchmarks(argc, argv);
}
