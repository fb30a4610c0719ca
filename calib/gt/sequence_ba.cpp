#include "rigcal/gt/sequence_ba.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
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
  out.planned_windows = plan.first.size();
  // The chunk's windows, and the motions they own.
  const size_t first_window = std::min(config.first_window, plan.first.size());
  const size_t end_window = std::clamp(config.end_window, first_window, plan.first.size());
  for (size_t k = 0; k + 1 < n; ++k) {
    if (plan.owner[k] < first_window || plan.owner[k] >= end_window) continue;
    if (out.end_owned == 0) out.first_owned = k;
    out.end_owned = k + 1;
  }
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
      if (it->second > next_pose && it->second <= plan.first[first_window]) {
        next_pose = it->second;  // the scans before the chunk's were skipped unread
      } else if (it->second > next_pose) {
        throw Error(fmt::format(
            "bundle adjustment: no scan stamped {} s, a pose of the trajectory (the scans of "
            "another recording?)",
            to_seconds_text(T_world_lidar.stamps[next_pose])));
      }
      if (next_pose >= plan.first[first_window]) pending.emplace(next_pose, std::move(*scan));
      ++next_pose;
    }
  };
  // The windows a batch at a time, one a core, each solved on one thread.
  const size_t count = end_window;
  const size_t batch =
      std::max<size_t>(1, config.parallel_windows > 0 ? size_t(config.parallel_windows)
                                                      : std::thread::hardware_concurrency());
  if (batch > 1) window_config.threads = 1;
  for (size_t i0 = first_window; i0 < count; i0 += batch) {
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
    report::tell(progress, "bundle adjustment: windows", i1 - first_window, count - first_window);
  }
  // A chunk stops reading at its last window's scans; a whole sequence reads to the end.
  if (first_window == 0 && end_window == plan.first.size()) {
    while (const std::optional<Scan> scan = next_scan())
      out.scans_unused += !pose_of_stamp.count(scan->stamp.ns);
  }

  Trajectory& chained = out.motions.T_odom_lidar;
  chained.stamps = T_world_lidar.stamps;
  chained.T_world_body = {T_world_lidar.T_world_body[0]};
  for (size_t k = 0; k + 1 < n; ++k) {
    if (!from_window[k]) {
      motion[k] = odometry.T_odom_lidar.T_world_body[k].inverse() *
                  odometry.T_odom_lidar.T_world_body[k + 1];
      covariance[k] = odometry.step_covariance[k];
      out.motions_from_odometry += k >= out.first_owned && k < out.end_owned;
    }
    chained.T_world_body.push_back(chained.T_world_body.back() * motion[k]);
  }
  out.motions.step_covariance = std::move(covariance);
  out.from_window = std::move(from_window);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return out;
}

std::optional<size_t> first_pose_of_window(size_t poses, const SequenceBaConfig& config,
                                           size_t window) {
  if (poses < 2) return std::nullopt;
  const Windows plan = plan_windows(poses, config);
  if (window >= plan.first.size()) return std::nullopt;
  return plan.first[window];
}

OdometryInput owned_motions(const SequenceBaResult& ba, const Trajectory& T_world_lidar) {
  OdometryInput owned;
  const Trajectory& T = ba.motions.T_odom_lidar;
  for (size_t k = ba.first_owned; k < ba.end_owned; ++k) {
    if (owned.T_odom_lidar.empty()) {
      owned.T_odom_lidar.stamps.push_back(T.stamps[k]);
      owned.T_odom_lidar.T_world_body.push_back(T_world_lidar.T_world_body[k]);
    }
    owned.T_odom_lidar.stamps.push_back(T.stamps[k + 1]);
    owned.T_odom_lidar.T_world_body.push_back(
        owned.T_odom_lidar.T_world_body.back() *
        (T.T_world_body[k].inverse() * T.T_world_body[k + 1]));
    owned.step_covariance.push_back(ba.motions.step_covariance[k]);
  }
  return owned;
}

SequenceBaResult join_window_motions(const std::vector<OdometryInput>& chunks,
                                     const std::vector<std::string>& sources,
                                     const OdometryInput& odometry, const SE3& T_world_first) {
  const Trajectory& T_odom_lidar = odometry.T_odom_lidar;
  const size_t n = T_odom_lidar.size();
  std::map<int64_t, size_t> pose_of_stamp;
  for (size_t k = 0; k < n; ++k) pose_of_stamp[T_odom_lidar.stamps[k].ns] = k;
  SequenceBaResult out;
  out.from_window.assign(n > 0 ? n - 1 : 0, false);
  std::vector<SE3> motion(out.from_window.size());
  std::vector<Matrix6d> covariance(out.from_window.size());
  std::vector<size_t> given_by(out.from_window.size());
  for (size_t c = 0; c < chunks.size(); ++c) {
    const Trajectory& T = chunks[c].T_odom_lidar;
    const std::string& source = c < sources.size() ? sources[c] : fmt::format("chunk {}", c + 1);
    if (chunks[c].step_covariance.size() + 1 != T.size())
      throw Error(fmt::format("{}: {} poses but {} step covariances", source, T.size(),
                              chunks[c].step_covariance.size()));
    for (size_t j = 0; j + 1 < T.size(); ++j) {
      const auto it = pose_of_stamp.find(T.stamps[j].ns);
      if (it == pose_of_stamp.end() || it->second + 1 >= n ||
          T_odom_lidar.stamps[it->second + 1] != T.stamps[j + 1]) {
        throw Error(fmt::format(
            "{}: its poses at {} s and {} s are not consecutive poses of the odometry (a chunk of "
            "another recording, or of another odometry?)",
            source, to_seconds_text(T.stamps[j]), to_seconds_text(T.stamps[j + 1])));
      }
      const size_t k = it->second;
      if (out.from_window[k]) {
        throw Error(fmt::format("{} and {} both give the motion from {} s: chunks must not overlap",
                                sources.at(given_by[k]), source, to_seconds_text(T.stamps[j])));
      }
      motion[k] = T.T_world_body[j].inverse() * T.T_world_body[j + 1];
      covariance[k] = chunks[c].step_covariance[j];
      out.from_window[k] = true;
      given_by[k] = c;
    }
  }
  Trajectory& chained = out.motions.T_odom_lidar;
  chained.stamps = T_odom_lidar.stamps;
  if (n == 0) return out;
  chained.T_world_body = {T_world_first};
  for (size_t k = 0; k + 1 < n; ++k) {
    if (!out.from_window[k]) {
      motion[k] = T_odom_lidar.T_world_body[k].inverse() * T_odom_lidar.T_world_body[k + 1];
      covariance[k] = odometry.step_covariance[k];
      ++out.motions_from_odometry;
    }
    chained.T_world_body.push_back(chained.T_world_body.back() * motion[k]);
  }
  out.motions.step_covariance = std::move(covariance);
  out.end_owned = n - 1;
  return out;
}

}  // namespace rigcal::gt
