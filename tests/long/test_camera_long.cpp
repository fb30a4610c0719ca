// Long statistical check (CTest label "long", run by `make test-long`): over 20 seeds and both
// lens models, the errors against simulator truth fall within 3 reported sigma at least 95 % of
// the time (fx, fy, cx, cy of both cameras and the stereo rotation's three axes).
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "rigcal/rig/rig.h"

namespace rigcal::camera {
std::vector<double> check_against_truth_for_long_test(rig::DistortionModel model, uint64_t seed);
}

TEST(CameraSimLong, ReportedSigmasAreHonestOver20Seeds) {
  for (const auto model :
       {rigcal::rig::DistortionModel::radtan, rigcal::rig::DistortionModel::equidistant}) {
    size_t within = 0, total = 0;
    for (uint64_t seed = 1; seed <= 20; ++seed) {
      for (double z : rigcal::camera::check_against_truth_for_long_test(model, seed)) {
        within += z <= 3.0;
        ++total;
      }
    }
    std::printf("%s: %zu of %zu errors within 3 sigma (%.1f %%)\n",
                model == rigcal::rig::DistortionModel::radtan ? "radtan" : "equidistant", within,
                total, 100.0 * within / total);
    EXPECT_GE(within, total * 95 / 100);
  }
}
