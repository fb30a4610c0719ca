// Metrics on synthetic trajectories, each checked against an independent computation: brute-force
// association, known transforms, a known drift, statistics by hand.
#include <gtest/gtest.h>

#include <random>

#include "rigcal/bench/evaluate.h"
#include "rigcal/bench/leaderboard.h"
#include "rigcal/core/error.h"

namespace rigcal::bench {
namespace {

Trajectory wavy(size_t n, double dt = 0.1, uint64_t seed = 1) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.01);
  Trajectory t;
  for (size_t i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) * dt;
    t.stamps.push_back(Time::from_seconds(100.0 + s));
    const Eigen::Vector3d p(5.0 * s, 20.0 * std::sin(0.1 * s),
                            2.0 * std::sin(0.05 * s) + noise(rng));
    t.T_world_body.push_back(
        SE3::from_rotation_vector(Eigen::Vector3d(0.1 * std::sin(s), 0.05, 0.1 * s), p));
  }
  return t;
}

TEST(BenchStats, MatchHandComputedValues) {
  const Stats s = statistics({3.0, 1.0, 4.0, 1.0, 5.0});
  EXPECT_EQ(s.n, 5u);
  EXPECT_DOUBLE_EQ(s.mean, 14.0 / 5.0);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt((9.0 + 1 + 16 + 1 + 25) / 5.0));
  EXPECT_DOUBLE_EQ(s.median, 3.0);
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 5.0);
  EXPECT_DOUBLE_EQ(s.sse, 52.0);
  const double m = 2.8;
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(((3 - m) * (3 - m) + 2 * (1 - m) * (1 - m) + (4 - m) * (4 - m) +
                                     (5 - m) * (5 - m)) /
                                    5));
  EXPECT_DOUBLE_EQ(statistics({1.0, 2.0, 10.0, 4.0}).median, 3.0);
}

// Box plot and histogram figures as numpy and matplotlib compute them (numpy 1.24:
// np.percentile(v, [25, 50, 75]) = 3.5, 6, 8.5; whiskers at the furthest values within 1.5 IQR
// of the box: 1 and 10, so 100 lies beyond; Freedman-Diaconis: ceil(99 / (2 * 5 / 11^(1/3))) =
// 23 bins, np.histogram's counts 5, 4, 1, 0 ... 0, 1).
TEST(BenchStats, DistributionAsNumpyAndMatplotlibDrawIt) {
  const Distribution d = distribution({7, 100, 3, 9, 1, 10, 4, 6, 2, 8, 5});
  EXPECT_EQ(d.n, 11u);
  EXPECT_DOUBLE_EQ(d.q1, 3.5);
  EXPECT_DOUBLE_EQ(d.median, 6.0);
  EXPECT_DOUBLE_EQ(d.q3, 8.5);
  EXPECT_DOUBLE_EQ(d.whisker_low, 1.0);
  EXPECT_DOUBLE_EQ(d.whisker_high, 10.0);
  EXPECT_DOUBLE_EQ(d.bin_low, 1.0);
  ASSERT_EQ(d.counts.size(), 23u);
  EXPECT_DOUBLE_EQ(d.bin_width, 99.0 / 23.0);
  std::vector<size_t> want(23, 0);
  want[0] = 5, want[1] = 4, want[2] = 1, want[22] = 1;
  EXPECT_EQ(d.counts, want);
  // The median between the two middle values of an even count, as statistics() gives it; all
  // equal: one bin.
  EXPECT_DOUBLE_EQ(distribution({4, 1, 3, 2}).median, statistics({4, 1, 3, 2}).median);
  EXPECT_EQ(distribution({2, 2, 2}).counts, std::vector<size_t>{3});
  EXPECT_EQ(distribution({}).n, 0u);
}

TEST(BenchAssociation, NearestMatchesBruteForce) {
  std::mt19937_64 rng(4);
  std::uniform_int_distribution<int64_t> step(1, 30'000'000);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Time> a, b;
    int64_t ta = 0, tb = 5'000'000;
    for (int i = 0; i < 300; ++i) a.push_back(Time{ta += step(rng)});
    for (int i = 0; i < 500; ++i) b.push_back(Time{tb += step(rng) / 2});
    const Time max_diff{4'000'000};
    const auto got = nearest_stamps(a, b, max_diff);
    std::vector<std::pair<size_t, size_t>> expected;
    for (size_t i = 0; i < a.size(); ++i) {
      size_t best = 0;
      for (size_t j = 1; j < b.size(); ++j) {
        if (std::abs((b[j] - a[i]).ns) < std::abs((b[best] - a[i]).ns)) best = j;  // first minimum
      }
      if (std::abs((b[best] - a[i]).ns) <= max_diff.ns) expected.emplace_back(i, best);
    }
    ASSERT_EQ(got, expected) << trial;
  }
}

