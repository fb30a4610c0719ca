#include "rigcal/lidar/odometry.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>

#include "rigcal/core/error.h"
#include "rigcal/lidar/preprocess.h"

namespace rigcal::lidar {
namespace {

// `covariance` in the previous sensor frame; the information's eigenvalues are those of any frame.
Degeneracy degeneracy_of(const Matrix6d& covariance, const Matrix6d& information, double ratio) {
  Degeneracy d;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> rot(covariance.topLeftCorner<3, 3>()),
      trans(covariance.bottomRightCorner<3, 3>());
  d.rotation_sigma_max_deg = std::sqrt(std::max(rot.eigenvalues()(2), 0.0)) * 180.0 / M_PI;
  d.weakest_rotation = rot.eigenvectors().col(2);
  d.translation_sigma_max_m = std::sqrt(std::max(trans.eigenvalues()(2), 0.0));
  d.weakest_translation = trans.eigenvectors().col(2);
  auto block_ratio = [](const Eigen::Matrix3d& block) {
    const Eigen::Vector3d l = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(block).eigenvalues();
    return l(2) > 0 ? std::max(l(0), 0.0) / l(2) : 0.0;
  };
  d.rotation_ratio = block_ratio(information.topLeftCorner<3, 3>());
  d.translation_ratio = block_ratio(information.bottomRightCorner<3, 3>());
  const Eigen::Vector3d variances = trans.eigenvalues();
  d.translation_variance_ratio =
      variances(2) > 0 ? std::max(variances(0), 0.0) / variances(2) : 0.0;
  d.degenerate = d.rotation_ratio < ratio || d.translation_ratio < ratio ||
                 d.translation_variance_ratio < ratio;
  return d;
}

double seconds_since(std::chrono::steady_clock::time_point started) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
}

}  // namespace

OdometryConfig os0_128_handheld() {
  OdometryConfig c;
  c.voxel_size_m = 0.5, c.max_range_m = 50.0, c.min_range_m = 0.5;
  c.step_sigma_floor_deg = 0.01, c.step_sigma_floor_m = 0.0;
  return c;
}

OdometryConfig os1_64_car() {
  OdometryConfig c;
  c.voxel_size_m = 1.0, c.max_range_m = 100.0, c.min_range_m = 1.0;
  c.step_sigma_floor_deg = 0.01, c.step_sigma_floor_m = 0.0005;
  return c;
}

std::vector<std::string> preset_names() { return {"os0-128", "os1-64"}; }

OdometryConfig odometry_preset(const std::string& name) {
  if (name == "os0-128") return os0_128_handheld();
  if (name == "os1-64") return os1_64_car();
  throw Error(fmt::format("unknown sensor preset '{}' (os0-128 or os1-64)", name));
}

