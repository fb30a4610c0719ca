#pragma once
// Pieces of ROS messages that the test and benchmark bag writers share (bag_writer.cpp,
// tests/perf/write_bag.cpp). ROS types: include from C++17 sources only (calib/io/bag.h says why).
#include <ros/time.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/PointField.h>

#include <cstdint>

namespace rigcal::testing::ros_msgs {

inline ros::Time ros_time(int64_t ns) {
  ros::Time t;
  t.fromNSec(static_cast<uint64_t>(ns));
  return t;
}

// The Ouster ROS driver's 48-byte point record as PointCloud2 fields: x y z (float32 at 0, 4,
// 8), intensity (float32, 16), t (uint32 ns, 20), reflectivity, ring, ambient (uint16 at 24, 26,
// 28) and range (uint32 mm, 32).
inline void add_ouster_fields(sensor_msgs::PointCloud2& m) {
  auto field = [&](const char* name, uint32_t offset, uint8_t type) {
    sensor_msgs::PointField f;
    f.name = name, f.offset = offset, f.datatype = type, f.count = 1;
    m.fields.push_back(f);
  };
  using F = sensor_msgs::PointField;
  field("x", 0, F::FLOAT32), field("y", 4, F::FLOAT32), field("z", 8, F::FLOAT32);
  field("intensity", 16, F::FLOAT32), field("t", 20, F::UINT32);
  field("reflectivity", 24, F::UINT16), field("ring", 26, F::UINT16);
  field("ambient", 28, F::UINT16), field("range", 32, F::UINT32);
}

}  // namespace rigcal::testing::ros_msgs