TEST(BenchAssociation, OneToOneMatchesGreedyBruteForce) {
  std::mt19937_64 rng(8);
  std::uniform_int_distribution<int64_t> step(1, 20'000'000);
  Trajectory gt, est;
  int64_t t = 0, u = 3'000'000;
  for (int i = 0; i < 200; ++i)
    gt.stamps.push_back(Time{t += step(rng)}), gt.T_world_body.emplace_back();
  for (int i = 0; i < 260; ++i)
    est.stamps.push_back(Time{u += step(rng)}), est.T_world_body.emplace_back();
  const Time max_diff{6'000'000};
  const Matches m = associate_one_to_one(gt, est, max_diff);
  // Brute force: repeatedly take the globally closest unused pair.
  std::vector<char> gu(gt.size(), 0), eu(est.size(), 0);
  std::vector<std::pair<size_t, size_t>> expected;
  while (true) {
    int64_t best = INT64_MAX;
    size_t bi = 0, bj = 0;
    for (size_t i = 0; i < gt.size(); ++i) {
      for (size_t j = 0; j < est.size(); ++j) {
        const int64_t d = std::abs((gt.stamps[i] - est.stamps[j]).ns);
        if (!gu[i] && !eu[j] && d <= max_diff.ns && d < best) best = d, bi = i, bj = j;
      }
    }
    if (best == INT64_MAX) break;
    gu[bi] = eu[bj] = 1;
    expected.emplace_back(bi, bj);
  }
  std::sort(expected.begin(), expected.end());
  ASSERT_EQ(m.gt.size(), expected.size());
  for (size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(m.gt[k], expected[k].first);
    EXPECT_EQ(m.est[k], expected[k].second);
  }
}

TEST(BenchAssociation, InterpolationIsExactOnUniformMotion) {
  // Constant velocity and constant rotation rate: slerp + linear interpolation are exact.
  Trajectory gt;
  for (int i = 0; i <= 10; ++i) {
    gt.stamps.push_back(Time::from_seconds(i));
    gt.T_world_body.push_back(SE3::from_rotation_vector(Eigen::Vector3d(0, 0, 0.2 * i),
                                                        Eigen::Vector3d(1.5 * i, -0.5 * i, 0)));
  }
  Trajectory est;
  for (double s : {-0.5, 0.25, 3.0, 7.6, 10.0, 10.5}) {
    est.stamps.push_back(Time::from_seconds(s));
    est.T_world_body.emplace_back();
  }
  const Interpolated in = interpolate_gt(gt, est, Time::from_seconds(1.0));
  ASSERT_EQ(in.est, (std::vector<size_t>{1, 2, 3, 4}));  // the ones inside the GT time span
  const double s = 7.6;
  EXPECT_TRUE(in.T_world_gt[2].t.isApprox(Eigen::Vector3d(1.5 * s, -0.5 * s, 0), 1e-14));
  EXPECT_NEAR(rotation_angle(in.T_world_gt[2].R), 0.2 * s, 1e-13);
  // A gap wider than max_gap is not bridged.
  EXPECT_TRUE(interpolate_gt(gt, est, Time::from_seconds(0.5)).est == (std::vector<size_t>{2, 4}));
}

TEST(BenchAlignment, RecoversKnownTransformsAndScale) {
  const Trajectory gt = wavy(500);
  const SE3 T_est_gt =
      SE3::from_rotation_vector(Eigen::Vector3d(0.3, -0.2, 1.1), Eigen::Vector3d(4, -7, 2));
  for (const Alignment method : {Alignment::se3, Alignment::sim3}) {
    const double scale = method == Alignment::sim3 ? 0.8 : 1.0;
    std::vector<SE3> est;
    for (const SE3& T : gt.T_world_body) {
      SE3 e = T_est_gt * T;
      e.t /= scale;  // the estimate is 1/scale too large
      est.push_back(e);
    }
    const AlignmentResult a = align(gt.T_world_body, est, method);
    EXPECT_NEAR(a.scale, scale, 1e-12);
    EXPECT_TRUE(a.T_gt_est.matrix().isApprox(T_est_gt.inverse().matrix(), 1e-10));
    std::vector<SE3> aligned;
    for (const SE3& e : est) aligned.push_back(apply(a, e));
    const PoseErrors err = absolute_errors(gt.T_world_body, aligned);
    EXPECT_LT(statistics(err.trans).max, 1e-9);
    EXPECT_LT(statistics(err.rot_deg).max, 1e-9);
  }
  // 4-DoF: yaw and translation only.
  const SE3 T_yaw =
      SE3::from_rotation_vector(Eigen::Vector3d(0, 0, -2.0), Eigen::Vector3d(1, 2, 3));
  std::vector<SE3> est;
  for (const SE3& T : gt.T_world_body) est.push_back(T_yaw * T);
  const AlignmentResult y = align(gt.T_world_body, est, Alignment::yaw);
  EXPECT_TRUE(y.T_gt_est.matrix().isApprox(T_yaw.inverse().matrix(), 1e-10));
  // Origin: the first poses coincide.
  const AlignmentResult o = align(gt.T_world_body, est, Alignment::origin);
  EXPECT_TRUE(apply(o, est[0]).matrix().isApprox(gt.T_world_body[0].matrix(), 1e-12));
  // Points on a line: no rotation is defined.
  std::vector<SE3> line;
  for (int i = 0; i < 10; ++i)
    line.push_back(SE3::from_rotation_vector(Eigen::Vector3d::Zero(), Eigen::Vector3d(i, 0, 0)));
  EXPECT_THROW(align(line, line, Alignment::se3), Error);
}

