#pragma once
// Shared by tests/unit/test_aprilgrid.cpp and tests/long/test_aprilgrid_long.cpp: how many of a
// simulated AprilGrid's tags rigcal's detector finds, by imaging condition and by tag size,
// counted against the truth.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "rigcal/sim/stereo.h"

namespace rigcal::camera::testing {

// Tag sides (the shortest of the four sides of the true corners: a tilted tag's bits are as
// small as its shortest side makes them), px: [lower bound, next bound).
inline constexpr std::array<double, 7> kSideBins = {0, 15, 20, 25, 30, 40, 60};

struct DetectionCounts {
  // Per side bin (the last open-ended): tags whose four true corners are inside the image, and
  // of those, the ones detected where they are (the reported corners' mean within a quarter of
  // the tag's side of the true one).
  std::array<int, kSideBins.size()> eligible{}, found{};
  // Tags reported elsewhere than where the tag of that id is: a wrong id or a wrong place.
  int wrong = 0;
  // Of the corners of the tags found, how many, and how many more than 1 px from their truth (a
  // refinement gone to a neighbouring saddle: the solver's outlier rejection sees them).
  int corners = 0, corners_off = 0;
  int images = 0;
  // Found / eligible over the tags whose side is at least side_px.
  double rate_from(double side_px) const;
  int eligible_from(double side_px) const;
  DetectionCounts& operator+=(const DetectionCounts& o);
};

struct Condition {
  std::string name;
  sim::ImageConfig image;
  sim::BoardPoseConfig poses;
  double shift_off_image = 0;  // partial boards: the board moved sideways by this part of its width
  bool held_to_bars = true;    // false: measured and printed, asserted only to give no wrong tag
};

// The default images, blur, tilts up to 60 deg, uneven light, heavy noise, partial boards; and
// a defocus no decoder reads small tags through (not held to the bars).
std::vector<Condition> detection_conditions(int views);

// The 6 x 6 AprilGrid of targets/ (88 mm tags) seen by the sample rig's left camera.
DetectionCounts detection_counts(const Condition& condition, uint64_t seed);

std::string describe(const std::string& name, const DetectionCounts& c);

// Printed, then asserted: no wrong tag; when held to the bars, at least 98 % of the tags whose
// four corners are in the image and whose shortest side is 30 px or more, 90 % from 25 px (at
// least `min_eligible` tags of 25 px or more, or the measurement says nothing).
void expect_bars(const std::string& name, const DetectionCounts& c, bool held_to_bars,
                 int min_eligible);

}  // namespace rigcal::camera::testing
