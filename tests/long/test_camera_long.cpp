// Long statistical check (CTest label "long", run by `make test-long`): over 20 seeds and both
// lens models, the errors against simulator truth fall within 3 reported sigma at least 95 % of
// the time (fx, fy, cx, cy of both cameras and the stereo rotation's three axes), and so do the
// projection errors against the mrcal-style projection uncertainty (5 pixels a camera).
// Efficiency, against the Cramer-Rao bound the test computes itself (tests/unit/camera_bound.h:
// OpenCV's projection at the true parameters, the corner noise measured against truth): per
// parameter group, the RMS error over the seeds at most 1.2 times the RMS reported sigma, and every
// reported sigma at most 1.25 times the bound (the lower side: at least kSigmaOverBoundMin, as in
// the seed-1 tests); and the 3-sigma honesty over every parameter (distortion and translation
// too) at least 95 % as well.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
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
    // Per parameter group over the seeds: sums of squared errors, reported sigmas, bounds and the
    // bound's first-order least-squares errors; the squared Mahalanobis distances (reported
    // covariance) and their degrees of freedom.
    struct Sums {
      double err2 = 0, sigma2 = 0, bound2 = 0, lsq2 = 0, m2 = 0;
      int n = 0, dof = 0, within = 0;
    };
    std::map<std::string, Sums> sums;
    double worst_ratio = 0, least_ratio = 1e9;
    std::string worst_name, least_name;
    uint64_t worst_seed = 0, least_seed = 0;
    size_t all_within = 0, all_total = 0;
    double max_lsq_gap = 0;                     // |error - lsq error| / sigma, worst
    std::vector<double> view_z, neighbour_rho;  // the bound's checks of independent corners
    for (uint64_t seed = 1; seed <= 20; ++seed) {
      const rigcal::camera::TruthZ t =
          rigcal::camera::check_against_truth_for_long_test(model, seed);
      for (const rigcal::camera::TruthZ::Parameter& p : t.figures) {
        Sums& g = sums[p.group];
        g.err2 += p.error * p.error, g.sigma2 += p.sigma * p.sigma, g.bound2 += p.bound * p.bound;
        g.lsq2 += p.lsq_error * p.lsq_error;
        ++g.n;
        g.within += std::abs(p.error) <= 3 * p.sigma;
        all_within += std::abs(p.error) <= 3 * p.sigma;
        ++all_total;
        const double ratio = p.sigma / p.bound;
        if (ratio > worst_ratio) worst_ratio = ratio, worst_name = p.name, worst_seed = seed;
        if (ratio < least_ratio) least_ratio = ratio, least_name = p.name, least_seed = seed;
        max_lsq_gap = std::max(max_lsq_gap, std::abs(p.error - p.lsq_error) / p.sigma);
        EXPECT_LE(p.sigma, rigcal::camera::kSigmaOverBoundMax * p.bound)
            << "seed " << seed << " " << p.name;
        EXPECT_GE(p.sigma, rigcal::camera::kSigmaOverBoundMin * p.bound)
            << "seed " << seed << " " << p.name;
      }
      view_z.push_back(t.view_mean_z_rms);
      neighbour_rho.push_back(t.neighbour_correlation);
      for (const rigcal::camera::TruthZ::Group& g : t.groups) {
        sums[g.group].m2 += g.mahalanobis2;
        sums[g.group].dof += g.n;
      }
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
    std::printf(
        "%s: reported sigma / bound over 20 seeds x %zu parameters: %.4f (%s, seed %llu) to %.4f "
        "(%s, seed %llu); |error - the bound's least-squares error| at most %.3f sigma; all "
        "parameters (distortion and translation too) within 3 sigma: %zu of %zu (%.1f %%)\n",
        name, all_total / 20, least_ratio, least_name.c_str(),
        static_cast<unsigned long long>(least_seed), worst_ratio, worst_name.c_str(),
        static_cast<unsigned long long>(worst_seed), max_lsq_gap, all_within, all_total,
        100.0 * all_within / all_total);
    std::printf(
        "%s: independent corners? per-view mean error in sigmas, rms: median %.2f, %.2f to %.2f "
        "over the seeds (1 if so); neighbours' error correlation median %+.3f, %+.3f to %+.3f "
        "(0)\n",
        name, rigcal::median(view_z), *std::min_element(view_z.begin(), view_z.end()),
        *std::max_element(view_z.begin(), view_z.end()), rigcal::median(neighbour_rho),
        *std::min_element(neighbour_rho.begin(), neighbour_rho.end()),
        *std::max_element(neighbour_rho.begin(), neighbour_rho.end()));
    for (const char* group : rigcal::camera::kParameterGroups) {
      const Sums& g = sums[group];
      const double rms_err = std::sqrt(g.err2 / g.n), rms_sigma = std::sqrt(g.sigma2 / g.n),
                   rms_bound = std::sqrt(g.bound2 / g.n), rms_lsq = std::sqrt(g.lsq2 / g.n);
      std::printf(
          "%s, %-18s (%3d seed-parameter pairs): RMS error / RMS reported sigma %.3f, RMS "
          "reported / RMS bound %.4f, RMS lsq error / RMS error %.4f; within 3 sigma %d; sum of "
          "squared Mahalanobis distances %.1f for %d dof (P(chi2 >= it) = %.3f)\n",
          name, group, g.n, rms_err / rms_sigma, rms_sigma / rms_bound, rms_lsq / rms_err, g.within,
          g.m2, g.dof, rigcal::chi2_upper_tail(g.m2, g.dof));
      EXPECT_LE(rms_err, 1.2 * rms_sigma) << name << " " << group;
    }
    EXPECT_GE(within, total * 95 / 100);
    EXPECT_GE(all_within, all_total * 95 / 100);
    EXPECT_GE(p_within, p_total * 95 / 100);
    // Not grossly pessimistic either: a 2-D Gaussian error has a median |e| of 0.67 to 1.18 of its
    // worst-direction sigma (elongated to round).
    EXPECT_GT(pz_median, 0.4);
  }
}

