// Long statistical check (CTest label "long", run by `make test-long`): over 20 seeds and both
// lens models, the errors against simulator truth fall within 3 reported sigma at least 95 % of
// the time (fx, fy, cx, cy of both cameras and the stereo rotation's three axes), and so do the
// projection errors against the mrcal-style projection uncertainty (5 pixels a camera).
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "camera_truth.h"

TEST(CameraSimLong, ReportedSigmasAreHonestOver20Seeds) {
  for (const auto model :
       {rigcal::rig::DistortionModel::radtan, rigcal::rig::DistortionModel::equidistant}) {
    size_t within = 0, total = 0, p_within = 0, p_total = 0;
    std::vector<double> pz;
    for (uint64_t seed = 1; seed <= 20; ++seed) {
      const rigcal::camera::TruthZ t =
          rigcal::camera::check_against_truth_for_long_test(model, seed);
      for (double z : t.parameters) {
        within += z <= 3.0;
        ++total;
      }
      for (double z : t.projection) {
        p_within += z <= 3.0;
        ++p_total;
        pz.push_back(z);
      }
    }
    std::nth_element(pz.begin(), pz.begin() + pz.size() / 2, pz.end());
    const char* name = model == rigcal::rig::DistortionModel::radtan ? "radtan" : "equidistant";
    std::printf("%s: %zu of %zu parameter errors within 3 sigma (%.1f %%)\n", name, within, total,
                100.0 * within / total);
    std::printf(
        "%s: %zu of %zu projection errors within 3 mrcal-style sigma (%.1f %%); median |e| / "
        "sigma %.2f\n",
        name, p_within, p_total, 100.0 * p_within / p_total, pz[pz.size() / 2]);
    EXPECT_GE(within, total * 95 / 100);
    EXPECT_GE(p_within, p_total * 95 / 100);
    // Not grossly pessimistic either: a 2-D Gaussian error has a median |e| of 0.67 to 1.18 of its
    // worst-direction sigma (elongated to round).
    EXPECT_GT(pz[pz.size() / 2], 0.4);
  }
}
