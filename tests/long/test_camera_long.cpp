// Long statistical check (CTest label "long", run by `make test-long`): over 20 seeds and both
// lens models, the errors against simulator truth fall within 3 reported sigma at least 95 % of
// the time (fx, fy, cx, cy of both cameras and the stereo rotation's three axes), and so do the
// projection errors against the mrcal-style projection uncertainty (5 pixels a camera).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "camera_truth.h"
#include "rigcal/core/stats.h"

TEST(CameraSimLong, ReportedSigmasAreHonestOver20Seeds) {
  for (const auto model :
       {rigcal::rig::DistortionModel::radtan, rigcal::rig::DistortionModel::equidistant}) {
    size_t within = 0, total = 0, p_within = 0, p_total = 0;
    std::vector<double> pz;
    // The principal-point and rotation bars: met per seed, and how often an estimator
    // whose errors have exactly the reported covariance (the Cramer-Rao bound of independent
    // corner noise; the coverage below checks that the errors follow it) would meet them, the
    // parameters taken as independent.
    int pp_met = 0, rot_met = 0;
    double pp_bound = 0, rot_bound = 0;
    std::mt19937_64 rng(1);
    std::normal_distribution<double> N(0.0, 1.0);
    for (uint64_t seed = 1; seed <= 20; ++seed) {
      const rigcal::camera::TruthZ t =
          rigcal::camera::check_against_truth_for_long_test(model, seed);
      pp_met += t.principal_point_px <= 0.3;
      rot_met += t.rotation_deg <= 0.01;
      double p = 1;
      for (double s : t.principal_point_sigma_px) p *= std::erf(0.3 / s / std::sqrt(2.0));
      pp_bound += p;
      int in = 0;
      for (int i = 0; i < 20000; ++i)
        in += t.rotation_sigma_deg.cwiseProduct(Eigen::Vector3d(N(rng), N(rng), N(rng))).norm() <=
              0.01;
      rot_bound += in / 20000.0;
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
    const double pz_median = rigcal::median(pz);
    const char* name = model == rigcal::rig::DistortionModel::radtan ? "radtan" : "equidistant";
    std::printf("%s: %zu of %zu parameter errors within 3 sigma (%.1f %%)\n", name, within, total,
                100.0 * within / total);
    std::printf(
        "%s: principal point <= 0.3 px (cx and cy of both cameras) in %d of 20 seeds, %.1f "
        "expected at the reported covariance; stereo rotation <= 0.01 deg in %d of 20, %.1f "
        "expected\n",
        name, pp_met, pp_bound, rot_met, rot_bound);
    std::printf(
        "%s: %zu of %zu projection errors within 3 mrcal-style sigma (%.1f %%); median |e| / "
        "sigma %.2f\n",
        name, p_within, p_total, 100.0 * p_within / p_total, pz_median);
    EXPECT_GE(within, total * 95 / 100);
    EXPECT_GE(p_within, p_total * 95 / 100);
    // Not grossly pessimistic either: a 2-D Gaussian error has a median |e| of 0.67 to 1.18 of its
    // worst-direction sigma (elongated to round).
    EXPECT_GT(pz_median, 0.4);
  }
}

// The 6 x 6 AprilGrid (88 mm tags), radtan, 40 views: the bars as rates over 20 seeds.
// The stereo rotation's 0.01 deg bar, met narrowly by seed 1 (0.0097 deg), holds in a fraction of
// the seeds only (doc/cameras.md gives the figures this asserts).
TEST(CameraSimLong, AprilGridBarsOver20Seeds) {
  int focal = 0, pp = 0, baseline = 0, rot = 0, rot2 = 0;
  double rot_max = 0;
  std::vector<double> rots;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    const rigcal::camera::TruthZ t = rigcal::camera::check_aprilgrid_for_long_test(seed);
    std::printf(
        "AprilGrid seed %2llu: focal %.2e, principal point %.3f px, baseline %.3f mm, rotation "
        "%.4f deg (1-sigma %.4f %.4f %.4f)\n",
        static_cast<unsigned long long>(seed), t.focal_rel, t.principal_point_px,
        1e3 * t.baseline_m, t.rotation_deg, t.rotation_sigma_deg[0], t.rotation_sigma_deg[1],
        t.rotation_sigma_deg[2]);
    focal += t.focal_rel <= 2e-4;
    pp += t.principal_point_px <= 0.3;
    baseline += t.baseline_m <= 0.2e-3;
    rot += t.rotation_deg <= 0.01;
    rot2 += t.rotation_deg <= 0.02;
    rot_max = std::max(rot_max, t.rotation_deg);
    rots.push_back(t.rotation_deg);
  }
  std::printf(
      "AprilGrid over 20 seeds: focal <= 2e-4 in %d, principal point <= 0.3 px in %d, baseline "
      "<= 0.2 mm in %d, rotation <= 0.01 deg in %d (<= 0.02 deg in %d; median %.4f, max %.4f "
      "deg)\n",
      focal, pp, baseline, rot, rot2, rigcal::median(rots), rot_max);
  EXPECT_EQ(focal, 20);
  EXPECT_EQ(baseline, 20);
  // Measured: principal point 19 of 20, rotation <= 0.01 deg 10 of 20 (median 0.0102 deg),
  // <= 0.02 deg 19 of 20 (max 0.0236). Asserted: at least 80 %, 40 % and 95 %.
  EXPECT_GE(pp, 16);
  EXPECT_GE(rot, 8);
  EXPECT_GE(rot2, 19);
}
