#pragma once
// The scan type every LiDAR reader of rigcal produces and the LiDAR odometry consumes: one sweep
// of points in the sensor frame, each with its own time. sim::LidarPoint (calib/sim/lidar.h) is the
// simulator's older form of the same idea and should become this type.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "rigcal/core/time.h"

namespace rigcal {

struct ScanPoint {
  Eigen::Vector3f p = Eigen::Vector3f::Zero();  // sensor frame, m
  int64_t t_ns = 0;                             // since Scan::stamp
  float intensity = 0;  // the reader's documented intensity field (Ouster: SIGNAL, else
                        // REFLECTIVITY)
  uint16_t ring = 0;    // beam row, 0 = top
  uint16_t column = 0;  // destaggered column (azimuth index), when the sensor has columns
  uint16_t reflectivity = 0;
  uint16_t near_ir = 0;
  uint32_t range_mm = 0;  // range as measured, mm (0 never appears: no return is no point)
};

struct Scan {
  Time stamp;  // on the sensor's clock: the time every point's t_ns counts from
  std::vector<ScanPoint> points;
  bool point_times = true;  // false: the source had no per-point times (every t_ns is 0)
};

}  // namespace rigcal
