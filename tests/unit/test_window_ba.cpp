// The LiDAR bundle adjustment's geometric stage (calib/gt/plane_patches, window_ba): planar
// patches of a known scene, and one window of a simulated walk's sweeps brought back onto their
// planes from perturbed poses, scored against the simulator's truth.
#include <ceres/autodiff_cost_function.h>
#include <ceres/manifold.h>
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numeric>
#include <random>

#include "rigcal/core/error.h"
#include "rigcal/core/stats.h"
#include "rigcal/gt/plane_patches.h"
#include "rigcal/gt/point_to_plane_error.h"
#include "rigcal/gt/sequence_ba.h"
#include "rigcal/gt/spherical_image.h"
#include "rigcal/gt/sweep_point_to_plane_error.h"
#include "rigcal/gt/window_ba.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/sim/session.h"

namespace rigcal {
namespace {

// A 4 m cube's ceiling and four walls, 5 mm noise across each face, and a 1 m pole (a line) in
// its middle.
TEST(PlanePatches, ABoxsFacesAreFoundFlatAndAPoleIsNot) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(-2.0, 2.0);
  std::normal_distribution<double> N(0.0, 0.005);
  std::vector<Eigen::Vector3d> points;
  const Eigen::Vector3d axes[5] = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(),
                                   -Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                   -Eigen::Vector3d::UnitY()};
  for (const Eigen::Vector3d& n : axes) {
    const Eigen::Matrix3d basis =
        Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), n).toRotationMatrix();
    for (int i = 0; i < 4000; ++i)
      points.push_back(2.0 * n + basis * Eigen::Vector3d(U(rng), U(rng), N(rng)));
  }
  const size_t face_points = points.size();
  for (int i = 0; i < 500; ++i)
    points.push_back(Eigen::Vector3d(0.5 + N(rng), 0.5 + N(rng), 0.25 * U(rng)));

  gt::PatchConfig config;
  config.max_scan_thickness_m = 0.01;  // twice the noise, as the default for the OS0's
  const std::vector<gt::PlanePatch> patches = gt::plane_patches(points, config);
  size_t in_patches = 0, off_face = 0;
  double worst = 0;  // the largest tilt in its sigmas
  for (const gt::PlanePatch& p : patches) {
    in_patches += p.members.size();
    EXPECT_LE(p.thickness_m, 0.01);
    double best = 0;  // the face the patch lies on
    for (const Eigen::Vector3d& n : axes) best = std::max(best, std::abs(p.normal.dot(n)));
    // A plane fitted to n points of noise s spread with a standard deviation w along its narrower
    // axis tilts by about s / (w sqrt(n)) (rad); more than 4 of those is a contaminated patch.
    const double w = std::sqrt(gt::fit_plane(points, p.members).variances(1));
    const double tilt_sigma = 0.005 / (w * std::sqrt(double(p.members.size())));
    const double off = std::acos(std::min(best, 1.0));
    worst = std::max(worst, off / tilt_sigma);
    off_face += off > 4 * tilt_sigma;
    for (uint32_t m : p.members) EXPECT_LT(m, face_points) << "a pole point in a plane";
  }
  std::printf(
      "[ figures ] %zu patches, %.1f %% of the faces' points in them; %zu normals tilted more than "
      "4 sigma off their face, the largest tilt %.2f sigma\n",
      patches.size(), 100.0 * double(in_patches) / double(face_points), off_face, worst);
  // A few patches at the edges hold some points of the other face within the thickness limits:
  // at most 2 % of them tilted beyond 4 sigma (none would be, by chance alone: 0.03 %).
  EXPECT_LE(double(off_face), 0.02 * double(patches.size()));
  // The points near the faces' edges and corners go to patches that straddle two faces, which
  // are not flat: they are split until too small, and dropped.
  EXPECT_GT(double(in_patches), 0.85 * double(face_points));
}

// A window of sweeps of the simulator's LiDAR along its trajectory part, each point with its
// time, and the true knots: the sensor's pose at every sweep's stamp and at the end of the last.
struct SimWindow {
  std::vector<Scan> scans;
  std::vector<SE3> truth;  // knots
  Time end;
  std::function<SE3(double)> T_world_lidar;  // the true motion, by motion time
  std::vector<double> start_s;               // each sweep's motion time
};
SimWindow sim_window(sim::MotionKind motion, size_t n) {
  const rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  sim::SimConfig config;
  config.trajectory_duration_s = 0.1 * double(n) + 0.5;
  config.trajectory_motion = motion;
  config.lidar = sim::os0_128();
  config.lidar.beams = 64;
  config.lidar.columns = 1024;
  const sim::TrajectoryPart part = sim::simulate_trajectories(rig, config);
  sim::SweepDrive drive = sim::trajectory_drive(rig, config, part);
  SimWindow w;
  w.T_world_lidar = drive.T_world_lidar;
  for (size_t k = 0; k <= n; ++k) {
    w.start_s.push_back(drive.first_s + double(drive.next) / drive.lidar.rate_hz);
    const sim::Sweep sweep = sim::next_sweep(drive);
    w.truth.push_back(sweep.T_world_lidar);
    if (k == n) {
      w.end = sweep.stamp;
      break;
    }
    Scan scan;
    scan.stamp = sweep.stamp;
    for (const sim::LidarPoint& p : sweep.points) {
      ScanPoint q;
      q.p = p.p;
      q.t_ns = p.t_ns;
      q.intensity = p.intensity;
      q.ring = p.ring;
      scan.points.push_back(q);
    }
    w.scans.push_back(std::move(scan));
  }
  return w;
}

