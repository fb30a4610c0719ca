// The ground truth's pose graph (calib/gt): odometry and GNSS priors from the simulator's
// trajectories part, scored against its truth.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <numeric>
#include <random>
#include <set>
#include <sstream>

#include "cli_run.h"
#include "rigcal/bench/metrics.h"
#include "rigcal/core/error.h"
#include "rigcal/core/stats.h"
#include "rigcal/core/text.h"
#include "rigcal/gt/motion_fusion.h"
#include "rigcal/gt/pose_graph.h"
#include "rigcal/io/gnss_fixes.h"
#include "rigcal/io/odometry_io.h"
#include "rigcal/io/trajectory_io.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/sim/session.h"

namespace rigcal {
namespace {

using gt::Matrix6d;

// The simulator's odometry noise as a step covariance (its scale error is a bias, left out).
Matrix6d step_covariance(const sim::OdometryNoise& noise) {
  const double r = noise.rot_sigma_deg * M_PI / 180.0, t = noise.trans_sigma_m;
  return (Vector6d() << r * r, r * r, r * r, t * t, t * t, t * t).finished().asDiagonal();
}

struct Scenario {
  rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  sim::SimConfig config;
  sim::TrajectoryPart part;
  Eigen::Vector3d p_lidar_antenna;
  std::vector<gt::PositionFix> fixes;
  gt::OdometryInput odometry;
  Trajectory truth_enu;  // T_enu_lidar

  void simulate() {
    part = sim::simulate_trajectories(rig, config);
    const rig::Sensor& gnss = rig::sensor(rig, "gnss");
    p_lidar_antenna = gnss.T_base_sensor.t;  // the LiDAR is the base frame
    fixes = gt::position_fixes(part.gnss, {}, {}, gnss.time_offset, gt::PoseGraphConfig{});
    odometry.T_odom_lidar = part.odometry;
    odometry.step_covariance.assign(part.odometry.size() - 1, step_covariance(config.odometry));
    truth_enu = part.truth_base;
    for (SE3& T : truth_enu.T_world_body) T = part.T_enu_world * T;
  }
};

// Relative translation error over pairs about `length_m` of path apart: the displacement in the
// first pose's frame (estimate and truth), or in ENU when `enu` (positions without rotation).
double relative_error_rms(const std::vector<SE3>& est, const std::vector<SE3>& truth,
                          double length_m, bool enu) {
  std::vector<double> along(truth.size(), 0.0), errors;
  for (size_t k = 1; k < truth.size(); ++k)
    along[k] = along[k - 1] + (truth[k].t - truth[k - 1].t).norm();
  size_t j = 0;
  for (size_t i = 0; i < truth.size(); i += 5) {
    while (j < truth.size() && along[j] - along[i] < length_m) ++j;
    if (j >= truth.size()) break;
    const Eigen::Vector3d d_est =
        enu ? Eigen::Vector3d(est[j].t - est[i].t) : Eigen::Vector3d((est[i].inverse() * est[j]).t);
    const Eigen::Vector3d d_true = enu ? Eigen::Vector3d(truth[j].t - truth[i].t)
                                       : Eigen::Vector3d((truth[i].inverse() * truth[j]).t);
    errors.push_back((d_est - d_true).norm());
  }
  return rms(errors);
}

// H block tridiagonal, random and positive definite: the chain's marginals against the dense
// inverse.
TEST(PoseGraph, ChainMarginalsAreTheDiagonalBlocksOfTheInverse) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> N;
  const size_t n = 9;
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(12 * n, 6 * n);
  for (size_t k = 0; k < n; ++k) {  // a prior on each pose and an edge to the next
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c) J(12 * k + r, 6 * k + c) = N(rng);
    if (k + 1 == n) continue;
    for (int r = 6; r < 12; ++r)
      for (int c = 0; c < 12; ++c) J(12 * k + r, 6 * k + c) = N(rng);
  }
  const Eigen::MatrixXd H = J.transpose() * J;
  std::vector<Matrix6d> D(n), B(n - 1);
  for (size_t k = 0; k < n; ++k) {
    D[k] = H.block<6, 6>(6 * k, 6 * k);
    if (k + 1 < n) B[k] = H.block<6, 6>(6 * k, 6 * k + 6);
  }
  const Eigen::MatrixXd H_inv = H.inverse();
  const std::vector<Matrix6d> C = gt::chain_marginals(D, B);
  ASSERT_EQ(C.size(), n);
  for (size_t k = 0; k < n; ++k) {
    const Matrix6d expected = H_inv.block<6, 6>(6 * k, 6 * k);
    EXPECT_LT((C[k] - expected).norm(), 1e-9 * expected.norm()) << k;
  }
  D[4].setZero();  // a pose nothing ties: no marginals
  B[3].setZero(), B[4].setZero();
  EXPECT_TRUE(gt::chain_marginals(D, B).empty());
}

// A two-minute walk with RTK fixes at 100 Hz, 1 % multipath outliers and a 20 s outage.
TEST(PoseGraph, AWalkWithRtkFixesBeatsTheOdometryAndTheGnssAloneAndItsSigmasAreHonest) {
  Scenario s;
  s.config.trajectory_duration_s = 120;
  s.config.gnss.outages = {{40.0, 60.0}};
  s.config.gnss.outlier_probability = 0.01;
  s.simulate();
  const gt::PoseGraphResult r =
      gt::solve_pose_graph(s.odometry, s.fixes, s.p_lidar_antenna, gt::PoseGraphConfig{});
  ASSERT_EQ(r.T_enu_lidar.size(), s.truth_enu.size());
  ASSERT_EQ(r.covariance.size(), s.truth_enu.size());
  EXPECT_TRUE(r.undetermined.empty());
  const std::vector<SE3>&est = r.T_enu_lidar.T_world_body, &truth = s.truth_enu.T_world_body;

  // Absolute errors, in the outage and out of it, with their normalized squares.
  std::vector<double> errors, outage_errors;
  size_t within = 0, rot_within = 0;
  for (size_t k = 0; k < truth.size(); ++k) {
    const Eigen::Vector3d e = est[k].t - truth[k].t;
    const double t = (s.truth_enu.stamps[k] - s.truth_enu.stamps.front()).seconds();
    (t >= 40.0 && t < 60.0 ? outage_errors : errors).push_back(e.norm());
    const Eigen::Matrix3d C = r.covariance[k].bottomRightCorner<3, 3>();
    within += e.dot(C.ldlt().solve(e)) <= 14.16;  // 99.73 % of chi-square(3)
    const Eigen::Vector3d e_rot = rotation_vector(est[k].R * truth[k].R.transpose());
    rot_within += e_rot.dot(r.covariance[k].topLeftCorner<3, 3>().ldlt().solve(e_rot)) <= 14.16;
  }
  std::vector<double> all = errors;
  all.insert(all.end(), outage_errors.begin(), outage_errors.end());
  // The odometry alone, aligned to the truth; the GNSS alone, at the scans.
  std::vector<double> odom_errors;
  {
    const bench::AlignmentResult a =
        bench::align(truth, s.odometry.T_odom_lidar.T_world_body, bench::Alignment::se3);
    for (size_t k = 0; k < truth.size(); ++k)
      odom_errors.push_back(
          (bench::apply(a, s.odometry.T_odom_lidar.T_world_body[k]).t - truth[k].t).norm());
  }
  // The GNSS alone, its multipath fixes (off by more than 0.3 m) left out: the honest bar.
  std::vector<SE3> gnss_at_scans, truth_at_fixes;
  std::vector<double> gnss_errors;
  for (const gt::PriorResidual& p : r.priors) {
    SE3 T;
    T.t = s.fixes[p.fix].p_enu - truth[p.node].R * s.p_lidar_antenna;
    const double e = (T.t - truth[p.node].t).norm();
    if (e >= 0.3) continue;
    gnss_at_scans.push_back(T);
    truth_at_fixes.push_back(truth[p.node]);
    gnss_errors.push_back(e);
  }
  const double rpe_graph = relative_error_rms(est, truth, 10.0, false);
  const double rpe_odom =
      relative_error_rms(s.odometry.T_odom_lidar.T_world_body, truth, 10.0, false);
  const double rpe_gnss = relative_error_rms(gnss_at_scans, truth_at_fixes, 10.0, true);
  std::printf(
      "[ figures ] pose graph, 120 s walk (%.0f m), 20 s outage: ATE rms %.1f mm (max %.1f; in the "
      "outage rms %.1f, max %.1f); odometry alone (aligned) rms %.1f mm; GNSS alone (no multipath "
      "fix) rms %.1f mm. "
      "RPE over 10 m: graph %.1f, odometry %.1f, GNSS %.1f mm. Poses within 3 sigma: position "
      "%.1f %%, rotation %.1f %%; priors rejected %zu of %zu\n",
      path_length(s.truth_enu), 1e3 * rms(errors), 1e3 * *std::max_element(all.begin(), all.end()),
      1e3 * rms(outage_errors), 1e3 * *std::max_element(outage_errors.begin(), outage_errors.end()),
      1e3 * rms(odom_errors), 1e3 * rms(gnss_errors), 1e3 * rpe_graph, 1e3 * rpe_odom,
      1e3 * rpe_gnss, 100.0 * within / truth.size(), 100.0 * rot_within / truth.size(), r.rejected,
      r.priors.size());
  EXPECT_LT(rms(all), rms(odom_errors));
  EXPECT_LT(rms(errors), rms(gnss_errors));
  EXPECT_LT(rpe_graph, rpe_odom);
  EXPECT_LT(rpe_graph, rpe_gnss);
  EXPECT_GE(double(within), 0.95 * double(truth.size()));
  EXPECT_GE(double(rot_within), 0.95 * double(truth.size()));
  // The outage is listed; the priors off by multipath are rejected, nearly no others.
  ASSERT_EQ(r.outages.size(), 1u);
  EXPECT_NEAR((r.outages[0].first - s.truth_enu.stamps.front()).seconds(), 40.0, 0.2);
  EXPECT_NEAR((r.outages[0].second - s.truth_enu.stamps.front()).seconds(), 60.0, 0.2);
  size_t off = 0, off_rejected = 0, good_rejected = 0;
  for (const gt::PriorResidual& p : r.priors) {
    const Eigen::Vector3d truth_antenna = truth[p.node] * s.p_lidar_antenna;
    const bool is_off = (s.fixes[p.fix].p_enu - truth_antenna).norm() > 0.3;
    off += is_off, off_rejected += is_off && p.rejected, good_rejected += !is_off && p.rejected;
  }
  EXPECT_GT(off, 3u);
  EXPECT_EQ(off_rejected, off);
  EXPECT_LE(double(good_rejected), 0.01 * double(r.priors.size()));
}