// The 6 x 6 AprilGrid (88 mm tags), radtan, 40 views: the bars as rates over 20 seeds, and
// the reported uncertainty's honesty as the checkerboard's above (at least 95 % within 3 sigma).
// The stereo rotation's 0.01 deg bar, met narrowly by seed 1 (0.0097 deg), holds in a fraction of
// the seeds only (doc/cameras.md gives the figures this asserts).
TEST(CameraSimLong, AprilGridBarsOver20Seeds) {
  int focal = 0, pp = 0, baseline = 0, rot = 0, rot2 = 0;
  double rot_max = 0;
  std::vector<double> rots;
  // Honesty, as for the checkerboard above: parameter errors (fx fy cx cy of both cameras, the
  // stereo rotation's axes), every parameter, and the centre-pixel projection errors within 3
  // reported sigma.
  size_t within = 0, total = 0, all_within = 0, all_total = 0, p_within = 0, p_total = 0;
  std::vector<double> pz;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    const rigcal::camera::TruthZ t = rigcal::camera::check_aprilgrid_for_long_test(seed);
    for (double z : t.parameters) within += z <= 3.0, ++total;
    for (const rigcal::camera::TruthZ::Parameter& p : t.figures)
      all_within += std::abs(p.error) <= 3 * p.sigma, ++all_total;
    for (double z : t.projection) p_within += z <= 3.0, ++p_total, pz.push_back(z);
    std::printf("AprilGrid seed %2llu: projection errors / sigma:",
                static_cast<unsigned long long>(seed));
    for (double z : t.projection) std::printf(" %.2f", z);
    std::printf("\n");
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
  std::printf(
      "AprilGrid honesty over 20 seeds: %zu of %zu parameter errors within 3 sigma (%.1f %%), all "
      "parameters %zu of %zu (%.1f %%), projection errors %zu of %zu (%.1f %%; median |e| / sigma "
      "%.2f)\n",
      within, total, 100.0 * within / total, all_within, all_total, 100.0 * all_within / all_total,
      p_within, p_total, 100.0 * p_within / p_total, rigcal::median(pz));
  // Measured with the grid-aware reader: 220 of 220, 439 of 440, 200 of 200 (median 1.09).
  EXPECT_GE(within, total * 95 / 100);
  EXPECT_GE(all_within, all_total * 95 / 100);
  EXPECT_GE(p_within, p_total * 95 / 100);
  EXPECT_GT(rigcal::median(pz), 0.4);  // not grossly pessimistic either
  EXPECT_EQ(focal, 20);
  EXPECT_EQ(baseline, 20);
  // Measured with the grid-aware reader: principal point 19 of 20, rotation <= 0.01 deg 14 of 20
  // (median 0.0060 deg), <= 0.02 deg 20 of 20 (max 0.0160); aruco alone gave 10 of 20 and 19.
  // Asserted: at least 80 %, 40 % and 95 %.
  EXPECT_GE(pp, 16);
  EXPECT_GE(rot, 8);
  EXPECT_GE(rot2, 19);
}