// Every knot but the first moved by 3 cm and 0.3 deg (sigma each axis).
std::vector<SE3> perturbed(const std::vector<SE3>& truth, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> N(0.0, 1.0);
  std::vector<SE3> out = {truth[0]};
  for (size_t k = 1; k < truth.size(); ++k) {
    const Eigen::Vector3d phi(N(rng), N(rng), N(rng)), dt(N(rng), N(rng), N(rng));
    out.push_back(SE3::from_rotation_vector(0.3 * M_PI / 180 * phi, 0.03 * dt) * truth[k]);
  }
  return out;
}

// The knots' errors against the truth (the first one, held, left out), m and deg.
void knot_errors(const std::vector<SE3>& truth, const std::vector<SE3>& T_world_lidar, size_t knots,
                 std::vector<double>& trans_m, std::vector<double>& rot_deg) {
  trans_m.clear();
  rot_deg.clear();
  for (size_t k = 1; k < knots; ++k) {
    const SE3 e = truth[k].inverse() * T_world_lidar[k];
    trans_m.push_back(e.t.norm());
    rot_deg.push_back(rotation_angle(e.R) * 180 / M_PI);
  }
}
double max_of(const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); }

// The written-out Jacobians of the point-to-plane terms against Ceres' automatic ones, in the
// manifolds' tangent spaces (the ambient ones may differ along the quaternion itself), at random
// knots up to 0.6 rad apart and fractions over the whole segment.
TEST(PointToPlaneCost, JacobiansMatchAutomaticDifferentiation) {
  std::mt19937_64 rng(21);
  std::normal_distribution<double> N(0.0, 1.0);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  auto vec = [&](double s) { return Eigen::Vector3d(s * N(rng), s * N(rng), s * N(rng)); };
  auto tangent = [](const double* q, const double* J_ambient) {
    Eigen::Matrix<double, 4, 3, Eigen::RowMajor> plus;
    ceres::EigenQuaternionManifold().PlusJacobian(q, plus.data());
    return Eigen::Matrix<double, 1, 3>(Eigen::Map<const Eigen::Matrix<double, 1, 4>>(J_ambient) *
                                       plus);
  };
  double worst = 0;
  constexpr int kPoints = 3;
  for (int trial = 0; trial < 200; ++trial) {
    Eigen::Quaterniond qa(rotation_from_vector(vec(1.0)));
    Eigen::Quaterniond qb(rotation_from_vector(vec(0.2)) * qa.toRotationMatrix());
    if (trial % 3 == 0) qb.coeffs() *= -1;  // the same rotation, the other sign
    Eigen::Vector3d ta = vec(5.0), tb = ta + vec(0.2);
    Eigen::Vector4d plane;
    plane << vec(1.0).normalized(), 0.1 * N(rng);
    Eigen::Matrix<double, 7, 1> knot_a, knot_b;  // the knots' blocks: quaternion, translation
    knot_a << qa.coeffs(), ta;
    knot_b << qb.coeffs(), tb;
    const Eigen::Vector3d c = vec(10.0);
    std::vector<gt::SweepPlanePointsCost::Point> points;
    std::vector<Eigen::Vector3d> rigid_points;
    for (int i = 0; i < kPoints; ++i) {
      const double f = i == 0 ? 0.0 : (trial % 5 == 0 ? 1e-9 : U(rng));
      points.push_back({vec(10.0), f});
      rigid_points.push_back(points.back().p_lidar);
    }
    const gt::SweepPlanePointsCost sweep(points, c, 100.0);
    const gt::PlanePointsCost rigid(rigid_points, c, 100.0);
    double r_ours[kPoints], r_rigid[kPoints], Ja_ours[7 * kPoints], Jb_ours[7 * kPoints],
        Jp_ours[4 * kPoints], Jra_ours[7 * kPoints], Jrp_ours[4 * kPoints];
    const double* ours_params[3] = {knot_a.data(), knot_b.data(), plane.data()};
    double* J_ours[3] = {Ja_ours, Jb_ours, Jp_ours};
    ASSERT_TRUE(sweep.Evaluate(ours_params, r_ours, J_ours));
    const double* rigid_params[2] = {knot_a.data(), plane.data()};
    double* J_rigid[2] = {Jra_ours, Jrp_ours};
    ASSERT_TRUE(rigid.Evaluate(rigid_params, r_rigid, J_rigid));
    for (int i = 0; i < kPoints; ++i) {
      const gt::SweepPointToPlaneError e{points[i].p_lidar, points[i].fraction, c, 100.0};
      const double* params[5] = {qa.coeffs().data(), ta.data(), qb.coeffs().data(), tb.data(),
                                 plane.data()};
      double r_auto = 0, J_auto[5][4];
      double* Ja[5] = {J_auto[0], J_auto[1], J_auto[2], J_auto[3], J_auto[4]};
      ceres::AutoDiffCostFunction<gt::SweepPointToPlaneError, 1, 4, 3, 4, 3, 4> automatic(
          new gt::SweepPointToPlaneError(e));
      ASSERT_TRUE(automatic.Evaluate(params, &r_auto, Ja));
      const double scale = std::abs(r_auto) + 1e3;  // w times the lever of 10 m
      EXPECT_NEAR(r_ours[i], r_auto, 1e-9 * scale);
      // Each knot's block: the quaternion's 4 (compared in the tangent), the translation's 3.
      for (int k = 0; k < 2; ++k) {
        const double* J_knot = (k == 0 ? Ja_ours : Jb_ours) + 7 * i;
        const double d =
            (tangent(params[2 * k], J_knot) - tangent(params[2 * k], J_auto[2 * k])).norm();
        worst = std::max(worst, d / scale);
        EXPECT_LT(d, 1e-7 * scale) << "trial " << trial << " point " << i << " knot " << k;
        for (int j = 0; j < 3; ++j)
          EXPECT_NEAR(J_knot[4 + j], J_auto[2 * k + 1][j], 1e-9 * scale)
              << "knot " << k << " t" << j;
      }
      for (int j = 0; j < 4; ++j) EXPECT_NEAR(Jp_ours[4 * i + j], J_auto[4][j], 1e-9 * scale);
      // Through Huber's loss at half the residual (or twice it: no change), each point alone:
      // r'^2 = 2 h |r| - h^2 and r' moves as h / r' times r.
      for (const double h : {0.5 * std::abs(r_auto), 2.0 * std::abs(r_auto)}) {
        const gt::SweepPlanePointsCost huber({points[i]}, c, 100.0, h);
        double rh = 0, Jh[3][7];
        double* Jhp[3] = {Jh[0], Jh[1], Jh[2]};
        ASSERT_TRUE(huber.Evaluate(ours_params, &rh, Jhp));
        const bool outside = std::abs(r_auto) > h;
        const double expected =
            outside ? std::copysign(std::sqrt(2 * h * std::abs(r_auto) - h * h), r_auto) : r_auto;
        EXPECT_NEAR(rh, expected, 1e-9 * scale);
        const double slope = outside ? h / std::abs(expected) : 1.0;
        for (int j = 0; j < 3; ++j) EXPECT_NEAR(Jh[0][4 + j], slope * J_auto[1][j], 1e-9 * scale);
        for (int j = 0; j < 4; ++j) EXPECT_NEAR(Jh[2][j], slope * J_auto[4][j], 1e-9 * scale);
      }
      // The rigid term, at knot a.
      const gt::PointToPlaneError rigid_e{points[i].p_lidar, c, 100.0};
      const double* rp[3] = {params[0], params[1], params[4]};
      double* Jra[3] = {J_auto[0], J_auto[1], J_auto[4]};
      ceres::AutoDiffCostFunction<gt::PointToPlaneError, 1, 4, 3, 4> rigid_automatic(
          new gt::PointToPlaneError(rigid_e));
      ASSERT_TRUE(rigid_automatic.Evaluate(rp, &r_auto, Jra));
      EXPECT_NEAR(r_rigid[i], r_auto, 1e-9 * scale);
      EXPECT_LT((tangent(params[0], Jra_ours + 7 * i) - tangent(params[0], J_auto[0])).norm(),
                1e-7 * scale);
      for (int j = 0; j < 3; ++j) EXPECT_NEAR(Jra_ours[7 * i + 4 + j], J_auto[1][j], 1e-9 * scale);
      for (int j = 0; j < 4; ++j) EXPECT_NEAR(Jrp_ours[4 * i + j], J_auto[4][j], 1e-9 * scale);
    }
  }
  std::printf("[ figures ] the largest tangent Jacobian difference, relative: %.2e\n", worst);
}

