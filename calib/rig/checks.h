#pragma once
// Internal: the rig's consistency checks, shared by validate() and the YAML reader (which adds
// file and line to each problem).
#include <string>
#include <vector>

#include "rigcal/rig/rig.h"

namespace rigcal::rig {

struct Problem {
  std::string key;   // "cam_l.intrinsics", "rigcal.base_frame"
  std::string what;  // what is wrong and what was expected
};

// Every problem of the rig, in sensor order.
std::vector<Problem> find_problems(const Rig& rig);
// "" for a proper rotation (within kRotationTolerance), else what is wrong.
std::string check_rotation(const Eigen::Matrix3d& R);

}  // namespace rigcal::rig
