#include "rigcal/gt/sequence_ba.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <map>
#include <thread>

#include "rigcal/core/error.h"
#include "rigcal/core/text.h"

namespace rigcal::gt {
namespace {

// Window i: the scans [first[i], end[i]), its last knot the pose end[i].
struct Windows {
  std::vector<size_t> first, end;
  // owner[k]: the window the motion k -> k + 1 is taken from.
  std::vector<size_t> owner;
};

Windows plan_windows(size_t poses, const SequenceBaConfig& c) {
  if (c.window_scans < 2 || c.overlap_scans >= c.window_scans)
    throw Error(fmt::format(
        "bundle adjustment: windows of {} scans overlapping by {}: at least 2 scans a window, "
        "and an overlap below that",
        c.window_scans, c.overlap_scans));
  Windows w;
  for (size_t s = 0; s + 1 < poses; s += c.window_scans - c.overlap_scans) {
    w.first.push_back(s);
    w.end.push_back(std::min(s + c.window_scans, poses - 1));
    if (w.end.back() == poses - 1) break;
  }
  // A window owns its motions from the middle of its overlap with the previous one to the middle
  // of its overlap with the next.
  w.owner.assign(poses - 1, 0);
  for (size_t i = 1; i < w.first.size(); ++i) {
    const size_t from = (w.first[i] + w.end[i - 1] + 1) / 2;
    for (size_t k = from; k + 1 < poses; ++k) w.owner[k] = i;
  }
  return w;
}

}  // namespace

SequenceBaResult sequence_ba(const std::function<std::optional<Scan>()>& next_scan,
                             const Trajectory& T_world_lidar, const OdometryInput& odometry,
                             const SequenceBaConfig& config, const report::Progress& progress) {
  const auto started = std::chrono::steady_clock::now();
  const size_t n = T_world_lidar.size();
  if (odometry.T_odom_lidar.stamps != T_world_lidar.stamps ||
      odometry.step_covariance.size() + 1 != n)
    throw Error("bundle adjustment: the initial poses and the odometry differ in their stamps");
  SequenceBaResult out;
  out.config = config;
  if (n < 2) return out;
  const Windows plan = plan_windows(n, config);
  std::map<int64_t, size_t> pose_of_stamp;
  for (size_t k = 0; k < n; ++k) pose_of_stamp[T_world_lidar.stamps[k].ns] = k;

  WindowBaConfig window_config = config.window;
  window_config.step_covariances = true;
  std::vector<SE3> motion(n - 1);
  std::vector<Matrix6d> covariance(n - 1);
  std::vector<bool> from_window(n - 1, false);
  std::map<size_t, Scan> pending;  // scans read, by pose, not yet past every window using them
  size_t next_pose = 0;            // every pose before it has had its scan read
  auto read_to = [&](size_t pose) {
    while (next_pose < pose) {
      std::optional<Scan> scan = next_scan();
      if (!scan) {
        throw Error(fmt::format("bundle adjustment: the scans end before the pose at {} s",
                                to_seconds_text(T_world_lidar.stamps[next_pose])));
      }
      const auto it = pose_of_stamp.find(scan->stamp.ns);
      if (it == pose_of_stamp.end() || it->second < next_pose) {
        ++out.scans_unused;
        continue;
      }
      if (it->second > next_pose) {
        throw Error(fmt::format(
            "bundle adjustment: no scan stamped {} s, a pose of the trajectory (the scans of "
            "another recording?)",
            to_seconds_text(T_world_lidar.stamps[next_pose])));
      }
      pending.emplace(next_pose++, std::move(*scan));
    }
  };
  // The windows a batch at a time, one a core, each solved on one thread.
  const size_t count = plan.first.size();
  const size_t batch =
      std::max<size_t>(1, config.parallel_windows > 0 ? size_t(config.parallel_windows)
                                                      : std::thread::hardware_concurrency());
  if (batch > 1) window_config.threads = 1;
  for (size_t i0 = 0; i0 < count; i0 += batch) {
    const size_t i1 = std::min(count, i0 + batch);
    read_to(plan.end[i1 - 1]);
    std::vector<WindowBaResult> results(i1 - i0);
    std::vector<double> seconds(i1 - i0);
    tbb::parallel_for(i0, i1, [&](size_t i) {
      const auto window_started = std::chrono::steady_clock::now();
      std::vector<Scan> scans;
      std::vector<SE3> knots;
      for (size_t k = plan.first[i]; k < plan.end[i]; ++k) {
        scans.push_back(pending.at(k));
        knots.push_back(T_world_lidar.T_world_body[k]);
      }
      knots.push_back(T_world_lidar.T_world_body[plan.end[i]]);
      results[i - i0] = window_ba(scans, knots, T_world_lidar.stamps[plan.end[i]], window_config);
      seconds[i - i0] =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - window_started).count();
    });
    for (size_t i = i0; i < i1; ++i) {
      const WindowBaResult& ba = results[i - i0];
      out.windows.push_back({plan.first[i], plan.end[i] - plan.first[i], ba.rounds, ba.patches,
                             ba.residuals, ba.rms_before_m, ba.rms_after_m,
                             !ba.step_covariance.empty(), seconds[i - i0], ba.photometric_residuals,
                             ba.photometric_sigma_range_m, ba.photometric_sigma_intensity});
      if (ba.step_covariance.empty()) continue;
      for (size_t k = plan.first[i]; k < plan.end[i]; ++k) {
        if (plan.owner[k] != i) continue;
        const size_t j = k - plan.first[i];
        motion[k] = ba.T_world_lidar[j].inverse() * ba.T_world_lidar[j + 1];
        covariance[k] = ba.step_covariance[j];
        from_window[k] = true;
      }
    }
    if (i1 < count)
      while (!pending.empty() && pending.begin()->first < plan.first[i1])
        pending.erase(pending.begin());
    report::tell(progress, "bundle adjustment: windows", i1, count);
  }
  while (const std::optional<Scan> scan = next_scan())
    out.scans_unused += !pose_of_stamp.count(scan->stamp.ns);

  Trajectory& chained = out.motions.T_odom_lidar;
  chained.stamps = T_world_lidar.stamps;
  chained.T_world_body = {T_world_lidar.T_world_body[0]};
  for (size_t k = 0; k + 1 < n; ++k) {
    if (!from_window[k]) {
      motion[k] = odometry.T_odom_lidar.T_world_body[k].inverse() *
                  odometry.T_odom_lidar.T_world_body[k + 1];
      covariance[k] = odometry.step_covariance[k];
      ++out.motions_from_odometry;
    }
    chained.T_world_body.push_back(chained.T_world_body.back() * motion[k]);
  }
  out.motions.step_covariance = std::move(covariance);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return out;
}

}  // namespace rigcal::gt