// Twenty sweeps of the simulator's hand-held calibration dance (angular rates to 3 rad/s),
// deskewed with the true continuous motion and given without point times, every pose but the
// first perturbed: the geometric adjustment alone, without the sweeps' motion to estimate.
TEST(WindowBa, DeskewedSweepsOfADanceComeBackOntoTheirPlanes) {
  const size_t n = 20;
  SimWindow w = sim_window(sim::MotionKind::handheld, n);
  for (size_t k = 0; k < n; ++k) {
    const SE3 T_lidar_world = w.truth[k].inverse();
    for (ScanPoint& p : w.scans[k].points) {
      const SE3 T_world_at = w.T_world_lidar(w.start_s[k] + 1e-9 * double(p.t_ns));
      p.p = (T_lidar_world * (T_world_at * Eigen::Vector3d(p.p.cast<double>()))).cast<float>();
      p.t_ns = 0;
    }
    w.scans[k].point_times = false;
  }
  const std::vector<SE3> initial = perturbed(w.truth, 11);
  std::vector<double> t0, r0, t1, r1;
  knot_errors(w.truth, initial, n, t0, r0);
  const gt::WindowBaResult ba = gt::window_ba(w.scans, initial, w.end, gt::WindowBaConfig{});
  knot_errors(w.truth, ba.T_world_lidar, n, t1, r1);
  std::printf(
      "[ figures ] pose errors before: %.1f mm, %.3f deg rms; after %d rounds (%zu patches, %zu "
      "residuals): %.2f mm (max %.2f), %.4f deg (max %.4f); point-plane rms %.1f -> %.1f mm\n",
      1e3 * rms(t0), rms(r0), ba.rounds, ba.patches, ba.residuals, 1e3 * rms(t1), 1e3 * max_of(t1),
      rms(r1), max_of(r1), 1e3 * ba.rms_before_m, 1e3 * ba.rms_after_m);
  EXPECT_TRUE(ba.T_world_lidar[0] == initial[0]);
  EXPECT_TRUE(ba.T_world_lidar[n] == initial[n]) << "the end knot: no point depends on it";
  EXPECT_LT(rms(t1), 0.1 * rms(t0));
  EXPECT_LT(rms(r1), 0.1 * rms(r0));
  EXPECT_LT(max_of(t1), 0.005);
  EXPECT_LT(max_of(r1), 0.05);
  // The map as crisp as the range noise (10 mm) allows.
  EXPECT_LT(ba.rms_after_m, 0.6 * ba.rms_before_m);
  EXPECT_LT(ba.rms_after_m, 0.012);
}

