// The AprilGrid detector over 20 seeds (the short version: AprilGridDetect in tests/unit): per
// imaging condition and tag size, the share of tags found, and no tag reported where another is.
#include <gtest/gtest.h>

#include "aprilgrid_rates.h"

namespace rigcal::camera::testing {
namespace {

TEST(AprilGridDetectLong, TagsFoundByConditionAndSizeOverTwentySeeds) {
  DetectionCounts held;
  for (const Condition& condition : detection_conditions(6)) {
    DetectionCounts c;
    for (uint64_t seed = 1; seed <= 20; ++seed) c += detection_counts(condition, seed);
    expect_bars(condition.name, c, condition.held_to_bars, 1000);
    if (condition.held_to_bars) held += c;
  }
  expect_bars("all conditions held to the bars", held, true, 6000);
}

}  // namespace
}  // namespace rigcal::camera::testing
