// The LiDAR bundle adjustment's geometric stage (calib/gt/plane_patches, window_ba): planar
// patches of a known scene, and one window of a simulated walk's sweeps brought back onto their
// planes from perturbed poses, scored against the simulator's truth.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <random>

#include "rigcal/core/stats.h"
#include "rigcal/gt/plane_patches.h"
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

// Twenty sweeps of the simulator's hand-held walk (64 beams x 1024 columns), deskewed with the
// true continuous motion (the constant motion of a sweep leaves 16 mm rms of the points off
// their planes at the true poses: the hand-held sway's accelerations); every pose but the first
// moved by 3 cm and 0.3 deg (sigma each axis).
TEST(WindowBa, AWalksSweepsComeBackOntoTheirPlanes) {
  const rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  sim::SimConfig config;
  config.trajectory_duration_s = 2.0;
  config.lidar = sim::os0_128();
  config.lidar.beams = 64;
  config.lidar.columns = 1024;
  const sim::TrajectoryPart part = sim::simulate_trajectories(rig, config);
  sim::SweepDrive drive = sim::trajectory_drive(rig, config, part);
  const std::vector<SE3>& truth = part.truth_base.T_world_body;
  const size_t n = 20;
  ASSERT_GT(truth.size(), n);
  std::vector<std::vector<Eigen::Vector3d>> points;
  for (size_t k = 0; k < n; ++k) {
    const double t0 = drive.first_s + double(drive.next) / drive.lidar.rate_hz;  // motion time
    const sim::Sweep sweep = sim::next_sweep(drive);
    ASSERT_LT((sweep.T_world_lidar.t - truth[k].t).norm(), 1e-9);
    std::vector<Eigen::Vector3d> deskewed;
    const SE3 T_lidar_world = sweep.T_world_lidar.inverse();
    for (const sim::LidarPoint& p : sweep.points) {
      deskewed.push_back(T_lidar_world * (drive.T_world_lidar(t0 + 1e-9 * p.t_ns) *
                                          Eigen::Vector3d(p.p.cast<double>())));
    }
    points.push_back(std::move(deskewed));
  }
  std::mt19937_64 rng(11);
  std::normal_distribution<double> N(0.0, 1.0);
  std::vector<SE3> initial = {truth[0]};
  for (size_t k = 1; k < n; ++k) {
    const Eigen::Vector3d phi(N(rng), N(rng), N(rng)), dt(N(rng), N(rng), N(rng));
    initial.push_back(SE3::from_rotation_vector(0.3 * M_PI / 180 * phi, 0.03 * dt) * truth[k]);
  }
  auto errors = [&](const std::vector<SE3>& T_world_lidar, std::vector<double>& trans_m,
                    std::vector<double>& rot_deg) {
    trans_m.clear();
    rot_deg.clear();
    for (size_t k = 1; k < n; ++k) {
      const SE3 e = truth[k].inverse() * T_world_lidar[k];
      trans_m.push_back(e.t.norm());
      rot_deg.push_back(rotation_angle(e.R) * 180 / M_PI);
    }
  };
  std::vector<double> t0, r0, t1, r1;
  errors(initial, t0, r0);
  const gt::WindowBaResult ba = gt::window_ba(points, initial, gt::WindowBaConfig{});
  errors(ba.T_world_lidar, t1, r1);
  std::printf(
      "[ figures ] pose errors before: %.1f mm, %.3f deg rms; after %d rounds (%zu patches, %zu "
      "residuals): %.2f mm (max %.2f), %.4f deg (max %.4f); point-plane rms %.1f -> %.1f mm\n",
      1e3 * rms(t0), rms(r0), ba.rounds, ba.patches, ba.residuals, 1e3 * rms(t1),
      1e3 * *std::max_element(t1.begin(), t1.end()), rms(r1),
      *std::max_element(r1.begin(), r1.end()), 1e3 * ba.rms_before_m, 1e3 * ba.rms_after_m);
  EXPECT_TRUE(ba.T_world_lidar[0] == initial[0]);
  EXPECT_LT(rms(t1), 0.1 * rms(t0));
  EXPECT_LT(rms(r1), 0.1 * rms(r0));
  EXPECT_LT(*std::max_element(t1.begin(), t1.end()), 0.005);
  EXPECT_LT(*std::max_element(r1.begin(), r1.end()), 0.05);
  // The map as crisp as the range noise (10 mm) allows.
  EXPECT_LT(ba.rms_after_m, 0.6 * ba.rms_before_m);
  EXPECT_LT(ba.rms_after_m, 0.012);
}

}  // namespace
}  // namespace rigcal