// Twelve raw sweeps of a walk, each point at its own time: the adjustment deskews them with the
// motion it estimates. Against it, the same sweeps deskewed once by the constant motion of the
// perturbed knots (what the adjustment does without sweep motion) and adjusted as rigid scans.
TEST(WindowBa, AWalksRawSweepsAreDeskewedByTheAdjustment) {
  const size_t n = 12;
  const SimWindow w = sim_window(sim::MotionKind::walk, n);
  const std::vector<SE3> initial = perturbed(w.truth, 12);
  std::vector<double> t0, r0, t1, r1, t2, r2;
  knot_errors(w.truth, initial, n + 1, t0, r0);

  gt::WindowBaConfig config;
  const gt::WindowBaResult at_truth = [&] {
    gt::WindowBaConfig once = config;
    once.rounds = 1;
    once.max_iterations = 0;
    return gt::window_ba(w.scans, w.truth, w.end, once);
  }();
  const gt::WindowBaResult ba = gt::window_ba(w.scans, initial, w.end, config);
  knot_errors(w.truth, ba.T_world_lidar, n + 1, t1, r1);
  gt::WindowBaConfig rigid = config;
  rigid.sweep_motion = false;
  const gt::WindowBaResult rigid_ba = gt::window_ba(w.scans, initial, w.end, rigid);
  knot_errors(w.truth, rigid_ba.T_world_lidar, n, t2, r2);
  std::printf(
      "[ figures ] at the true knots the points lie %.1f mm rms off their planes; knots before: "
      "%.1f mm, %.3f deg rms; with the sweeps' motion after %d rounds: %.2f mm (max %.2f), %.4f "
      "deg (max %.4f), point-plane %.1f -> %.1f mm; as rigid scans: %.2f mm (max %.2f), %.4f deg, "
      "point-plane %.1f mm\n",
      1e3 * at_truth.rms_before_m, 1e3 * rms(t0), rms(r0), ba.rounds, 1e3 * rms(t1),
      1e3 * max_of(t1), rms(r1), max_of(r1), 1e3 * ba.rms_before_m, 1e3 * ba.rms_after_m,
      1e3 * rms(t2), 1e3 * max_of(t2), rms(r2), 1e3 * rigid_ba.rms_after_m);
  // The interpolation between knots is not the walk's motion: the step's bob (2 cm at 1.6-1.9
  // Hz) bends a sweep's path off its chord, and the adjustment, which fits the points better
  // than the true knots do, leaves the knots a few mm off in the bob's rhythm. Over 20 sweeps
  // (seed 12): with one knot a sweep 3.7 mm rms (6.2 at most), 0.048 deg; with two (the
  // default) 2.1 mm (3.3), 0.020 deg.
  EXPECT_LT(rms(t1), 0.1 * rms(t0));
  EXPECT_LT(rms(r1), 0.1 * rms(r0));
  EXPECT_LT(max_of(t1), 0.01);
  EXPECT_LT(max_of(r1), 0.08);
  EXPECT_LT(ba.rms_after_m, at_truth.rms_before_m + 0.001);
  EXPECT_LT(rms(t1), 0.5 * rms(t2)) << "the sweeps' motion should matter on a walk";
}