// A truth trajectory's odometry and fixes, made here: steps perturbed by `step_sigma` (rotation
// rad, translation m; rigcal's tangent) and chained from an arbitrary odometry frame; fixes of
// the antenna at every scan with `fix_sigma_m` noise, kept where `has_fix` says.
struct Synthetic {
  Trajectory truth;  // T_enu_lidar
  Eigen::Vector3d p_lidar_antenna{0.1, -0.05, 0.3};
  gt::OdometryInput odometry;
  std::vector<gt::PositionFix> fixes;

  void make(double step_rot, double step_trans, double fix_sigma_m,
            const std::function<bool(double)>& has_fix, uint64_t seed = 1) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> N;
    const Vector6d sigma =
        (Vector6d() << step_rot, step_rot, step_rot, step_trans, step_trans, step_trans).finished();
    const Matrix6d C = sigma.cwiseProduct(sigma).asDiagonal();
    odometry.T_odom_lidar.stamps = truth.stamps;
    odometry.T_odom_lidar.T_world_body = {
        SE3::from_rotation_vector(Eigen::Vector3d(0.02, -0.01, 1.0), Eigen::Vector3d(5, -3, 1))};
    for (size_t k = 0; k + 1 < truth.size(); ++k) {
      Vector6d e;
      for (int i = 0; i < 6; ++i) e(i) = sigma(i) * N(rng);
      const SE3 step = perturbed(truth.T_world_body[k].inverse() * truth.T_world_body[k + 1], e);
      odometry.T_odom_lidar.T_world_body.push_back(odometry.T_odom_lidar.T_world_body.back() *
                                                   step);
      odometry.step_covariance.push_back(C);
    }
    for (size_t k = 0; k < truth.size(); ++k) {
      const double t = (truth.stamps[k] - truth.stamps.front()).seconds();
      if (!has_fix(t)) continue;
      gt::PositionFix f;
      f.stamp = truth.stamps[k];
      f.p_enu = truth.T_world_body[k] * p_lidar_antenna +
                fix_sigma_m * Eigen::Vector3d(N(rng), N(rng), N(rng));
      f.covariance = fix_sigma_m * fix_sigma_m * Eigen::Matrix3d::Identity();
      fixes.push_back(f);
    }
  }

  // GNSS/INS attitudes of the LiDAR at every scan, each off the truth by independent rotations
  // about ENU's axes of `tilt_rad` (east, north) and `heading_rad` (up).
  std::vector<gt::AttitudeFix> attitudes;
  void make_attitudes(double tilt_rad, double heading_rad, uint64_t seed = 2) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> N;
    for (size_t k = 0; k < truth.size(); ++k) {
      const Eigen::Vector3d e(tilt_rad * N(rng), tilt_rad * N(rng), heading_rad * N(rng));
      gt::AttitudeFix a;
      a.stamp = truth.stamps[k];
      a.q_enu_lidar = Eigen::Quaterniond(SE3::from_rotation_vector(e, Eigen::Vector3d::Zero()).R *
                                         truth.T_world_body[k].R);
      a.covariance =
          Eigen::Vector3d(tilt_rad * tilt_rad, tilt_rad * tilt_rad, heading_rad * heading_rad)
              .asDiagonal();
      attitudes.push_back(a);
    }
  }
};

// The share of the poses whose rotation error lies within the 3-sigma ellipsoid of its marginal
// covariance (14.16: chi-square with 3 degrees of freedom at 99.73 %).
double rotations_within_3_sigma(const gt::PoseGraphResult& r, const Trajectory& truth) {
  size_t within = 0;
  for (size_t k = 0; k < truth.size(); ++k) {
    const Eigen::Vector3d e =
        rotation_vector(r.T_enu_lidar.T_world_body[k].R * truth.T_world_body[k].R.transpose());
    within += e.dot(r.covariance[k].topLeftCorner<3, 3>().ldlt().solve(e)) <= 14.16;
  }
  return double(within) / double(truth.size());
}

// `seconds` at 10 Hz of T_enu_lidar(t).
Trajectory truth_of(double seconds, const std::function<SE3(double)>& T_enu_lidar) {
  Trajectory out;
  for (int k = 0; k <= int(std::lround(10 * seconds)); ++k) {
    out.stamps.push_back(Time::from_seconds(1000.0 + 0.1 * k));
    out.T_world_body.push_back(T_enu_lidar(0.1 * k));
  }
  return out;
}

// A loop of 10 m radius, one lap a minute, heading along the loop.
SE3 on_a_loop(double t) {
  const double a = 2 * M_PI * t / 60.0;
  return SE3::from_rotation_vector(
      Eigen::Vector3d(0, 0, a + M_PI / 2),
      Eigen::Vector3d(10 * std::cos(a), 10 * std::sin(a), 0.1 * std::sin(3 * a)));
}

TEST(PoseGraph, NoFixAtAllPlacesNoPoseAndSaysWhy) {
  Synthetic s;
  s.truth = truth_of(10, on_a_loop);
  s.make(1e-4, 2e-3, 0.02, [](double) { return false; });
  const gt::PoseGraphResult none =
      gt::solve_pose_graph(s.odometry, s.fixes, s.p_lidar_antenna, gt::PoseGraphConfig{});
  EXPECT_TRUE(none.T_enu_lidar.empty());
  ASSERT_EQ(none.undetermined.size(), 1u);
  EXPECT_EQ(none.undetermined[0].what, "every pose");
  EXPECT_NE(none.undetermined[0].why.find("no GNSS fix"), std::string::npos);
  // Fixes an hour away (a wrong clock offset): said so, with the clock named.
  std::vector<gt::PositionFix> late = {gt::PositionFix{}, gt::PositionFix{}};
  late[0].stamp = s.truth.stamps.back() + Time::from_seconds(3600);
  late[1].stamp = late[0].stamp + Time::from_seconds(0.1);
  const gt::PoseGraphResult off =
      gt::solve_pose_graph(s.odometry, late, s.p_lidar_antenna, gt::PoseGraphConfig{});
  EXPECT_TRUE(off.T_enu_lidar.empty());
  ASSERT_EQ(off.undetermined.size(), 1u);
  EXPECT_NE(off.undetermined[0].why.find("time_offset"), std::string::npos);
  EXPECT_EQ(off.fixes_unused, 2u);
}

TEST(PoseGraph, ARigStandingStillHasItsPositionButNoHeading) {
  Synthetic s;
  s.truth = truth_of(30, [](double) {
    return SE3::from_rotation_vector(Eigen::Vector3d(0, 0, 2.0), Eigen::Vector3d(3, 4, 0.5));
  });
  s.make(1e-4, 1e-3, 0.02, [](double) { return true; });
  const gt::PoseGraphResult r =
      gt::solve_pose_graph(s.odometry, s.fixes, s.p_lidar_antenna, gt::PoseGraphConfig{});
  ASSERT_EQ(r.T_enu_lidar.size(), s.truth.size());
  ASSERT_EQ(r.undetermined.size(), 1u);
  EXPECT_NE(r.undetermined[0].what.find("heading"), std::string::npos);
  EXPECT_TRUE(r.covariance.empty());  // no sigmas invented for a rotation nothing fixes
  ASSERT_EQ(r.notes.size(), 1u);
  EXPECT_NE(r.notes[0].find("not determined"), std::string::npos);
  // The antenna is where the fixes and the odometry put it: a random walk of 1 mm a step seen
  // through fixes of 2 cm, whose smoothed error is sqrt(sqrt(q r) / 2) = 3.2 mm on each axis
  // (q, r the step's and the fix's variance), 5.5 mm rms in 3D; 14.5 mm is the 99.99 % point
  // of that error's length (chi with 3 degrees of freedom).
  std::vector<double> errors_m;
  for (size_t k = 0; k < s.truth.size(); ++k) {
    errors_m.push_back((r.T_enu_lidar.T_world_body[k] * s.p_lidar_antenna -
                        s.truth.T_world_body[k] * s.p_lidar_antenna)
                           .norm());
  }
  std::printf("[ figures ] antenna errors %.1f mm rms, max %.1f mm\n", 1e3 * rms(errors_m),
              1e3 * *std::max_element(errors_m.begin(), errors_m.end()));
  EXPECT_LT(rms(errors_m), 0.007);
  EXPECT_LT(*std::max_element(errors_m.begin(), errors_m.end()), 0.0145);
}

