// Issue 6, acceptance 1 in full: 100 trials of 2 minutes at 100 Hz, true offsets in +-200 ms:
// maximum error <= 0.5 ms, RMS <= 0.2 ms; the sigmas and the drift test honest over the trials.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "rigcal/time_sync/time_sync.h"

namespace rigcal::time_sync {

TimeSyncResult offset_trial_for_long_test(uint64_t seed, double true_offset_s);

namespace {

TEST(TimeSyncSimLong, HundredTrialsWithinHalfAMillisecond) {
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> U(-0.2, 0.2);
  const int trials = 100;
  double max_err = 0, sse = 0;
  int false_drift = 0, beyond_3_sigma = 0;
  for (int k = 0; k < trials; ++k) {
    const double truth = U(rng);
    const TimeSyncResult r = offset_trial_for_long_test(50000 + k, truth);
    ASSERT_EQ(r.verdict, "ok") << r.reason;
    const double e = r.offset_s - truth;
    max_err = std::max(max_err, std::abs(e));
    sse += e * e;
    false_drift += r.drift_significant;
    beyond_3_sigma += std::abs(e) > 3 * r.sigma_s;
  }
  const double rms = std::sqrt(sse / trials);
  std::printf(
      "%d trials: max error %.4f ms, RMS %.4f ms; %d errors beyond 3 sigma; drift flagged "
      "(truth 0) in %d\n",
      trials, 1e3 * max_err, 1e3 * rms, beyond_3_sigma, false_drift);
  EXPECT_LE(max_err, 0.5e-3);
  EXPECT_LE(rms, 0.2e-3);
  EXPECT_LE(beyond_3_sigma, 5);
  EXPECT_LE(false_drift, 3);
}

}  // namespace
}  // namespace rigcal::time_sync
