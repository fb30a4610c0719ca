// Long statistical check (CTest label "long", run by `make test-long`) of the board warp over ten
// seeds: a board bent by (4, -2) mm is recovered within 3 sigma and the intrinsics with the warp
// solved are as honest as on a flat board (within 3 sigma in at least 95 % of seed-parameter
// pairs), while the flat model's focal lengths carry the bias (most beyond 3 sigma); a flat
// board's warp comes out at zero within 3 sigma in at least 95 % of seed-axis pairs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "camera_warp.h"

TEST(CameraSimLong, BoardWarpOverTenSeeds) {
  for (const Eigen::Vector2d& truth : {Eigen::Vector2d(0.004, -0.002), Eigen::Vector2d(0, 0)}) {
    int warp_within = 0, warp_total = 0, k_within = 0, k_total = 0, biased = 0;
    double flat_focal_bias = 0, warp_focal_bias = 0;
    for (uint64_t seed = 1; seed <= 10; ++seed) {
      const rigcal::camera::WarpRun w = rigcal::camera::warp_run(truth, seed);
      for (int a = 0; a < 2; ++a) {
        warp_within += std::abs(w.warp_m[a] - truth[a]) <= 3 * w.warp_sigma_m[a];
        ++warp_total;
      }
      for (size_t i = 0; i < w.warp_error.size(); ++i) {
        k_within += std::abs(w.warp_error[i]) <= 3 * w.warp_sigma[i];
        ++k_total;
      }
      for (size_t i : {0, 1, 4, 5}) {
        biased += std::abs(w.flat_error[i]) > 3 * w.flat_sigma[i];
        flat_focal_bias += w.flat_error[i] / 40;
        warp_focal_bias += w.warp_error[i] / 40;
      }
    }
    std::printf(
        "board warp (%.0f, %.0f) mm, 10 seeds: warp within 3 sigma of the truth in %d of %d; "
        "intrinsics (warp solved) within 3 sigma in %d of %d; focal lengths beyond 3 sigma with "
        "the board taken as flat: %d of 40; mean focal error %+.3f px flat, %+.3f px warp "
        "solved\n",
        1e3 * truth.x(), 1e3 * truth.y(), warp_within, warp_total, k_within, k_total, biased,
        flat_focal_bias, warp_focal_bias);
    EXPECT_GE(warp_within, 19);
    EXPECT_GE(k_within, 76);
    // The flat model's bias depends on the views: 32 of the 40 focal lengths beyond 3 sigma
    // over seeds 1-10, their mean error +9.9 px against -0.04 px with the warp solved (a flat
    // board: 0 of 40, -0.01 px).
    if (truth.isZero()) {
      EXPECT_LE(biased, 2);
    } else {
      EXPECT_GE(biased, 28);
    }
  }
}