// The same standing rig with a GNSS/INS's attitudes (0.1 deg of tilt, 0.5 deg of heading, white):
// the heading is now determined, within its sigma, and the sigmas are given.
TEST(PoseGraph, ARigStandingStillHasItsHeadingFromTheInsAttitudes) {
  Synthetic s;
  s.truth = truth_of(30, [](double) {
    return SE3::from_rotation_vector(Eigen::Vector3d(0, 0, 2.0), Eigen::Vector3d(3, 4, 0.5));
  });
  // An odometry that keeps the rotation (1e-6 rad a step): the heading is the attitudes' alone.
  s.make(1e-6, 1e-3, 0.02, [](double) { return true; });
  const double tilt = 0.1 * M_PI / 180, heading = 0.5 * M_PI / 180;
  s.make_attitudes(tilt, heading);
  gt::PoseGraphConfig config;
  config.attitude_correlation_s = 0;  // the attitudes here are independent
  const gt::PoseGraphResult r =
      gt::solve_pose_graph(s.odometry, s.fixes, s.p_lidar_antenna, config, s.attitudes);
  ASSERT_EQ(r.T_enu_lidar.size(), s.truth.size());
  EXPECT_TRUE(r.undetermined.empty()) << r.undetermined[0].what << ": " << r.undetermined[0].why;
  ASSERT_EQ(r.covariance.size(), s.truth.size());
  ASSERT_EQ(r.attitude_priors.size(), s.truth.size());
  // The gate rejects 0.1 % of good attitudes (its chi-square quantile): 0.3 of 301 expected.
  EXPECT_LE(r.attitudes_rejected, 2u);
  // 301 attitudes of 0.5 deg on a rig whose odometry barely turns: the heading to about
  // 0.5 / sqrt(301) = 0.029 deg.
  const double sigma_heading = std::sqrt(r.covariance[150](2, 2));
  const Eigen::Vector3d e =
      rotation_vector(r.T_enu_lidar.T_world_body[150].R * s.truth.T_world_body[150].R.transpose());
  std::printf("[ figures ] a standing rig with attitudes: heading error %.4f deg, sigma %.4f deg\n",
              e.z() * 180 / M_PI, sigma_heading * 180 / M_PI);
  EXPECT_NEAR(sigma_heading, heading / std::sqrt(301.0), 0.2 * heading / std::sqrt(301.0));
  EXPECT_LT(std::abs(e.z()), 4 * sigma_heading);
  EXPECT_GE(rotations_within_3_sigma(r, s.truth), 0.95);
  // Taken as correlated over 10 s (the default), the same attitudes weigh as 301 / 200 of them:
  // the sigma grows to match.
  const gt::PoseGraphResult c = gt::solve_pose_graph(s.odometry, s.fixes, s.p_lidar_antenna,
                                                     gt::PoseGraphConfig{}, s.attitudes);
  ASSERT_EQ(c.covariance.size(), s.truth.size());
  EXPECT_NEAR(std::sqrt(c.covariance[150](2, 2)) / sigma_heading, std::sqrt(200.0), 0.5);
}

// Attitudes that agree with nothing (a random rotation each, the rig's INS rotation wrong by
// everything): every one is rejected by the gate, and the standing rig is held as without them.
TEST(PoseGraph, AttitudesThatAgreeWithNothingAreRejectedAndSaidSo) {
  Synthetic s;
  s.truth = truth_of(10, [](double) {
    return SE3::from_rotation_vector(Eigen::Vector3d(0, 0, 2.0), Eigen::Vector3d(3, 4, 0.5));
  });
  s.make(1e-4, 1e-3, 0.02, [](double) { return true; });
  s.make_attitudes(1e-3, 1e-3);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> N;
  for (gt::AttitudeFix& a : s.attitudes)
    a.q_enu_lidar = Eigen::Quaterniond(N(rng), N(rng), N(rng), N(rng)).normalized();
  const gt::PoseGraphResult r = gt::solve_pose_graph(s.odometry, s.fixes, s.p_lidar_antenna,
                                                     gt::PoseGraphConfig{}, s.attitudes);
  ASSERT_EQ(r.T_enu_lidar.size(), s.truth.size());
  EXPECT_EQ(r.attitudes_rejected, r.attitude_priors.size());
  ASSERT_EQ(r.undetermined.size(), 1u);
  EXPECT_NE(r.undetermined[0].why.find("Every GNSS/INS attitude was rejected"), std::string::npos)
      << r.undetermined[0].why;
  EXPECT_TRUE(r.covariance.empty());
}

TEST(PoseGraph, AStraightLineLeavesOnlyTheRollAboutItUndetermined) {
  Synthetic s;
  s.truth = truth_of(20, [](double t) {
    return SE3::from_rotation_vector(Eigen::Vector3d(0, 0, 0.5),
                                     Eigen::Vector3d(std::cos(0.5) * t, std::sin(0.5) * t, 0));
  });
  s.make(1e-4, 1e-3, 0.02, [](double) { return true; });
  const gt::PoseGraphResult r =
      gt::solve_pose_graph(s.odometry, s.fixes, s.p_lidar_antenna, gt::PoseGraphConfig{});
  ASSERT_EQ(r.T_enu_lidar.size(), s.truth.size());
  ASSERT_EQ(r.undetermined.size(), 1u);
  EXPECT_NE(r.undetermined[0].what.find("rotation about"), std::string::npos);
  EXPECT_NE(r.undetermined[0].why.find("line"), std::string::npos) << r.undetermined[0].why;
  const Eigen::Vector3d line(std::cos(0.5), std::sin(0.5), 0);
  if (!r.covariance.empty()) {  // the sigma is large about the line, small about the rest
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> e(r.covariance[100].topLeftCorner<3, 3>());
    EXPECT_GT(std::abs(e.eigenvectors().col(2).dot(line)), 0.99);
    EXPECT_GT(std::sqrt(e.eigenvalues()(2)), 1.0 * M_PI / 180);
    EXPECT_LT(std::sqrt(e.eigenvalues()(1)), 0.1 * M_PI / 180);
  }
  // The rotation error is a rotation about the line (the odometry's frame was turned 57 deg
  // about a tilted axis: the line fixes everything else).
  for (size_t k = 0; k < s.truth.size(); k += 40) {
    const Eigen::Vector3d e =
        rotation_vector(r.T_enu_lidar.T_world_body[k].R * s.truth.T_world_body[k].R.transpose());
    EXPECT_LT(e.cross(line).norm(), 0.01) << k << ": " << e.transpose();
    EXPECT_LT((r.T_enu_lidar.T_world_body[k] * s.p_lidar_antenna -
               s.truth.T_world_body[k] * s.p_lidar_antenna)
                  .norm(),
              0.03)
        << k;
  }
}

// The same line with a GNSS/INS's attitudes: the roll about it is theirs, nothing undetermined;
// a few attitudes 5 deg off (an INS's glitch) are rejected by the gate, and only they.
TEST(PoseGraph, AStraightLineHasItsRollFromTheInsAttitudes) {
  Synthetic s;
  s.truth = truth_of(20, [](double t) {
    return SE3::from_rotation_vector(Eigen::Vector3d(0, 0, 0.5),
                                     Eigen::Vector3d(std::cos(0.5) * t, std::sin(0.5) * t, 0));
  });
  s.make(1e-4, 1e-3, 0.02, [](double) { return true; });
  s.make_attitudes(0.1 * M_PI / 180, 0.5 * M_PI / 180);
  const std::set<size_t> glitches = {20, 77, 130, 180};
  for (const size_t k : glitches) {
    s.attitudes[k].q_enu_lidar =
        Eigen::Quaterniond(
            SE3::from_rotation_vector(Eigen::Vector3d(0.05, -0.06, 0.0), Eigen::Vector3d::Zero())
                .R) *
        s.attitudes[k].q_enu_lidar;
  }
  const gt::PoseGraphResult r = gt::solve_pose_graph(s.odometry, s.fixes, s.p_lidar_antenna,
                                                     gt::PoseGraphConfig{}, s.attitudes);
  ASSERT_EQ(r.T_enu_lidar.size(), s.truth.size());
  EXPECT_TRUE(r.undetermined.empty()) << r.undetermined[0].what << ": " << r.undetermined[0].why;
  ASSERT_EQ(r.covariance.size(), s.truth.size());
  // Every glitch rejected; of the rest, what the gate's 99.9 % quantile lets through (0.2 of 197
  // expected, 2 at most here).
  std::set<size_t> rejected;
  for (const gt::AttitudeResidual& a : r.attitude_priors)
    if (a.rejected) rejected.insert(a.node);
  for (const size_t k : glitches) EXPECT_EQ(rejected.count(k), 1u) << k;
  EXPECT_LE(rejected.size(), glitches.size() + 2);
  const Eigen::Vector3d line(std::cos(0.5), std::sin(0.5), 0);
  double worst_roll_deg = 0;
  for (size_t k = 0; k < s.truth.size(); ++k) {
    const Eigen::Vector3d e =
        rotation_vector(r.T_enu_lidar.T_world_body[k].R * s.truth.T_world_body[k].R.transpose());
    worst_roll_deg = std::max(worst_roll_deg, std::abs(e.dot(line)) * 180 / M_PI);
  }
  const double roll_sigma_deg =
      std::sqrt(line.dot(r.covariance[100].topLeftCorner<3, 3>() * line)) * 180 / M_PI;
  std::printf(
      "[ figures ] a straight line with attitudes: the roll about it %.4f deg at worst, its sigma "
      "%.4f deg at the middle\n",
      worst_roll_deg, roll_sigma_deg);
  // Without them it is free (the test above: the odometry's frame is 57 deg off); with them
  // about 0.1 deg of sigma (0.1 deg of tilt taken as correlated over 10 s, 20 s of them, and
  // the odometry's rotation walking 0.006 deg a step).
  EXPECT_LT(roll_sigma_deg, 0.15);
  EXPECT_LT(worst_roll_deg, 0.3);
  EXPECT_GE(rotations_within_3_sigma(r, s.truth), 0.95);
}

