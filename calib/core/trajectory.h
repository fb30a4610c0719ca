#pragma once
// The one trajectory type of rigcal: poses of a tracked frame ("body") in a fixed frame
// ("world"), each with its stamp. Readers and writers live in calib/io/trajectory_io.h.
#include <optional>
#include <vector>

#include "rigcal/core/se3.h"
#include "rigcal/core/time.h"

namespace rigcal {

struct Trajectory {
  // One stamp a pose, strictly increasing. Files without stamps (KITTI without a times file) get
  // the frame index as stamp (0 s, 1 s, 2 s ...) and has_stamps = false.
  std::vector<Time> stamps;
  std::vector<SE3> T_world_body;
  bool has_stamps = true;

  size_t size() const { return T_world_body.size(); }
  bool empty() const { return T_world_body.empty(); }
};

// Length of the path through the positions, m.
double path_length(const Trajectory& trajectory);

// The pose `fraction` of the way from T_a to T_b (0: T_a, 1: T_b): the rotation by slerp, the
// translation linearly.
SE3 interpolate(const SE3& T_a, const SE3& T_b, double fraction);

// The pose at t: a pose stamped t as it is, else interpolated between the poses before and after
// t when they are no more than max_gap apart; none outside the stamps or across a longer gap.
std::optional<SE3> pose_at(const Trajectory& trajectory, Time t, Time max_gap);

}  // namespace rigcal