// Keyframes: every third sweep of a walk, each with its own pose at its sweep's end, a gap of two
// sweeps before the next. The knots come back as close to the truth as where the sweeps follow
// each other, the motions across the gaps held by the planes the sweeps share; a pose that is
// neither a scan's stamp nor a sweep's end is refused.
TEST(WindowBa, KeyframesWithGapsBetweenThemComeBackOntoTheTruth) {
  const size_t n = 30;
  const SimWindow w = sim_window(sim::MotionKind::walk, n);
  std::vector<Scan> scans;
  std::vector<Time> stamps;
  std::vector<SE3> truth;
  for (size_t k = 0; k < n; k += 3) {
    scans.push_back(w.scans[k]);
    for (size_t p : {k, k + 1}) {
      stamps.push_back(p < n ? w.scans[p].stamp : w.end);
      truth.push_back(w.truth[p]);
    }
  }
  const std::vector<SE3> initial = perturbed(truth, 21);
  const gt::WindowBaResult ba = gt::window_ba(scans, stamps, initial, gt::WindowBaConfig{});
  ASSERT_EQ(ba.T_world_lidar.size(), truth.size());
  std::vector<double> t0, r0, t1, r1;
  knot_errors(truth, initial, truth.size(), t0, r0);
  knot_errors(truth, ba.T_world_lidar, truth.size(), t1, r1);
  std::printf(
      "[ figures ] %zu keyframes of %zu sweeps, %zu poses: before %.1f mm, %.3f deg rms; after "
      "%d rounds %.2f mm (max %.2f), %.4f deg (max %.4f)\n",
      scans.size(), n, truth.size(), 1e3 * rms(t0), rms(r0), ba.rounds, 1e3 * rms(t1),
      1e3 * max_of(t1), rms(r1), max_of(r1));
  // The consecutive sweeps' figures above (12 sweeps, 13 knots): under 3 mm and 0.02 deg rms.
  EXPECT_LT(rms(t1), 0.1 * rms(t0));
  EXPECT_LT(rms(r1), 0.1 * rms(r0));
  EXPECT_LT(max_of(t1), 0.01);
  EXPECT_LT(max_of(r1), 0.08);

  std::vector<Time> dangling = stamps;
  std::vector<SE3> dangling_knots = initial;
  dangling.insert(dangling.begin() + 2, w.scans[1].stamp + Time::from_seconds(0.05));
  dangling_knots.insert(dangling_knots.begin() + 2, initial[1]);
  EXPECT_THROW(gt::window_ba(scans, dangling, dangling_knots, gt::WindowBaConfig{}), Error);
  std::vector<Time> no_end(stamps.begin(), stamps.end() - 1);
  EXPECT_THROW(gt::window_ba(scans, no_end, std::vector<SE3>(initial.begin(), initial.end() - 1),
                             gt::WindowBaConfig{}),
               Error);
}

// A sweep's spherical image (the photometric term's): the projection found from the scan puts
// every point on its own beam's row and the image holds a range at most pixels; a point moved
// into another scan's image by the true knots finds its own range there.
TEST(SphericalImage, PointsFallOnTheirBeamsRows) {
  const SimWindow w = sim_window(sim::MotionKind::walk, 2);
  const Scan& scan = w.scans[0];
  const gt::SphericalProjection projection = gt::spherical_projection(scan);
  ASSERT_EQ(projection.rows, 64);
  EXPECT_NEAR(projection.cols, 1024, 8);
  double worst = 0;
  std::vector<Eigen::Vector3d> p;
  std::vector<float> intensity;
  for (const ScanPoint& q : scan.points) {
    double u = 0, v = 0;
    projection.project(Eigen::Vector3d(q.p.cast<double>()), &u, &v);
    worst = std::max(worst, std::abs(v - double(q.ring)));
    p.push_back(q.p.cast<double>());
    intensity.push_back(q.intensity);
  }
  EXPECT_LT(worst, 0.1) << "rows off their beams";
  const gt::SphericalImage image = gt::spherical_image(p, intensity, projection);
  const size_t filled = size_t(
      std::count_if(image.range_m.begin(), image.range_m.end(), [](double r) { return r > 0; }));
  std::printf("[ figures ] a walk's sweep: %zu points, %d x %d image, %.1f %% of pixels filled\n",
              scan.points.size(), projection.rows, projection.cols,
              100.0 * double(filled) / double(image.range_m.size()));
  EXPECT_GT(double(filled), 0.5 * double(image.range_m.size()));
}

// The photometric term on the twelve raw sweeps of a walk: after the geometric rounds, each
// sweep's points against the images of the two sweeps before it. It must converge as the
// geometric adjustment does (a tenth of the initial error, under 1 cm everywhere). What it
// changes is printed: on this window (seed 12) the knots' positions 1.96 -> 1.47 mm rms, their
// rotations 0.012 -> 0.031 deg: the range residuals at grazing incidence tilt the sweeps in roll
// and pitch, and over a sequence that tilt is what makes the term worse than none
// (doc/ground-truth.md, "The photometric term").
TEST(WindowBa, ThePhotometricTermKeepsAWalksKnotsOnTheTruth) {
  const size_t n = 12;
  const SimWindow w = sim_window(sim::MotionKind::walk, n);
  const std::vector<SE3> initial = perturbed(w.truth, 12);
  gt::WindowBaConfig config;
  const gt::WindowBaResult geometric = gt::window_ba(w.scans, initial, w.end, config);
  config.photometric.enabled = true;
  const gt::WindowBaResult both = gt::window_ba(w.scans, initial, w.end, config);
  std::vector<double> t0, r0, t1, r1, t2, r2;
  knot_errors(w.truth, initial, n + 1, t0, r0);
  knot_errors(w.truth, geometric.T_world_lidar, n + 1, t1, r1);
  knot_errors(w.truth, both.T_world_lidar, n + 1, t2, r2);
  std::printf(
      "[ figures ] knots before %.1f mm, %.3f deg rms; geometric %.2f mm (max %.2f), %.4f deg; "
      "with the photometric term (%zu residuals, sigmas %.1f mm, %.1f intensity) %.2f mm (max "
      "%.2f), %.4f deg\n",
      1e3 * rms(t0), rms(r0), 1e3 * rms(t1), 1e3 * max_of(t1), rms(r1), both.photometric_residuals,
      1e3 * both.photometric_sigma_range_m, both.photometric_sigma_intensity, 1e3 * rms(t2),
      1e3 * max_of(t2), rms(r2));
  EXPECT_GT(both.photometric_residuals, 1000u * (n - 1));
  EXPECT_EQ(geometric.photometric_residuals, 0u);
  EXPECT_LT(both.photometric_sigma_range_m, 0.05);
  EXPECT_LT(rms(t2), 0.1 * rms(t0));
  EXPECT_LT(max_of(t2), 0.01);
  EXPECT_LT(rms(r2), 0.1 * rms(r0));
}

