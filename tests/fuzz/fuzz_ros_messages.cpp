// ROS1 message decoders (io/ros_messages.h) on any bytes: the first byte chooses the type
// (PointCloud2, Image, Imu, NavSatFix, PoseStamped, PoseWithCovarianceStamped, Odometry), the
// rest is the serialized message. A decoded message's views must lie inside the input.
#include "fuzz_common.h"
#include "rigcal/io/ros_messages.h"

static int fuzz_ros_messages(const uint8_t* data, size_t size) {
  using namespace rigcal;
  if (size == 0) return 0;
  const std::string_view bytes = fuzz::as_text(data + 1, size - 1);
  auto inside = [&](std::string_view v) {
    if (!v.empty() &&
        (v.data() < bytes.data() || v.data() + v.size() > bytes.data() + bytes.size()))
      fuzz::finding("a decoded view lies outside the message", std::to_string(v.size()));
  };
  static const char* kPoses[] = {"geometry_msgs/PoseStamped",
                                 "geometry_msgs/PoseWithCovarianceStamped", "nav_msgs/Odometry"};
  fuzz::expect_only_rigcal_errors([&] {
    switch (data[0] % 7) {
      case 0: {
        const io::RosPointCloud2 m = io::decode_point_cloud2(bytes);
        inside(m.data);
        if (m.height > 0 &&
            uint64_t{m.row_step} * (m.height - 1) + uint64_t{m.width} * m.point_step >
                m.data.size())
          fuzz::finding("PointCloud2 rows past its data", std::to_string(m.data.size()));
        break;
      }
      case 1: {
        const io::RosImage m = io::decode_image(bytes);
        inside(m.data);
        if (uint64_t{m.step} * m.height > m.data.size())
          fuzz::finding("Image rows past its data", std::to_string(m.data.size()));
        break;
      }
      case 2:
        io::decode_imu(bytes);
        break;
      case 3:
        io::decode_nav_sat_fix(bytes);
        break;
      default:
        io::decode_pose(bytes, kPoses[(data[0] % 7) - 4]);
        break;
    }
  });
  return 0;
}
RIGCAL_FUZZ_TARGET(ros_messages, fuzz_ros_messages)