// The attitudes from GNSS/INS poses: the INS's rotation through the rig's; refused where there
// is no attitude to take.
TEST(PoseGraph, AttitudeFixesComposeTheRigsRotationAndRefusePositionsOnly) {
  Trajectory T_enu_ins;
  T_enu_ins.stamps = {Time::from_seconds(10.0), Time::from_seconds(10.01)};
  T_enu_ins.T_world_body = {
      SE3::from_rotation_vector(Eigen::Vector3d(0.1, 0.2, 1.5), Eigen::Vector3d(1, 2, 3)),
      SE3::from_rotation_vector(Eigen::Vector3d(0.1, 0.2, 1.6), Eigen::Vector3d(1, 2, 3))};
  const Eigen::Quaterniond q_ins_lidar(
      SE3::from_rotation_vector(Eigen::Vector3d(M_PI, 0, 0.01), Eigen::Vector3d::Zero()).R);
  const std::vector<gt::AttitudeFix> a =
      gt::attitude_fixes(T_enu_ins, q_ins_lidar, 0.25, Eigen::Vector2d(0.001, 0.004));
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a[1].stamp, Time::from_seconds(10.26));
  EXPECT_LT((a[1].q_enu_lidar.toRotationMatrix() -
             T_enu_ins.T_world_body[1].R * q_ins_lidar.toRotationMatrix())
                .norm(),
            1e-12);
  EXPECT_NEAR(a[0].covariance(0, 0), 1e-6, 1e-18);
  EXPECT_NEAR(a[0].covariance(2, 2), 1.6e-5, 1e-18);
  for (SE3& T : T_enu_ins.T_world_body) T.R.setIdentity();
  try {
    gt::attitude_fixes(T_enu_ins, q_ins_lidar, 0.0, Eigen::Vector2d(0.001, 0.004));
    ADD_FAILURE() << "identity rotations taken as attitudes";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("carry no attitude"), std::string::npos) << e.what();
  }
  EXPECT_THROW(gt::attitude_fixes(T_enu_ins, q_ins_lidar, 0.0, Eigen::Vector2d(0.0, 0.004)), Error);
}

// A walk along a line with a 0.7 m lateral sway (less than min_spread_m across it): the sway and
// the lever arm fix the roll about the line well enough (sigma under 1 deg), and it is solved.
TEST(PoseGraph, ANearlyStraightPathHasItsRollFromItsSway) {
  Synthetic s;
  s.truth = truth_of(40, [](double t) {
    const double lateral = 0.7 * std::sin(2 * M_PI * t / 8.0);
    return SE3::from_rotation_vector(
        Eigen::Vector3d(0, 0, 0.5),
        Eigen::Vector3d(std::cos(0.5) * t - std::sin(0.5) * lateral,
                        std::sin(0.5) * t + std::cos(0.5) * lateral, 0));
  });
  s.make(1e-4, 1e-3, 0.02, [](double) { return true; });
  const gt::PoseGraphResult r =
      gt::solve_pose_graph(s.odometry, s.fixes, s.p_lidar_antenna, gt::PoseGraphConfig{});
  ASSERT_EQ(r.T_enu_lidar.size(), s.truth.size());
  EXPECT_TRUE(r.undetermined.empty()) << r.undetermined[0].what << ": " << r.undetermined[0].why;
  ASSERT_EQ(r.covariance.size(), s.truth.size());
  size_t within = 0;
  for (size_t k = 0; k < s.truth.size(); ++k) {
    const Eigen::Vector3d e =
        rotation_vector(r.T_enu_lidar.T_world_body[k].R * s.truth.T_world_body[k].R.transpose());
    within += e.dot(r.covariance[k].topLeftCorner<3, 3>().ldlt().solve(e)) <= 14.16;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> e(r.covariance[200].topLeftCorner<3, 3>());
  std::printf(
      "[ figures ] a 40 m path with a 0.7 m sway: weakest rotation sigma %.3f deg; "
      "rotations within 3 sigma %.1f %%\n",
      std::sqrt(e.eigenvalues()(2)) * 180 / M_PI, 100.0 * within / s.truth.size());
  EXPECT_GE(double(within), 0.95 * double(s.truth.size()));
}

TEST(PoseGraph, ASequenceStartingInAnOutageIsBridgedByTheOdometryWithGrowingSigmas) {
  Synthetic s;
  s.truth = truth_of(60, on_a_loop);
  s.make(2e-4, 3e-3, 0.02, [](double t) { return t >= 10.0; });
  const gt::PoseGraphResult r =
      gt::solve_pose_graph(s.odometry, s.fixes, s.p_lidar_antenna, gt::PoseGraphConfig{});
  ASSERT_EQ(r.T_enu_lidar.size(), s.truth.size());
  EXPECT_TRUE(r.undetermined.empty());
  ASSERT_EQ(r.outages.size(), 1u);
  EXPECT_EQ(r.outages[0].first, s.truth.stamps.front());
  EXPECT_NEAR((r.outages[0].second - s.truth.stamps.front()).seconds(), 10.0, 1e-6);
  ASSERT_EQ(r.covariance.size(), s.truth.size());
  // The sigmas grow into the outage, backwards from its end; the errors stay inside them.
  auto sigma = [&](size_t k) {
    return std::sqrt(r.covariance[k].bottomRightCorner<3, 3>().trace());
  };
  EXPECT_GT(sigma(0), sigma(50));
  EXPECT_GT(sigma(50), sigma(100));
  EXPECT_GT(sigma(0), 5 * sigma(300));
  size_t within = 0;
  std::vector<double> start_errors;
  for (size_t k = 0; k < s.truth.size(); ++k) {
    const Eigen::Vector3d e = r.T_enu_lidar.T_world_body[k].t - s.truth.T_world_body[k].t;
    within += e.dot(r.covariance[k].bottomRightCorner<3, 3>().ldlt().solve(e)) <= 14.16;
    if (k < 100) start_errors.push_back(e.norm());
  }
  std::printf(
      "[ figures ] a 10 s outage at the start: position sigma at 0 s %.1f mm, 5 s %.1f mm, "
      "30 s %.1f mm; errors in the outage rms %.1f mm; within 3 sigma %.1f %%\n",
      1e3 * sigma(0), 1e3 * sigma(50), 1e3 * sigma(300), 1e3 * rms(start_errors),
      100.0 * double(within) / double(s.truth.size()));
  EXPECT_GE(double(within), 0.95 * double(s.truth.size()));
}

TEST(PoseGraph, PositionFixesTakeTheReceiversSigmasItsStatesAndTheClockOffset) {
  Trajectory T_enu_gnss;
  for (int i = 0; i < 4; ++i) {
    T_enu_gnss.stamps.push_back(Time::from_seconds(10.0 + i));
    T_enu_gnss.T_world_body.push_back(
        SE3::from_rotation_vector(Eigen::Vector3d::Zero(), Eigen::Vector3d(i, 0, 0)));
  }
  const gt::PoseGraphConfig config;
  // NavSatFix states: 2 (GBAS: RTK fixed), 1 (SBAS), -1 (no fix: left out), 0 (single).
  const std::vector<gt::PositionFix> f =
      gt::position_fixes(T_enu_gnss, {}, {2, 1, -1, 0}, 0.25, config);
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[0].quality, gt::FixQuality::rtk_fixed);
  EXPECT_EQ(f[1].quality, gt::FixQuality::single);
  EXPECT_EQ(f[2].quality, gt::FixQuality::single);
  EXPECT_DOUBLE_EQ(f[2].p_enu.x(), 3.0);
  EXPECT_EQ(f[0].stamp, Time::from_seconds(10.25));
  EXPECT_NEAR(std::sqrt(f[0].covariance(0, 0)), config.sigma_rtk_fixed.x(), 1e-12);
  EXPECT_NEAR(std::sqrt(f[0].covariance(2, 2)), config.sigma_rtk_fixed.y(), 1e-12);
  EXPECT_NEAR(std::sqrt(f[1].covariance(1, 1)), config.sigma_single.x(), 1e-12);
  // The receiver's own standard deviations win over its state.
  const std::vector<Eigen::Vector3d> sd(4, Eigen::Vector3d(0.01, 0.02, 0.05));
  const std::vector<gt::PositionFix> g = gt::position_fixes(T_enu_gnss, sd, {}, 0.0, config);
  ASSERT_EQ(g.size(), 4u);
  EXPECT_NEAR(g[3].covariance(1, 1), 0.02 * 0.02, 1e-15);
  EXPECT_NEAR(g[3].covariance(2, 2), 0.05 * 0.05, 1e-15);
  // Zeros (NavSatFix's covariance type unknown): the state's sigmas.
  std::vector<Eigen::Vector3d> unknown = sd;
  unknown[1].setZero();
  const std::vector<gt::PositionFix> u =
      gt::position_fixes(T_enu_gnss, unknown, {2, 0, 2, 2}, 0.0, config);
  EXPECT_NEAR(std::sqrt(u[1].covariance(0, 0)), config.sigma_single.x(), 1e-12);
  EXPECT_NEAR(u[0].covariance(0, 0), 0.01 * 0.01, 1e-15);
  EXPECT_THROW(gt::position_fixes(T_enu_gnss, {sd[0]}, {}, 0.0, config), Error);
  EXPECT_THROW(gt::position_fixes(T_enu_gnss, {}, {2, 2}, 0.0, config), Error);
  // The solution's type wins over the status (which cannot tell RTK float from fixed); a fix
  // the status calls no fix stays out; the receiver's sigmas still win over the type's.
  using Q = gt::FixQuality;
  const std::vector<Q> types = {Q::rtk_float, Q::single, Q::rtk_fixed, Q::rtk_fixed};
  const std::vector<gt::PositionFix> q =
      gt::position_fixes(T_enu_gnss, {}, {2, 2, -1, 0}, 0.0, config, types);
  ASSERT_EQ(q.size(), 3u);
  EXPECT_EQ(q[0].quality, Q::rtk_float);
  EXPECT_EQ(q[1].quality, Q::single);
  EXPECT_EQ(q[2].quality, Q::rtk_fixed);
  EXPECT_NEAR(std::sqrt(q[0].covariance(0, 0)), config.sigma_rtk_float.x(), 1e-12);
  EXPECT_NEAR(std::sqrt(q[0].covariance(2, 2)), config.sigma_rtk_float.y(), 1e-12);
  EXPECT_NEAR(std::sqrt(q[1].covariance(2, 2)), config.sigma_single.y(), 1e-12);
  const std::vector<gt::PositionFix> qs =
      gt::position_fixes(T_enu_gnss, unknown, {}, 0.0, config, types);
  EXPECT_NEAR(qs[0].covariance(0, 0), 0.01 * 0.01, 1e-15);  // its sigmas, not float's
  EXPECT_NEAR(std::sqrt(qs[1].covariance(0, 0)), config.sigma_single.x(), 1e-12);  // zeros
  EXPECT_THROW(gt::position_fixes(T_enu_gnss, {}, {}, 0.0, config, {Q::single}), Error);
  // The receiver's whole covariance (NavSatFix's, type known) is kept whole; a fix whose
  // sigmas are zeros (not known) still takes its state's.
  Eigen::Matrix3d C;
  C << 4e-4, 3e-4, 1e-4, 3e-4, 9e-4, -2e-4, 1e-4, -2e-4, 25e-4;
  const std::vector<gt::PositionFix> w = gt::position_fixes(T_enu_gnss, unknown, {}, 0.0, config,
                                                            {}, std::vector<Eigen::Matrix3d>(4, C));
  EXPECT_EQ(w[0].covariance, C);
  EXPECT_NEAR(std::sqrt(w[1].covariance(0, 0)), config.sigma_rtk_fixed.x(), 1e-12);
  EXPECT_EQ(w[1].covariance(0, 1), 0.0);
  EXPECT_THROW(gt::position_fixes(T_enu_gnss, sd, {}, 0.0, config, {}, {C}), Error);
}