// The motion error e of `measured` against `truth` (measured = perturbed(truth, e)).
Eigen::Matrix<double, 6, 1> motion_error(const SE3& measured, const SE3& truth) {
  Eigen::Matrix<double, 6, 1> e;
  e << rotation_vector(measured.R * truth.R.transpose()), measured.t - truth.t;
  return e;
}

// A walk's raw sweeps and a drifting odometry along them (`sigma_t` m and `sigma_deg` a step, each
// axis), with the scans streamed as lidar::ScanStream::next gives them.
struct WalkWithOdometry {
  SimWindow w;
  gt::OdometryInput odometry;
  size_t next = 0;  // the next scan next_scan gives
  std::function<std::optional<Scan>()> next_scan = [this]() -> std::optional<Scan> {
    if (next >= w.scans.size()) return std::nullopt;
    return w.scans[next++];
  };
};
void make_walk_with_odometry(size_t n, double sigma_t, double sigma_deg, WalkWithOdometry& out) {
  out.w = sim_window(sim::MotionKind::walk, n);
  const SimWindow& w = out.w;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> N(0.0, 1.0);
  const double sigma_rot = sigma_deg * M_PI / 180;
  gt::OdometryInput& odometry = out.odometry;
  odometry.T_odom_lidar.stamps.push_back(w.scans[0].stamp);
  odometry.T_odom_lidar.T_world_body.push_back(w.truth[0]);
  for (size_t k = 0; k < n; ++k) {
    Eigen::Matrix<double, 6, 1> e;
    e << sigma_rot * N(rng), sigma_rot * N(rng), sigma_rot * N(rng), sigma_t * N(rng),
        sigma_t * N(rng), sigma_t * N(rng);
    const SE3 step = perturbed(w.truth[k].inverse() * w.truth[k + 1], e);
    odometry.T_odom_lidar.stamps.push_back(k + 1 < n ? w.scans[k + 1].stamp : w.end);
    odometry.T_odom_lidar.T_world_body.push_back(odometry.T_odom_lidar.T_world_body.back() * step);
    gt::Matrix6d c = gt::Matrix6d::Zero();
    c.diagonal() << Eigen::Vector3d::Constant(sigma_rot * sigma_rot),
        Eigen::Vector3d::Constant(sigma_t * sigma_t);
    odometry.step_covariance.push_back(c);
  }
}

// The motions between consecutive poses of `spans` (0 ... n: every step; the keyframes: from one
// to the next), from the windows, against the truth and the odometry: better than the odometry's
// by `ratio`, and (`honest`) their sigmas (a span's: its steps' covariances summed, the steps
// short) honest.
void expect_motions_better_and_honest(const WalkWithOdometry& walk, const gt::SequenceBaResult& ba,
                                      const std::vector<size_t>& spans, double ratio,
                                      bool honest = true) {
  const SimWindow& w = walk.w;
  const size_t n = w.scans.size();
  ASSERT_EQ(ba.motions.T_odom_lidar.size(), n + 1);
  ASSERT_EQ(ba.motions.step_covariance.size(), n);
  EXPECT_EQ(ba.motions_from_odometry, 0u);
  EXPECT_EQ(ba.scans_unused, 0u);
  std::vector<double> odo_t, odo_r, ba_t, ba_r;
  size_t components = 0, within = 0;
  double worst = 0;
  std::vector<double> zs[6];
  for (size_t s = 0; s + 1 < spans.size(); ++s) {
    const size_t a = spans[s], b = spans[s + 1];
    const SE3 truth = w.truth[a].inverse() * w.truth[b];
    const auto& T = ba.motions.T_odom_lidar.T_world_body;
    const auto& O = walk.odometry.T_odom_lidar.T_world_body;
    const Eigen::Matrix<double, 6, 1> e_odo = motion_error(O[a].inverse() * O[b], truth);
    const Eigen::Matrix<double, 6, 1> e = motion_error(T[a].inverse() * T[b], truth);
    gt::Matrix6d covariance = gt::Matrix6d::Zero();
    for (size_t k = a; k < b; ++k) covariance += ba.motions.step_covariance[k];
    odo_r.push_back(e_odo.head<3>().norm() * 180 / M_PI);
    odo_t.push_back(e_odo.tail<3>().norm());
    ba_r.push_back(e.head<3>().norm() * 180 / M_PI);
    ba_t.push_back(e.tail<3>().norm());
    for (int i = 0; i < 6; ++i) {
      const double z = e(i) / std::sqrt(covariance(i, i));
      within += std::abs(z) < 3;
      zs[i].push_back(z);
      worst = std::max(worst, std::abs(z));
      ++components;
    }
  }
  double seconds = 0;
  for (const gt::WindowSummary& s : ba.windows) seconds += s.seconds;
  std::printf(
      "[ figures ] %zu keyframes of %zu scans, %zu windows (%.1f s each); %zu motions' errors: "
      "odometry %.2f mm, %.4f deg rms; windows %.2f mm (max %.2f), %.4f deg (max %.4f); %.1f %% of "
      "the components within 3 sigma, the largest %.2f sigma\n",
      ba.keyframes.size(), n, ba.windows.size(), seconds / double(ba.windows.size()),
      spans.size() - 1, 1e3 * rms(odo_t), rms(odo_r), 1e3 * rms(ba_t), 1e3 * max_of(ba_t),
      rms(ba_r), max_of(ba_r), 100.0 * double(within) / double(components), worst);
  std::printf("[ figures ] errors over sigmas, rms by component (rx ry rz tx ty tz):");
  for (int i = 0; i < 6; ++i) std::printf(" %.2f", rms(zs[i]));
  std::printf("\n");
  EXPECT_LT(rms(ba_t), ratio * rms(odo_t));
  EXPECT_LT(rms(ba_r), ratio * rms(odo_r));
  if (honest) {
    EXPECT_GE(double(within), 0.95 * double(components));
  }
}

