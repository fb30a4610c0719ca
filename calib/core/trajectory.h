#pragma once
// The one trajectory type of rigcal: poses of a tracked frame ("body") in a fixed frame
// ("world"), each with its stamp. Readers and writers live in calib/io/trajectory_io.h.
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

}  // namespace rigcal
