#include "rigcal/core/trajectory.h"

namespace rigcal {

double path_length(const Trajectory& trajectory) {
  double length = 0.0;
  for (size_t i = 1; i < trajectory.size(); ++i) {
    length += (trajectory.T_world_body[i].t - trajectory.T_world_body[i - 1].t).norm();
  }
  return length;
}

}  // namespace rigcal