// A job array: the plan of `whole` cut into chunks of windows ([first, end) each, the last one
// past the plan's end), each adjusted alone from its first window's scan on (those before skipped
// unread, as lidar::ScanStream::skip_before does for a folder), their owned motions joined, gives
// the whole run's motions and covariances (to rounding: the chunks' motions are chained and taken
// apart again).
void expect_chunks_join_to_the_whole(WalkWithOdometry& walk, const gt::SequenceBaConfig& config,
                                     const gt::SequenceBaResult& whole,
                                     const std::vector<std::pair<size_t, size_t>>& cuts) {
  const gt::OdometryInput& odometry = walk.odometry;
  const size_t n = walk.w.scans.size();
  std::vector<gt::OdometryInput> chunks;
  std::vector<std::string> names;
  size_t owned = 0;
  for (const auto& [first, end] : cuts) {
    gt::SequenceBaConfig chunk_config = config;
    chunk_config.first_window = first;
    chunk_config.end_window = end;
    walk.next = gt::first_pose_of_window(odometry.T_odom_lidar, config, first).value();
    EXPECT_EQ(walk.next, whole.windows[first].first_pose);
    const gt::SequenceBaResult chunk =
        gt::sequence_ba(walk.next_scan, odometry.T_odom_lidar, odometry, chunk_config);
    EXPECT_EQ(chunk.windows.size(), std::min(end, whole.planned_windows) - first);
    chunks.push_back(gt::owned_motions(chunk, odometry.T_odom_lidar));
    names.push_back(fmt::format("chunk {}", chunks.size()));
    owned += chunks.back().step_covariance.size();
  }
  EXPECT_EQ(owned, n);
  const gt::SequenceBaResult joined =
      gt::join_window_motions(chunks, names, odometry, odometry.T_odom_lidar.T_world_body[0]);
  EXPECT_EQ(joined.motions_from_odometry, 0u);
  ASSERT_EQ(joined.motions.T_odom_lidar.size(), n + 1);
  double worst_t = 0, worst_r = 0, worst_c = 0;
  for (size_t k = 0; k < n; ++k) {
    const auto& A = whole.motions.T_odom_lidar.T_world_body;
    const auto& B = joined.motions.T_odom_lidar.T_world_body;
    const SE3 d = (A[k].inverse() * A[k + 1]).inverse() * (B[k].inverse() * B[k + 1]);
    worst_t = std::max(worst_t, d.t.norm());
    worst_r = std::max(worst_r, rotation_angle(d.R));
    worst_c =
        std::max(worst_c, (joined.motions.step_covariance[k] - whole.motions.step_covariance[k])
                                  .cwiseAbs()
                                  .maxCoeff() /
                              whole.motions.step_covariance[k].cwiseAbs().maxCoeff());
  }
  std::printf("[ figures ] chunks joined against the whole run: %.2g m, %.2g rad, %.2g relative\n",
              worst_t, worst_r, worst_c);
  // Rounding only: the motions are chained to poses metres from the origin and taken apart again
  // (1e-12 m here; a gap's motions are bent along the odometry's path, a few more operations).
  EXPECT_LT(worst_t, 1e-11);
  EXPECT_LT(worst_r, 1e-12);
  EXPECT_LT(worst_c, 1e-12);
  // Chunks that overlap, or that belong to another trajectory, are refused.
  EXPECT_THROW(gt::join_window_motions({chunks[0], chunks[0]}, {"a", "a2"}, odometry, SE3()),
               Error);
  gt::OdometryInput shifted = chunks[1];
  for (Time& t : shifted.T_odom_lidar.stamps) t = t + Time::from_seconds(0.05);
  EXPECT_THROW(gt::join_window_motions({shifted}, {"shifted"}, odometry, SE3()), Error);
  // A chunk missing: its motions stay the odometry's, counted.
  EXPECT_EQ(gt::join_window_motions({chunks[0], chunks[2]}, {"a", "c"}, odometry, SE3())
                .motions_from_odometry,
            chunks[1].step_covariance.size());
}