// The fixes CSV read for positions (the ground truth's reading): no attitude columns needed, the
// receiver's sigmas and NavSatFix's status kept, bad ones refused with their line.
TEST(GnssFixesCsv, PositionsOnlyNeedNoAttitudeAndKeepSigmasAndStatus) {
  const std::string text =
      "time,latitude,longitude,height,status,std_east,std_north,std_up\n"
      "100.0,41.9,12.5,50.0,2,0.01,0.02,0.03\n"
      "100.1,41.9000009,12.5,50.0,-1,0,0,0\n";
  const io::GnssFixes f = io::parse_gnss_fixes(text, "f.csv", std::nullopt);
  EXPECT_FALSE(f.has_attitude);
  ASSERT_EQ(f.T_enu_gnss.size(), 2u);
  EXPECT_NEAR(f.T_enu_gnss.T_world_body[1].t.y(), 0.1, 1e-3);  // 0.0000009 deg of latitude
  EXPECT_TRUE(f.T_enu_gnss.T_world_body[1].R.isIdentity());
  ASSERT_EQ(f.status, (std::vector<int>{2, -1}));
  ASSERT_EQ(f.std_enu_m.size(), 2u);
  EXPECT_EQ(f.std_enu_m[0], Eigen::Vector3d(0.01, 0.02, 0.03));
  // With an attitude convention, the attitude columns are required again.
  EXPECT_THROW(io::parse_gnss_fixes(text, "f.csv", io::Attitude::enu), Error);
  auto message = [](const std::string& csv) {
    try {
      io::parse_gnss_fixes(csv, "f.csv", std::nullopt);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("time,latitude,longitude,height,status\n1,41.9,12.5,5,3\n").find("f.csv:2"),
            std::string::npos);
  EXPECT_NE(
      message("time,latitude,longitude,height,std_east,std_north,std_up\n1,41.9,12.5,5,-1,1,1\n")
          .find("standard deviations"),
      std::string::npos);
  EXPECT_NE(message("time,latitude,height\n1,41.9,5\n").find("'longitude'"), std::string::npos);
  // The covariance's terms off the diagonal (navsat.csv's), read with the sigmas into the whole
  // matrix; numbers that make no covariance refused with their line.
  const io::GnssFixes c = io::parse_gnss_fixes(
      "time,latitude,longitude,height,std_east,std_north,std_up,cov_en,cov_eu,cov_nu\n"
      "1,41.9,12.5,5,0.02,0.03,0.05,0.0003,0.0001,-0.0002\n",
      "f.csv", std::nullopt);
  ASSERT_EQ(c.covariance_enu_m2.size(), 1u);
  EXPECT_NEAR(c.covariance_enu_m2[0](1, 1), 0.0009, 1e-15);
  EXPECT_EQ(c.covariance_enu_m2[0](1, 0), 0.0003);
  EXPECT_EQ(c.covariance_enu_m2[0](2, 1), -0.0002);
  EXPECT_TRUE(f.covariance_enu_m2.empty()) << "no off-diagonal columns: the sigmas alone";
  const std::string bad = message(
      "time,latitude,longitude,height,std_east,std_north,std_up,cov_en,cov_eu,cov_nu\n"
      "1,41.9,12.5,5,0.02,0.03,0.05,0.001,0,0\n");
  EXPECT_EQ(bad.rfind("f.csv:2: cov_en 0.001 cov_eu 0 cov_nu 0 with standard deviations 0.02 "
                      "0.03 0.05: not a covariance",
                      0),
            0u)
      << bad;
}

// The solution's type (fix_type, q or quality): RTKLIB's Q codes or words; anything else refused
// with its line. The writer's fixes read back to the same ENU positions at the same origin.
TEST(GnssFixesCsv, FixTypesReadAsCodesOrWordsAndTheWrittenFixesReadBack) {
  using T = io::FixType;
  const io::GnssFixes f = io::parse_gnss_fixes(
      "time,latitude,longitude,height,Q\n1,41.9,12.5,50,1\n2,41.9,12.5,50,2\n3,41.9,12.5,50,5\n"
      "4,41.9,12.5,50,3\n5,41.9,12.5,50,4\n6,41.9,12.5,50,6\n7,41.9,12.5,50,Float\n"
      "8,41.9,12.5,50,fixed\n9,41.9,12.5,50,single\n",
      "f.csv", std::nullopt);
  EXPECT_EQ(f.fix_type, (std::vector<T>{T::rtk_fixed, T::rtk_float, T::single, T::single, T::single,
                                        T::rtk_float, T::rtk_float, T::rtk_fixed, T::single}));
  EXPECT_TRUE(f.status.empty());
  for (const std::string bad : {"0", "7", "rtk", ""}) {
    try {
      io::parse_gnss_fixes(
          "time,lat,lon,height,fix_type\n1,41.9,12.5,50,1\n2,41.9,12.5,50," + bad + "\n", "f.csv",
          std::nullopt);
      ADD_FAILURE() << "accepted fix type '" << bad << "'";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("f.csv:3"), std::string::npos) << e.what();
    }
  }
  // The origin: three numbers within their ranges.
  const io::GeodeticOrigin o = io::parse_geodetic_origin(" 41.89021, 12.492231,69", "--enu-origin");
  EXPECT_DOUBLE_EQ(o.latitude_deg, 41.89021);
  EXPECT_DOUBLE_EQ(o.longitude_deg, 12.492231);
  EXPECT_DOUBLE_EQ(o.height_m, 69.0);
  for (const char* bad :
       {"41.9,12.5", "41.9,12.5,50,1", "91,12.5,50", "41.9,x,50", "41.9,12.5,1e6"})
    EXPECT_THROW(io::parse_geodetic_origin(bad, "--enu-origin"), Error) << bad;
  // Written and read back at the same origin: the positions within 0.1 mm, everything else kept.
  Trajectory T_enu_gnss;
  std::vector<Eigen::Vector3d> sd;
  std::vector<T> types;
  for (int i = 0; i < 5; ++i) {
    T_enu_gnss.stamps.push_back(Time::from_seconds(1000.0 + 0.01 * i));
    T_enu_gnss.T_world_body.push_back(SE3::from_rotation_vector(
        Eigen::Vector3d::Zero(), Eigen::Vector3d(300.0 * i, -80.0 * i, 3.0 * i)));
    sd.emplace_back(0.01 * (i + 1), 0.01 * (i + 1), 0.02 * (i + 1));
    types.push_back(i < 2 ? T::rtk_fixed : i < 4 ? T::rtk_float : T::single);
  }
  const std::string csv = io::gnss_fixes_csv(T_enu_gnss, sd, types, o);
  const io::GnssFixes back = io::parse_gnss_fixes(csv, "w.csv", std::nullopt, o);
  ASSERT_EQ(back.T_enu_gnss.size(), 5u);
  for (size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(back.T_enu_gnss.stamps[i], T_enu_gnss.stamps[i]);
    EXPECT_LT((back.T_enu_gnss.T_world_body[i].t - T_enu_gnss.T_world_body[i].t).norm(), 1e-4);
    EXPECT_LT((back.std_enu_m[i] - sd[i]).norm(), 1e-9);
  }
  EXPECT_EQ(back.fix_type, types);
  EXPECT_EQ(back.status, (std::vector<int>{2, 2, 2, 2, 0}));
  // At the first fix instead: the first position at the origin.
  EXPECT_LT(io::parse_gnss_fixes(csv, "w.csv", std::nullopt).T_enu_gnss.T_world_body[0].t.norm(),
            1e-4);
}