std::string preset_for_model(std::string_view model) {
  std::string m;
  for (char c : model) {
    if (std::isalnum(static_cast<unsigned char>(c)))
      m += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  if (m.find("os0") != std::string::npos) return "os0-128";
  if (m.find("os1") != std::string::npos) return "os1-64";
  return "";
}

Odometry start_odometry(const OdometryConfig& config) {
  Odometry o;
  o.config = config;
  o.map.voxel_size = config.voxel_size_m;
  o.map.max_points_per_voxel = config.max_points_per_voxel;
  // KISS-ICP's spacing: a full voxel's points spread over it.
  o.map.min_point_spacing =
      config.voxel_size_m /
      std::sqrt(static_cast<double>(std::max<size_t>(config.max_points_per_voxel, 1)));
  o.threshold.initial_m = config.initial_threshold_m;
  o.threshold.min_motion_m = config.min_motion_m;
  o.threshold.max_range_m = config.max_range_m;
  return o;
}

Step register_scan(Odometry& o, const Scan& scan) {
  const auto started = std::chrono::steady_clock::now();
  const OdometryConfig& c = o.config;
  Trajectory& poses = o.T_odom_lidar;
  Step step;
  step.stamp = scan.stamp;
  step.points_in = scan.points.size();
  if (!poses.empty() && scan.stamp <= poses.stamps.back()) {
    step.skipped = fmt::format("stamp {} s not after the last registered scan's ({} s)",
                               to_seconds_text(scan.stamp), to_seconds_text(poses.stamps.back()));
    return step;
  }
  // Constant velocity: the last motion, scaled to this scan's time step.
  SE3 T_prev_cur_predicted;
  double period_s = 0;
  const size_t n = poses.size();
  if (n >= 1) period_s = (scan.stamp - poses.stamps[n - 1]).seconds();
  if (n >= 2) {
    const double last_s = (poses.stamps[n - 1] - poses.stamps[n - 2]).seconds();
    T_prev_cur_predicted = motion_fraction(
        poses.T_world_body[n - 2].inverse() * poses.T_world_body[n - 1], period_s / last_s);
  }
  const SE3 T_odom_prev = n >= 1 ? poses.T_world_body[n - 1] : SE3::identity();
  const SE3 T_odom_predicted = T_odom_prev * T_prev_cur_predicted;
  // The motion over this sweep is taken as the motion from the previous stamp to this one: first
  // the prediction (none for the second scan), then the estimate. The first scan is deskewed
  // once the second has been registered (below).
  const bool deskew = c.deskew && scan.point_times && n >= 1;
  // Sampled before the deskew (which moves points by centimetres, not voxels): the map's level
  // and the registration's, each deskewed again when the motion is better known.
  const std::vector<ScanPoint> frame_raw =
      voxel_sample(scan.points, 0.5 * c.voxel_size_m, c.min_range_m, c.max_range_m);
  const std::vector<ScanPoint> source_raw =
      voxel_sample(frame_raw, 1.5 * c.voxel_size_m, 0.0, INFINITY);
  auto deskewed = [&](const std::vector<ScanPoint>& points, const SE3& T_cur_next) {
    return lidar::deskew(points, T_cur_next, period_s, deskew);
  };
  std::vector<Eigen::Vector3d> frame = deskewed(frame_raw, T_prev_cur_predicted);
  std::vector<Eigen::Vector3d> source = deskewed(source_raw, T_prev_cur_predicted);
  step.points_used = source.size();
  step.deskewed = deskew;
  SE3 T_odom_cur = T_odom_predicted;
  if (n >= 1) {
    const double sigma = sigma_m(o.threshold);
    step.threshold_m = 3.0 * sigma;
    auto registered = [&](const SE3& T_guess, const SE3& T_prev_cur_motion) {
      frame = deskewed(frame_raw, T_prev_cur_motion);
      source = deskewed(source_raw, T_prev_cur_motion);
      return register_points(source, o.map, T_guess, 3.0 * sigma, sigma / 3.0, c.registration);
    };
    Registration r =
        register_points(source, o.map, T_odom_predicted, 3.0 * sigma, sigma / 3.0, c.registration);
    if (r.correspondences < c.min_correspondences ||
        double(r.correspondences) < c.min_overlap * double(source.size())) {
      step.skipped = fmt::format(
          "no overlap with the map: {} of {} points near a map plane (at least {} and {:.0f} % "
          "needed)",
          r.correspondences, source.size(), c.min_correspondences, 100 * c.min_overlap);
      step.correspondences = r.correspondences;
      step.seconds = seconds_since(started);
      return step;
    }
    const bool sweep_motion = deskew && c.estimate_sweep_motion;
    for (int pass = 1; deskew && !sweep_motion && pass < c.deskew_passes && r.correspondences >= 6;
         ++pass)
      r = registered(r.T_odom_lidar, T_odom_prev.inverse() * r.T_odom_lidar);
    // The second scan: the first one deskewed with the motion now known, the map rebuilt from
    // it, and the second registered again (twice: the motion improves with the map).
    for (int pass = 0; deskew && n == 1 && o.first_scan.point_times && pass < 2; ++pass) {
      clear(o.map);
      add_points(o.map, lidar::deskew(o.first_scan.points, r.T_odom_lidar, period_s, true));
      r = registered(r.T_odom_lidar, r.T_odom_lidar);
    }
    if (n == 1) o.first_scan = Scan{};
    if (sweep_motion) {
      // The sweep's own motion, about the last step's.
      const SE3 T_prev_cur = T_odom_prev.inverse() * r.T_odom_lidar;
      const double deg = c.sweep_motion_sigma_deg * M_PI / 180.0, m = c.sweep_motion_sigma_m;
      const SweepRegistration s =
          register_sweep(source_raw, period_s, o.map, r.T_odom_lidar, T_prev_cur,
                         (Vector6d() << deg, deg, deg, m, m, m).finished(), 3.0 * sigma,
                         sigma / 3.0, c.registration);
      if (s.start.correspondences >= 12 && s.start.converged) {
        r = s.start;
        frame = deskewed(frame_raw, s.T_start_end);
        source = deskewed(source_raw, s.T_start_end);
      }
    }
    step.points_used = source.size();
    T_odom_cur = r.T_odom_lidar;
    update(o.threshold, T_odom_predicted.inverse() * T_odom_cur);
    // The covariance of T_odom_cur, the map (the previous poses) held: in the previous frame.
    Matrix6d A = Matrix6d::Zero();
    A.topLeftCorner<3, 3>() = A.bottomRightCorner<3, 3>() = T_odom_prev.R.transpose();
    step.covariance_prev_cur = A * r.covariance * A.transpose();
    const double floor_rad = c.step_sigma_floor_deg * M_PI / 180.0;
    step.covariance_prev_cur.diagonal() +=
        (Vector6d() << Eigen::Vector3d::Constant(floor_rad * floor_rad),
         Eigen::Vector3d::Constant(c.step_sigma_floor_m * c.step_sigma_floor_m))
            .finished();
    step.degeneracy = degeneracy_of(step.covariance_prev_cur, r.information, c.degenerate_ratio);
    Degeneracy& d = step.degeneracy;
    if (c.degenerate_sigma_m > 0 && (d.translation_ratio < c.degenerate_ratio ||
                                     d.translation_variance_ratio < c.degenerate_ratio)) {
      step.covariance_prev_cur.bottomRightCorner<3, 3>() +=
          c.degenerate_sigma_m * c.degenerate_sigma_m * d.weakest_translation *
          d.weakest_translation.transpose();
      d.translation_widened = true;
    }
    step.correspondences = r.correspondences;
    step.residual_rms_m = r.residual_rms_m;
    step.noise_sigma_m = r.noise_sigma_m;
    step.iterations = r.iterations;
    step.converged = r.converged;
  } else {
    o.first_scan.stamp = scan.stamp;
    o.first_scan.point_times = scan.point_times;
    o.first_scan.points = frame_raw;
  }
  step.T_odom_lidar = T_odom_cur;
  std::vector<Eigen::Vector3d> frame_odom;
  frame_odom.reserve(frame.size());
  for (const Eigen::Vector3d& p : frame) frame_odom.push_back(T_odom_cur * p);
  add_points(o.map, frame_odom);
  remove_far(o.map, T_odom_cur.t, c.max_range_m);
  poses.stamps.push_back(scan.stamp);
  poses.T_world_body.push_back(T_odom_cur);
  step.seconds = seconds_since(started);
  return step;
}

}  // namespace rigcal::lidar