// Three seconds of a walk's raw sweeps, every scan a keyframe, in windows of 8 scans overlapping
// by 2: every motion between consecutive scans taken from a window, with its covariance, far
// better than the odometry's and honest; and the same cut into a job array's chunks.
TEST(SequenceBa, AWalksWindowsGiveMotionsBetterThanTheOdometrysWithHonestSigmas) {
  WalkWithOdometry walk;
  make_walk_with_odometry(30, 0.01, 0.1, walk);
  gt::SequenceBaConfig config;  // every scan a keyframe (the default)
  config.window_scans = 8;
  config.overlap_scans = 2;
  const gt::SequenceBaResult ba =
      gt::sequence_ba(walk.next_scan, walk.odometry.T_odom_lidar, walk.odometry, config);
  EXPECT_EQ(ba.keyframes.size(), 30u);
  ASSERT_EQ(ba.planned_windows, 5u);  // 30 scans, windows of 8 starting every 6
  std::vector<size_t> every(31);
  std::iota(every.begin(), every.end(), 0);
  expect_motions_better_and_honest(walk, ba, every, 0.3);
  expect_chunks_join_to_the_whole(walk, config, ba, {{0, 2}, {2, 3}, {3, 9}});
}

// The walk with keyframes chosen by motion (0.3 m or 5 deg; the walk makes about 0.13 m a sweep): a
// third of the scans adjusted, in windows of 6 keyframes overlapping by 2, the odometry's motion
// across each gap and over each sweep a gap follows a prior (an odometry as good as rigcal's on
// the demo's walk, 2 mm and 0.02 deg a step, with honest covariances: it cannot show what an
// odometry that errs beyond its covariance does, doc/ground-truth.md; a sweep's end knot and the
// next keyframe's first knot each see half a sweep, and the planes alone hold the gap between
// them poorly). Every motion still comes from a window (across a gap,
// spread over its steps along the odometry's path); the job array's chunks start at keyframes.
TEST(SequenceBa, KeyframesChosenByMotionGiveEveryMotionWithHonestSigmas) {
  WalkWithOdometry walk;
  make_walk_with_odometry(30, 0.002, 0.02, walk);
  gt::SequenceBaConfig config;
  config.keyframe_distance_m = 0.3;
  config.keyframe_angle_deg = 5;
  config.window_scans = 6;
  config.overlap_scans = 2;
  const gt::SequenceBaResult ba =
      gt::sequence_ba(walk.next_scan, walk.odometry.T_odom_lidar, walk.odometry, config);
  EXPECT_GE(ba.keyframes.size(), 8u);
  EXPECT_LE(ba.keyframes.size(), 15u);
  ASSERT_GE(ba.planned_windows, 3u);
  // Between keyframes, the motions are the windows': better than the odometry's (a third of its
  // error here, as with every scan adjusted; 0.59 without the odometry's prior on each
  // keyframe's own sweep), honest.
  std::vector<size_t> keyframes = ba.keyframes;
  keyframes.push_back(30);
  expect_motions_better_and_honest(walk, ba, keyframes, 0.5);
  // Each step inside a span between keyframes (the odometry's path bent to the window's motion
  // across the span) is about as good as the odometry's, but not honest: each carries an equal
  // share of the span's covariance, not the odometry's error bridged between the span's ends
  // (74 % of the components within 3 sigma here, 13 sigma at worst; adding the bridge to each
  // step loosens the whole chain by it instead: tried, doc/ground-truth.md).
  std::vector<size_t> every(31);
  std::iota(every.begin(), every.end(), 0);
  expect_motions_better_and_honest(walk, ba, every, 1.5, /*honest=*/false);
  expect_chunks_join_to_the_whole(walk, config, ba, {{0, 1}, {1, 2}, {2, 9}});

  // A rig standing still: a keyframe every keyframe_max_gap scans, and the last sweep's.
  gt::OdometryInput standing = walk.odometry;
  for (SE3& T : standing.T_odom_lidar.T_world_body) T = walk.odometry.T_odom_lidar.T_world_body[0];
  gt::SequenceBaConfig plan_only = config;
  plan_only.keyframe_max_gap = 3;  // keyframes 0, 3, ..., 27 and 29; windows start at 0, 4, 8
  EXPECT_EQ(gt::first_pose_of_window(standing.T_odom_lidar, plan_only, 1).value(), 12u);
  EXPECT_EQ(gt::first_pose_of_window(standing.T_odom_lidar, plan_only, 2).value(), 24u);
  EXPECT_FALSE(gt::first_pose_of_window(standing.T_odom_lidar, plan_only, 3).has_value());
  // Keyframes need overlapping windows: the motion from a window's last keyframe to the next is
  // the next window's.
  plan_only.overlap_scans = 0;
  EXPECT_THROW(gt::first_pose_of_window(standing.T_odom_lidar, plan_only, 0), Error);
}

}  // namespace
}  // namespace rigcal