TEST(BenchRpe, KnownScaleDriftGivesItsPercentage) {
  // Straight line, 1 m a frame; the estimate travels 2 % too far: every segment's error is 2 %.
  std::vector<SE3> gt, est;
  for (int i = 0; i < 2000; ++i) {
    gt.push_back(SE3::from_rotation_vector(Eigen::Vector3d::Zero(), Eigen::Vector3d(i, 0, 0)));
    est.push_back(
        SE3::from_rotation_vector(Eigen::Vector3d::Zero(), Eigen::Vector3d(1.02 * i, 0, 0)));
  }
  const std::vector<Segment> segs = length_segments(gt, est, {100, 800}, 10);
  // Starts 0, 10, ... : a 100 m segment ends at i + 101 (the first beyond 100 m), 800 m at i + 801.
  EXPECT_EQ(segs.size(), 190u + 120u);
  EXPECT_EQ(segs.front().last, 101u);
  const Drift d = pooled_drift(segs);
  // |t(E)| = 0.02 * 101 m over a nominal 100 m, 0.02 * 801 over 800: the KITTI definition.
  const double expected = 100.0 * (190 * 0.02 * 101 / 100 + 120 * 0.02 * 801 / 800) / 310.0;
  EXPECT_NEAR(d.trans_pct, expected, 1e-10);
  EXPECT_NEAR(d.rot_deg_per_m, 0.0, 1e-12);
  const std::vector<Segment> deltas = frame_deltas(gt, est, 5);
  EXPECT_EQ(deltas.size(), 399u);
  EXPECT_NEAR(deltas[3].trans, 0.1, 1e-12);
}

TEST(BenchEvaluate, RigcalDefaultInterpolatesAlignsAndReportsZeroForAPerfectEstimate) {
  const Trajectory gt = wavy(3000, 0.1);
  // The estimate: a different world frame, stamps between GT stamps, exact poses there.
  const SE3 T_est_gt =
      SE3::from_rotation_vector(Eigen::Vector3d(0.0, 0.0, 0.7), Eigen::Vector3d(1, 2, 0));
  Trajectory est;
  for (size_t i = 0; i + 1 < gt.size(); i += 3) {
    est.stamps.push_back(gt.stamps[i] + Time::from_ns(50'000'000));
    est.T_world_body.push_back(T_est_gt *
                               interpolate(gt.T_world_body[i], gt.T_world_body[i + 1], 0.5));
  }
  const EvalResult r = evaluate(gt, est);
  EXPECT_EQ(r.association, Association::interpolate);
  EXPECT_EQ(r.n_pairs, est.size());
  EXPECT_LT(r.ate_trans.max, 1e-8);
  EXPECT_LT(r.ate_rot_deg.max, 1e-6);
  ASSERT_NE(find_rpe(r, "vbr"), nullptr);
  EXPECT_LT(find_rpe(r, "vbr")->drift.trans_pct, 1e-8);
  EXPECT_GT(find_rpe(r, "kitti")->drift.n_segments, 0u);
}

TEST(BenchEvaluate, ClearErrorsForNoOverlapAndMismatchedCounts) {
  const Trajectory gt = wavy(100);
  Trajectory later = wavy(100);
  for (Time& t : later.stamps) t = t + Time::from_seconds(1000);
  try {
    evaluate(gt, later);
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no pose pairs: the trajectories do not overlap in time"),
              std::string::npos)
        << e.what();
  }
  Trajectory a = wavy(10), b = wavy(12);
  a.has_stamps = b.has_stamps = false;
  EXPECT_THROW(evaluate(a, b), Error);
  EXPECT_THROW(evaluate(Trajectory{}, gt), Error);
}

TEST(BenchLeaderboard, RankIsTheAreaUnderTheCumulativeCurve) {
  const std::vector<double> errors = {1.0, 4.0, 12.0, INFINITY};
  EXPECT_DOUBLE_EQ(rank_score(errors, 10.0), 9.0 + 6.0);
  // The area under the step curve of the count below x, 0..10, sampled finely.
  const auto curve = cumulative_curve(errors, 10.0, 100001);
  double area = 0.0;
  for (size_t k = 1; k < curve.size(); ++k)
    area += curve[k].second * (curve[k].first - curve[k - 1].first);
  EXPECT_NEAR(area * errors.size(), rank_score(errors, 10.0), 1e-3);
  EXPECT_DOUBLE_EQ(curve.back().second, 0.5);
}

}  // namespace
}  // namespace rigcal::bench