// `rigcal ground-truth` on files: an odometry with its step covariances, GNSS/INS poses, the rig.
// The correlation time of residuals that are the fixes' errors themselves: a first-order
// Gauss-Markov error (5 s) comes out near 5 s, outages and all, and with spans of fixes a
// hundred times worse (float or single: their residuals in their own sigmas); white errors give
// 0.
TEST(PoseGraph, TheFixesCorrelationTimeFromResiduals) {
  std::vector<gt::PositionFix> fixes;
  auto series = [&fixes](double tau, uint64_t seed, double worse = 1.0) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> N(0.0, 1.0);
    const double dt = 0.1, a = tau > 0 ? std::exp(-dt / tau) : 0.0;
    std::vector<gt::PriorResidual> priors;
    fixes.clear();
    Eigen::Vector3d e(N(rng), N(rng), N(rng));
    for (int k = 0; k < 6000; ++k) {
      e = a * e + std::sqrt(1 - a * a) * Eigen::Vector3d(N(rng), N(rng), N(rng));
      if (k >= 2000 && k < 2300) continue;  // a 30 s outage
      // 2 s of worse fixes every minute, the same error process scaled by their sigma.
      const double sigma = 0.01 * (k % 600 < 20 ? worse : 1.0);
      gt::PriorResidual p;
      p.stamp = Time::from_seconds(100 + dt * k);
      p.residual_enu = sigma * e;
      p.rejected = k % 97 == 0;  // rejected priors are left out
      p.fix = fixes.size();
      fixes.push_back({p.stamp, Eigen::Vector3d::Zero(),
                       sigma * sigma * Eigen::Matrix3d::Identity(), gt::FixQuality::rtk_fixed});
      priors.push_back(p);
    }
    return priors;
  };
  std::vector<double> estimates, mixed, unwhitened;
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    auto priors = series(5.0, seed);
    estimates.push_back(gt::estimate_fix_correlation(priors, fixes));
    priors = series(5.0, seed, 100.0);
    mixed.push_back(gt::estimate_fix_correlation(priors, fixes));
    std::vector<gt::PositionFix> alike = fixes;  // every fix said to be as good as the others
    for (gt::PositionFix& f : alike) f.covariance = 1e-4 * Eigen::Matrix3d::Identity();
    unwhitened.push_back(gt::estimate_fix_correlation(priors, alike));
    priors = series(0.0, seed);
    EXPECT_EQ(gt::estimate_fix_correlation(priors, fixes), 0.0);
  }
  std::printf("[ figures ] 10 min of fixes correlated over 5 s: estimated");
  for (double e : estimates) std::printf(" %.1f", e);
  std::printf(" s; with 2 s a minute of fixes 100 times worse:");
  for (double e : mixed) std::printf(" %.1f", e);
  std::printf(" s (taken alike:");
  for (double e : unwhitened) std::printf(" %.1f", e);
  std::printf(" s)\n");
  // Ten minutes hold about 120 correlation times: the autocorrelation's crossing scatters by
  // about 15 % (seeds 1-5: 5.7, 5.6, 4.4, 6.0, 4.5 s). Taken alike (not divided by their
  // sigmas), the worse fixes' residuals hold most of the energy and the estimate falls at their
  // spans' edges.
  for (const std::vector<double>* v : {&estimates, &mixed}) {
    for (double e : *v) {
      EXPECT_GT(e, 3.5);
      EXPECT_LT(e, 7.0);
    }
  }
  for (double e : unwhitened) EXPECT_LT(e, 3.5);
  EXPECT_EQ(gt::estimate_fix_correlation({}, {}), 0.0);
}

// Fixes whose errors wander over 5 s (1 % multipath, a 20 s outage; three-minute walks whose
// odometry has no scale error, so that its covariance says all it errs by): their error as a
// Gauss-Markov state of the graph anchors the trajectory better than scaling each prior's
// covariance does, with the true correlation time given; the time and the white share found by
// the marginal likelihood come out near the truth (5 s, none) and anchor as well; the sigmas
// stay honest.
TEST(PoseGraph, CorrelatedFixesAsAStateAnchorBetterThanScaledCovariances) {
  std::vector<double> ate_scaled, ate_states, ate_independent, ate_ml, tau_ml, white_ml;
  size_t within = 0, poses = 0;
  for (uint64_t seed = 1; seed <= 2; ++seed) {
    Scenario s;
    s.config.seed = seed;
    s.config.trajectory_duration_s = 180;
    s.config.gnss.correlation_time_s = 5.0;
    s.config.gnss.outages = {{60.0, 80.0}};
    s.config.gnss.outlier_probability = 0.01;
    s.config.odometry.scale_error = 0;
    s.simulate();
    auto ate = [&](const gt::PoseGraphResult& r) {
      std::vector<double> e;
      for (size_t k = 0; k < s.truth_enu.size(); ++k)
        e.push_back((r.T_enu_lidar.T_world_body[k].t - s.truth_enu.T_world_body[k].t).norm());
      return rms(e);
    };
    gt::PoseGraphConfig c;
    ate_independent.push_back(ate(gt::solve_pose_graph(s.odometry, s.fixes, s.p_lidar_antenna, c)));
    c.fix_correlation_s = 5.0;
    c.fix_error_states = false;
    ate_scaled.push_back(ate(gt::solve_pose_graph(s.odometry, s.fixes, s.p_lidar_antenna, c)));
    c.fix_error_states = true;
    ate_states.push_back(ate(gt::solve_pose_graph(s.odometry, s.fixes, s.p_lidar_antenna, c)));
    c.fix_correlation_s = 2.0;  // the gate's solve with a time as poorly estimated as residuals do
    c.fix_correlation_by_likelihood = true;
    const gt::PoseGraphResult r = gt::solve_pose_graph(s.odometry, s.fixes, s.p_lidar_antenna, c);
    ate_ml.push_back(ate(r));
    tau_ml.push_back(r.fix_correlation_s);
    white_ml.push_back(r.fix_white_fraction);
    ASSERT_EQ(r.covariance.size(), s.truth_enu.size());
    for (size_t k = 0; k < s.truth_enu.size(); ++k) {
      const Eigen::Vector3d e = r.T_enu_lidar.T_world_body[k].t - s.truth_enu.T_world_body[k].t;
      within += e.dot(r.covariance[k].bottomRightCorner<3, 3>().ldlt().solve(e)) <= 14.16;
      ++poses;
    }
  }
  std::printf("[ figures ] ATE rms in ENU (mm), seeds 1-2: fixes independent");
  for (double e : ate_independent) std::printf(" %.1f", 1e3 * e);
  std::printf("; with the true 5 s, covariances scaled");
  for (double e : ate_scaled) std::printf(" %.1f", 1e3 * e);
  std::printf(", error states");
  for (double e : ate_states) std::printf(" %.1f", 1e3 * e);
  std::printf("; error states, the most likely time and white share:");
  for (size_t i = 0; i < tau_ml.size(); ++i)
    std::printf(" %.1f s, %.4f: %.1f;", tau_ml[i], white_ml[i], 1e3 * ate_ml[i]);
  std::printf(" positions within 3 sigma %.1f %%\n", 100.0 * within / poses);
  auto sum = [](const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); };
  EXPECT_LT(sum(ate_states), sum(ate_scaled));
  EXPECT_LT(sum(ate_ml), sum(ate_scaled));
  for (size_t i = 0; i < tau_ml.size(); ++i) {
    EXPECT_GT(tau_ml[i], 3.5);
    EXPECT_LT(tau_ml[i], 7.5);
    EXPECT_LT(white_ml[i], 0.02);
  }
  EXPECT_GE(double(within), 0.95 * double(poses));
}

