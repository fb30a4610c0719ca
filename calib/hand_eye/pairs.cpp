#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <optional>

#include "rigcal/core/error.h"
#include "rigcal/core/stats.h"
#include "rigcal/core/trajectory.h"
#include "rigcal/hand_eye/hand_eye.h"

namespace rigcal::hand_eye {
namespace {

// The body-frame angular and linear velocity of `traj` at t, by central differences over +-50 ms
// (one LiDAR period); zero where the poses are not there.
void velocity(const Trajectory& traj, Time t, Time max_gap, Eigen::Vector3d& w,
              Eigen::Vector3d& v) {
  const Time h = Time::from_ns(50'000'000);
  const auto a = pose_at(traj, t - h, max_gap), b = pose_at(traj, t + h, max_gap);
  w.setZero(), v.setZero();
  if (!a || !b) return;
  const SE3 d = a->inverse() * *b;
  w = rotation_vector(d.R) / 0.1;
  v = d.t / 0.1;
}

// The pairs of one length along the smoothed GNSS/INS trajectory (motion_pairs).
void pairs_of_length(const Trajectory& lidar, const Trajectory& gnss, const PairOptions& o,
                     double spacing_s, std::vector<MotionPair>& pairs) {
  const Time offset = Time::from_seconds(o.time_offset_s);
  const Time spacing = Time::from_seconds(spacing_s), max_gap = Time::from_seconds(o.max_gap_s);
  const Time stride = o.stride_s > 0 ? Time::from_seconds(o.stride_s) : spacing;
  const double min_rotation = o.min_rotation_deg * M_PI / 180.0;
  size_t i = 0;
  while (i < gnss.size()) {
    const auto it =
        std::lower_bound(gnss.stamps.begin() + i, gnss.stamps.end(), gnss.stamps[i] + spacing);
    if (it == gnss.stamps.end()) break;
    const size_t j = static_cast<size_t>(it - gnss.stamps.begin());
    const Time t0 = gnss.stamps[i] + offset, t1 = gnss.stamps[j] + offset;
    const auto L0 = pose_at(lidar, t0, max_gap), L1 = pose_at(lidar, t1, max_gap);
    const SE3 B = gnss.T_world_body[i].inverse() * gnss.T_world_body[j];
    // A pair much longer than asked spans a GNSS/INS outage: skipped.
    if (L0 && L1 && (gnss.stamps[j] - gnss.stamps[i]) < spacing + spacing &&
        rotation_angle(B.R) >= min_rotation) {
      MotionPair p{t0, t1, L0->inverse() * *L1, B};
      velocity(lidar, t0, max_gap, p.w0, p.v0);
      velocity(lidar, t1, max_gap, p.w1, p.v1);
      pairs.push_back(p);
    }
    i = stride == spacing
            ? j
            : static_cast<size_t>(std::lower_bound(gnss.stamps.begin() + i + 1, gnss.stamps.end(),
                                                   gnss.stamps[i] + stride) -
                                  gnss.stamps.begin());
  }
}

}  // namespace

time_sync::TimeSyncResult estimate_clock_offset(const Trajectory& lidar, const Trajectory& gnss,
                                                double prior_offset_s) {
  time_sync::AngularRates gnss_rates = time_sync::angular_rates_from_trajectory(gnss);
  for (Time& t : gnss_rates.stamps) t = t + Time::from_seconds(prior_offset_s);
  time_sync::TimeSyncResult r =
      time_sync::estimate_time_offset(time_sync::angular_rates_from_trajectory(lidar), gnss_rates);
  r.offset_s += prior_offset_s;
  return r;
}

Trajectory smooth_poses(const Trajectory& in, double half_window_s) {
  Trajectory out = in;
  if (half_window_s <= 0) return out;
  const Time h = Time::from_seconds(half_window_s);
  // The fixes' noise from their second differences (white noise: variance 6 sigma^2), robustly:
  // fixes beyond 5 sigma (and 5 cm) of a window's fit are left out of it. A window's own misfits
  // would not do: a 1.5 m jump drags a least-squares quadratic by decimetres at every fix.
  double noise = 0;
  if (in.size() >= 3) {
    for (int a = 0; a < 3; ++a) {
      std::vector<double> d2;
      for (size_t k = 1; k + 1 < in.size(); ++k) {
        d2.push_back(std::abs(in.T_world_body[k + 1].t[a] - 2 * in.T_world_body[k].t[a] +
                              in.T_world_body[k - 1].t[a]));
      }
      noise += std::pow(1.4826 * median(d2) / std::sqrt(6.0), 2);
    }
  }
  const double cut = std::max(0.05, 5.0 * std::sqrt(noise));
  tbb::parallel_for(size_t{0}, in.size(), [&](size_t i) {
    const size_t lo = static_cast<size_t>(
        std::lower_bound(in.stamps.begin(), in.stamps.end(), in.stamps[i] - h) - in.stamps.begin());
    const size_t hi = static_cast<size_t>(
        std::upper_bound(in.stamps.begin(), in.stamps.end(), in.stamps[i] + h) - in.stamps.begin());
    if (hi - lo < 5) return;
    // Rows 1, dt, dt^2: positions, then rotation vectors relative to the pose's own (a linear fit
    // would be biased by the angular acceleration: alpha h^2 / 6, 0.1 deg on a hand-held rig).
    const size_t m = hi - lo;
    std::vector<Eigen::Vector3d> q(m);
    for (size_t k = 0; k < m; ++k) {
      const double dt = (in.stamps[lo + k] - in.stamps[i]).seconds();
      q[k] = Eigen::Vector3d(1.0, dt, dt * dt);
    }
    std::vector<char> use(m, 1);
    Eigen::Matrix3d Ap, cp;
    auto normal_matrix = [&] {
      Ap.setZero();
      int n = 0;
      for (size_t k = 0; k < m; ++k) {
        if (use[k]) Ap += q[k] * q[k].transpose(), ++n;
      }
      return n >= 5;
    };
    bool ok = true;
    for (int it = 0; it < 4; ++it) {  // fit, keep the fixes within the cut of it, again
      if (!(ok = normal_matrix())) break;
      Eigen::Matrix3d bp = Eigen::Matrix3d::Zero();
      for (size_t k = 0; k < m; ++k) {
        if (use[k]) bp += q[k] * in.T_world_body[lo + k].t.transpose();
      }
      cp = Ap.ldlt().solve(bp);
      std::vector<char> next(m);
      for (size_t k = 0; k < m; ++k)
        next[k] = (in.T_world_body[lo + k].t - cp.transpose() * q[k]).norm() <= cut;
      if (next == use) break;
      use.swap(next);
    }
    if (!ok || !normal_matrix()) return;
    const SE3& Ti = in.T_world_body[i];
    Eigen::Matrix3d bp = Eigen::Matrix3d::Zero(), br = Eigen::Matrix3d::Zero();
    for (size_t k = 0; k < m; ++k) {
      if (!use[k]) continue;
      bp += q[k] * in.T_world_body[lo + k].t.transpose();
      br += q[k] * rotation_vector(Ti.R.transpose() * in.T_world_body[lo + k].R).transpose();
    }
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(Ap);
    out.T_world_body[i].t = ldlt.solve(bp).row(0).transpose();
    out.T_world_body[i].R = Ti.R * rotation_from_vector(ldlt.solve(br).row(0).transpose());
  });
  return out;
}

std::vector<double> pair_lengths(const PairOptions& o) {
  for (double s : o.spacings_s) {
    if (!(s > 0)) throw Error(fmt::format("pair spacing {} s: must be positive", s));
  }
  std::vector<double> lengths = o.spacings_s;
  std::sort(lengths.begin(), lengths.end());
  lengths.erase(std::unique(lengths.begin(), lengths.end()), lengths.end());
  return lengths;
}

std::vector<MotionPair> motion_pairs(const Trajectory& lidar, const Trajectory& raw_gnss,
                                     const PairOptions& o) {
  const Trajectory gnss = smooth_poses(raw_gnss, o.gnss_half_window_s);
  std::vector<MotionPair> pairs;
  for (double s : pair_lengths(o)) pairs_of_length(lidar, gnss, o, s, pairs);
  std::stable_sort(pairs.begin(), pairs.end(), [](const MotionPair& a, const MotionPair& b) {
    return a.t0 < b.t0 || (a.t0 == b.t0 && a.t1 < b.t1);
  });
  return pairs;
}

}  // namespace rigcal::hand_eye
