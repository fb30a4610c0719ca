// The AprilGrid detector against the simulator's truth, one seed (the 20-seed version:
// AprilGridDetectLong in tests/long): under each imaging condition, the share of tags found by
// their size in the image, and no tag reported where another one is.
#include <gtest/gtest.h>

#include "aprilgrid_rates.h"

namespace rigcal::camera::testing {
namespace {

TEST(AprilGridDetect, TagsFoundByConditionAndSizeSeedOne) {
  DetectionCounts held;
  for (const Condition& condition : detection_conditions(3)) {
    const DetectionCounts c = detection_counts(condition, 1);
    expect_bars(condition.name, c, condition.held_to_bars, 20);
    if (condition.held_to_bars) held += c;
  }
  expect_bars("all conditions held to the bars", held, true, 100);
}

}  // namespace
}  // namespace rigcal::camera::testing