// Two estimates of 2000 motions, each step's errors drawn from its own covariance: a good along
// x and in yaw, poor along y; b the other way round (the car's odometry along the road, the
// adjustment across). Fused a step at a time by covariance intersection: better than either in
// every direction they are not both poor in, and the fused sigmas honest; with one estimate
// better in every direction, the weight goes to it alone; with one claiming less noise than it
// has, no fusion.
TEST(MotionFusion, CovarianceIntersectionTakesTheBetterEstimateInEachDirection) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> N(0.0, 1.0);
  using Vector6d = Eigen::Matrix<double, 6, 1>;
  auto draw = [&](const Vector6d& sigma) {
    Vector6d e;
    for (int i = 0; i < 6; ++i) e[i] = sigma[i] * N(rng);
    return e;
  };
  Vector6d sigma_a, sigma_b;
  sigma_a << 0.001, 0.001, 0.0002, 0.001, 0.02, 0.005;  // rotation (rad), translation (m)
  sigma_b << 0.001, 0.001, 0.002, 0.02, 0.002, 0.005;
  const size_t n = 2000;
  gt::OdometryInput a, b;
  std::vector<SE3> truth_steps;
  for (gt::OdometryInput* o : {&a, &b}) o->T_odom_lidar.T_world_body.push_back(SE3{});
  for (size_t k = 0; k <= n; ++k) {
    a.T_odom_lidar.stamps.push_back(Time::from_seconds(0.1 * double(k)));
    if (k == n) break;
    const SE3 step = SE3::from_rotation_vector(Eigen::Vector3d(0.01, -0.02, 0.05 * N(rng)),
                                               Eigen::Vector3d(0.8, 0.05 * N(rng), 0.01));
    truth_steps.push_back(step);
    a.T_odom_lidar.T_world_body.push_back(a.T_odom_lidar.T_world_body.back() *
                                          perturbed(step, draw(sigma_a)));
    b.T_odom_lidar.T_world_body.push_back(b.T_odom_lidar.T_world_body.back() *
                                          perturbed(step, draw(sigma_b)));
    a.step_covariance.push_back(sigma_a.cwiseAbs2().asDiagonal());
    b.step_covariance.push_back(sigma_b.cwiseAbs2().asDiagonal());
  }
  b.T_odom_lidar.stamps = a.T_odom_lidar.stamps;
  const gt::FusedMotions fused = gt::fuse_motions(a, b);
  ASSERT_EQ(fused.motions.T_odom_lidar.size(), n + 1);
  ASSERT_EQ(fused.weight_a.size(), n);
  // The errors of each estimate's steps, per axis, and the fused one's within its 3 sigma.
  Vector6d sq_a = Vector6d::Zero(), sq_b = sq_a, sq_f = sq_a;
  size_t within = 0;
  auto error = [](const Trajectory& t, size_t k, const SE3& truth) {
    const SE3 m = t.T_world_body[k].inverse() * t.T_world_body[k + 1];
    Vector6d d;
    d << rotation_vector(m.R * truth.R.transpose()), m.t - truth.t;
    return d;
  };
  for (size_t k = 0; k < n; ++k) {
    sq_a += error(a.T_odom_lidar, k, truth_steps[k]).cwiseAbs2();
    sq_b += error(b.T_odom_lidar, k, truth_steps[k]).cwiseAbs2();
    const Vector6d e = error(fused.motions.T_odom_lidar, k, truth_steps[k]);
    sq_f += e.cwiseAbs2();
    const Vector6d sigma = fused.motions.step_covariance[k].diagonal().cwiseSqrt();
    for (int i = 0; i < 6; ++i) within += std::abs(e[i]) < 3 * sigma[i];
  }
  const Vector6d rms_a = (sq_a / double(n)).cwiseSqrt(), rms_b = (sq_b / double(n)).cwiseSqrt(),
                 rms_f = (sq_f / double(n)).cwiseSqrt();
  std::printf(
      "[ figures ] step errors rms, yaw (mrad), x, y (mm): a %.3f %.2f %.2f, b %.3f %.2f "
      "%.2f, fused %.3f %.2f %.2f; weight on a %.2f; within 3 sigma %.1f %%\n",
      1e3 * rms_a[2], 1e3 * rms_a[3], 1e3 * rms_a[4], 1e3 * rms_b[2], 1e3 * rms_b[3],
      1e3 * rms_b[4], 1e3 * rms_f[2], 1e3 * rms_f[3], 1e3 * rms_f[4], fused.weight_a[0],
      100.0 * double(within) / double(6 * n));
  // Each of yaw, x and y within 1.6 times the better estimate's (covariance intersection gives
  // up part of each one's information to stay consistent), and far better than the worse one's.
  for (int i : {2, 3, 4}) {
    EXPECT_LT(rms_f[i], 1.6 * std::min(rms_a[i], rms_b[i])) << "axis " << i;
    EXPECT_LT(rms_f[i], 0.5 * std::max(rms_a[i], rms_b[i])) << "axis " << i;
  }
  EXPECT_GE(double(within) / double(6 * n), 0.99);
  EXPECT_TRUE(fused.fused);
  EXPECT_LT(fused.disagreeing_fraction, 0.02);
  // a claiming a tenth of the noise it has: the covariances' test refuses the fusion.
  gt::OdometryInput overconfident = a;
  for (gt::Matrix6d& c : overconfident.step_covariance) c *= 0.01;
  const gt::FusedMotions refused = gt::fuse_motions(overconfident, b);
  EXPECT_FALSE(refused.fused);
  EXPECT_GT(refused.disagreeing_fraction, 0.5);
  EXPECT_LT(
      (refused.motions.T_odom_lidar.T_world_body[n].t - b.T_odom_lidar.T_world_body[n].t).norm(),
      1e-12);
  // b better than a in every direction: b alone (its motions chained again: round-off only).
  gt::OdometryInput worse = a;
  for (gt::Matrix6d& c : worse.step_covariance) c = 100.0 * b.step_covariance[0];
  const gt::FusedMotions b_alone = gt::fuse_motions(worse, b);
  EXPECT_EQ(b_alone.weight_a[0], 0.0);
  EXPECT_LT(
      (b_alone.motions.T_odom_lidar.T_world_body[n].t - b.T_odom_lidar.T_world_body[n].t).norm(),
      1e-7);
  // Not the same poses: refused.
  gt::OdometryInput shifted = b;
  shifted.T_odom_lidar.stamps[3] = shifted.T_odom_lidar.stamps[3] + Time::from_seconds(0.01);
  EXPECT_THROW(gt::fuse_motions(a, shifted), Error);
}

TEST(GroundTruthCli, WritesVbrsFormatAndSigmasRefusesBadInputAndSaysWhatIsUndetermined) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / fmt::format("rigcal_gt_cli_{}", ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir / "rec");
  Scenario s;
  s.config.trajectory_duration_s = 30;
  s.simulate();
  std::vector<io::StepCovariance> steps;
  for (size_t k = 0; k + 1 < s.odometry.T_odom_lidar.size(); ++k)
    steps.push_back({s.odometry.T_odom_lidar.stamps[k], s.odometry.T_odom_lidar.stamps[k + 1],
                     s.odometry.step_covariance[k]});
  auto write = [](const fs::path& p, const std::string& text) { std::ofstream(p) << text; };
  write(dir / "odom.tum", io::trajectory_to_tum(s.odometry.T_odom_lidar));
  write(dir / "odom_covariances.txt", io::step_covariances_to_text(steps));
  write(dir / "rec/poses.tum", io::trajectory_to_tum(s.part.gnss));
  const std::string common = fmt::format("ground-truth {0}/rec --rig {1}/data/sample_rig.yaml",
                                         dir.string(), RIGCAL_SOURCE_DIR);
  testing::CliRun r =
      testing::rigcal_cli(common + fmt::format(" --odometry {0}/odom.tum --gnss {0}/rec/poses.tum "
                                               "--out {0}/seq_gt.txt --report {0}/report",
                                               dir.string()),
                          dir);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("priors"), std::string::npos) << r.out;
  const std::string gt_text = testing::slurp(dir / "seq_gt.txt");
  EXPECT_EQ(gt_text.substr(0, gt_text.find('\n')), "#timestamp tx ty tz qx qy qz qw");
  EXPECT_TRUE(fs::exists(dir / "seq_gt_sigmas.txt"));
  const nlohmann::json report =
      nlohmann::json::parse(testing::slurp(dir / "report/ground_truth.json"));
  EXPECT_EQ(report["summary"]["poses"].get<size_t>(), s.truth_enu.size());
  EXPECT_EQ(report["priors"].size(), report["summary"]["priors"].get<size_t>());
  // The page a person reads beside the JSON (no markers here: the sigmas are the word), with
  // the top view; `rigcal report` renders it again the same from the two.
  const std::string page = testing::slurp(dir / "report/report.html");
  EXPECT_NE(page.find("No markers surveyed"), std::string::npos);
  for (const char* text : {"id=\"summary\"", "id=\"priors\"", "The ground truth from above",
                           "The GNSS priors' residuals"})
    EXPECT_NE(page.find(text), std::string::npos) << text;
  EXPECT_TRUE(fs::exists(dir / "report/trajectory_top.svg"));
  fs::remove(dir / "report/report.html");
  EXPECT_EQ(testing::rigcal_cli(fmt::format("report {}/report", dir.string()), dir).status, 0);
  EXPECT_EQ(testing::slurp(dir / "report/report.html"), page);
  // Read back, against the truth.
  const Trajectory gt = io::read_trajectory(dir / "seq_gt.txt").trajectory;
  ASSERT_EQ(gt.size(), s.truth_enu.size());
  std::vector<double> errors;
  for (size_t k = 0; k < gt.size(); ++k) {
    EXPECT_EQ(gt.stamps[k], s.truth_enu.stamps[k]);
    errors.push_back((gt.T_world_body[k].t - s.truth_enu.T_world_body[k].t).norm());
  }
  EXPECT_LT(rms(errors), 0.03);

  // No covariances beside the odometry: refused, saying what is missing; nothing written.
  fs::rename(dir / "odom_covariances.txt", dir / "c.txt");
  r = testing::rigcal_cli(common + fmt::format(" --odometry {0}/odom.tum --gnss {0}/rec/poses.tum "
                                               "--out {0}/x_gt.txt",
                                               dir.string()),
                          dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("no step covariances"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "x_gt.txt"));
  // An output over an input: refused.
  r = testing::rigcal_cli(common + fmt::format(" --odometry {0}/odom.tum --covariances {0}/c.txt "
                                               "--gnss {0}/rec/poses.tum --out {0}/rec/poses.tum",
                                               dir.string()),
                          dir);
  EXPECT_EQ(r.status, 2) << r.err;
  // Fixes an hour off the scans' clock: exit 3, undetermined, no trajectory written.
  Trajectory late = s.part.gnss;
  for (Time& t : late.stamps) t = t + Time::from_seconds(3600);
  write(dir / "late.tum", io::trajectory_to_tum(late));
  r = testing::rigcal_cli(common + fmt::format(" --odometry {0}/odom.tum --covariances {0}/c.txt "
                                               "--gnss {0}/late.tum --out {0}/y_gt.txt "
                                               "--report {0}/late_report",
                                               dir.string()),
                          dir);
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("undetermined: every pose"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "y_gt.txt"));
  EXPECT_TRUE(fs::exists(dir / "late_report/ground_truth.json"));
  // Its page says what is undetermined first.
  const std::string late_page = testing::slurp(dir / "late_report/report.html");
  EXPECT_NE(late_page.find("the data do not determine"), std::string::npos);
  EXPECT_NE(late_page.find("<ul class=\"warning\">"), std::string::npos);
  // The same fixes as a CSV (RTK fixed, the default sigmas) at a given origin with --enu-origin:
  // the same trajectory, in the same frame.
  const std::vector<Eigen::Vector3d> sd(s.part.gnss.size(), Eigen::Vector3d(0.02, 0.02, 0.03));
  write(dir / "fixes.csv",
        io::gnss_fixes_csv(s.part.gnss, sd,
                           std::vector<io::FixType>(s.part.gnss.size(), io::FixType::rtk_fixed),
                           {41.89021, 12.492231, 69.0}));
  r = testing::rigcal_cli(common + fmt::format(" --odometry {0}/odom.tum --covariances {0}/c.txt "
                                               "--gnss {0}/fixes.csv --out {0}/z_gt.txt "
                                               "--enu-origin 41.89021,12.492231,69",
                                               dir.string()),
                          dir);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const Trajectory from_fixes = io::read_trajectory(dir / "z_gt.txt").trajectory;
  ASSERT_EQ(from_fixes.size(), gt.size());
  for (size_t k = 0; k < gt.size(); k += 17)
    EXPECT_LT((from_fixes.T_world_body[k].t - gt.T_world_body[k].t).norm(), 1e-3) << k;
  // The same fixes with their fix states and no standard deviations: the note names the sigmas
  // each state is given.
  {
    std::istringstream in(testing::slurp(dir / "fixes.csv"));
    std::string line, states;
    while (std::getline(in, line)) {
      const std::vector<std::string_view> f = split_fields(line);
      ASSERT_EQ(f.size(), 9u) << line;
      states += fmt::format("{},{},{},{},{}\n", f[0], f[1], f[2], f[3], f[8]);
    }
    write(dir / "states.csv", states);
  }
  r = testing::rigcal_cli(common + fmt::format(" --odometry {0}/odom.tum --covariances {0}/c.txt "
                                               "--gnss {0}/states.csv --out {0}/s_gt.txt "
                                               "--enu-origin 41.89021,12.492231,69",
                                               dir.string()),
                          dir);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_NE((r.out + r.err).find("by its fix state: RTK fixed 0.02 / 0.03 m, float 0.3 / 0.5 m"),
            std::string::npos)
      << r.out << r.err;
  // An origin for poses already in ENU, or not three numbers: refused.
  r = testing::rigcal_cli(common + fmt::format(" --odometry {0}/odom.tum --covariances {0}/c.txt "
                                               "--gnss {0}/rec/poses.tum --out {0}/w_gt.txt "
                                               "--enu-origin 41.89021,12.492231,69",
                                               dir.string()),
                          dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("ENU origin applies to fixes"), std::string::npos) << r.err;
  r = testing::rigcal_cli(common + fmt::format(" --odometry {0}/odom.tum --covariances {0}/c.txt "
                                               "--gnss {0}/fixes.csv --out {0}/w_gt.txt "
                                               "--enu-origin 41.89021,12.492231",
                                               dir.string()),
                          dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("LAT,LON,HEIGHT"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "w_gt.txt"));

  // The GNSS/INS poses' attitudes as priors (--attitude), with the simulator's INS noise as their
  // sigmas (0.05 deg a fix on each axis, white): taken at every scan that has an attitude on
  // each side, their residuals within that noise, and the rotations better than without them.
  r = testing::rigcal_cli(common + fmt::format(" --odometry {0}/odom.tum --covariances {0}/c.txt "
                                               "--gnss {0}/rec/poses.tum --attitude "
                                               "{0}/rec/poses.tum --attitude-sigma-deg 0.05,0.05 "
                                               "--attitude-correlation 0 --out {0}/a_gt.txt "
                                               "--report {0}/a_report",
                                               dir.string()),
                          dir);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("GNSS/INS attitudes: "), std::string::npos) << r.out;
  EXPECT_EQ((r.out + r.err).find("attitude is not used"), std::string::npos) << r.out << r.err;
  {
    const nlohmann::json a =
        nlohmann::json::parse(testing::slurp(dir / "a_report/ground_truth.json"));
    const nlohmann::json& summary = a["summary"]["attitudes"];
    EXPECT_GE(summary["priors"].get<size_t>(), s.truth_enu.size() - 2);
    EXPECT_LE(summary["priors_rejected"].get<size_t>(), s.truth_enu.size() / 100);
    EXPECT_EQ(a["attitude_priors"].size(), summary["priors"].get<size_t>());
    // Two axes of 0.05 deg: 0.071 deg rms of tilt; one: 0.05 of heading.
    EXPECT_LT(summary["residual_tilt_deg"]["rms"].get<double>(), 0.09);
    EXPECT_LT(summary["residual_heading_deg"]["rms"].get<double>(), 0.065);
    EXPECT_DOUBLE_EQ(summary["sigma_heading_deg"].get<double>(), 0.05);
    EXPECT_NE(testing::slurp(dir / "a_report/report.html").find("GNSS/INS attitudes"),
              std::string::npos);
    const Trajectory with = io::read_trajectory(dir / "a_gt.txt").trajectory;
    ASSERT_EQ(with.size(), gt.size());
    std::vector<double> deg_with, deg_without;
    for (size_t k = 0; k < gt.size(); ++k) {
      const Eigen::Matrix3d& R_true = s.truth_enu.T_world_body[k].R;
      deg_with.push_back(rotation_angle(with.T_world_body[k].R * R_true.transpose()) * 180 / M_PI);
      deg_without.push_back(rotation_angle(gt.T_world_body[k].R * R_true.transpose()) * 180 / M_PI);
    }
    std::printf("[ figures ] rotation errors rms: %.4f deg with the attitudes, %.4f without\n",
                rms(deg_with), rms(deg_without));
    EXPECT_LT(rms(deg_with), 0.5 * rms(deg_without));
  }
  // Positions written as poses (every rotation the identity): refused, the file named.
  Trajectory positions = s.part.gnss;
  for (SE3& T : positions.T_world_body) T.R.setIdentity();
  write(dir / "positions.tum", io::trajectory_to_tum(positions));
  r = testing::rigcal_cli(common + fmt::format(" --odometry {0}/odom.tum --covariances {0}/c.txt "
                                               "--gnss {0}/rec/poses.tum --attitude "
                                               "{0}/positions.tum --out {0}/b_gt.txt",
                                               dir.string()),
                          dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("positions.tum: every rotation is the identity"), std::string::npos)
      << r.err;
  // A rig whose GNSS sensor is an antenna: no attitude to take.
  {
    std::string rig = testing::slurp(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
    const size_t at = rig.find("frame: ins");
    ASSERT_NE(at, std::string::npos);
    write(dir / "antenna.yaml", rig.replace(at, 10, "frame: antenna"));
  }
  r = testing::rigcal_cli(fmt::format("ground-truth {0}/rec --rig {0}/antenna.yaml --odometry "
                                      "{0}/odom.tum --covariances {0}/c.txt --gnss "
                                      "{0}/rec/poses.tum --attitude {0}/rec/poses.tum --out "
                                      "{0}/b_gt.txt",
                                      dir.string()),
                          dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("a GNSS antenna"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "b_gt.txt"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rigcal
