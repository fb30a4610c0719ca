#pragma once
// ROS1 messages from their serialized bytes (doc/formats.md, "ROS1 bags"): the sensor messages a
// rig records, decoded without ROS's generated headers so that every step reads them in C++20
// and a fuzz target can feed them any bytes. ROS1 serialization is little-endian; a string or a
// variable array is a uint32 length then its elements; fixed arrays have no length.
//
// Each decoder throws rigcal::Error saying what was cut or inconsistent ("PointCloud2: data holds
// 100 bytes, width 10 x height 1 x point_step 48 needs 480"); the caller adds the bag, topic and
// message index. Byte views point into the caller's buffer, which must outlive them.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rigcal/core/se3.h"
#include "rigcal/core/time.h"

namespace rigcal::io {

// std_msgs/Header.
struct RosHeader {
  uint32_t seq = 0;
  Time stamp;
  std::string frame_id;
};

// sensor_msgs/PointField (datatype 1..8: int8 uint8 int16 uint16 int32 uint32 float32 float64).
struct RosPointField {
  std::string name;
  uint32_t offset = 0;
  uint8_t datatype = 0;
  uint32_t count = 1;
};
// Bytes of one element of a PointField datatype; 0 for an unknown datatype.
size_t point_field_size(uint8_t datatype);

// sensor_msgs/PointCloud2. `data` holds height rows of row_step bytes, each of width records of
// point_step bytes (the rest of a row is padding).
struct RosPointCloud2 {
  RosHeader header;
  uint32_t height = 0, width = 0;
  std::vector<RosPointField> fields;
  bool is_bigendian = false;
  uint32_t point_step = 0, row_step = 0;
  std::string_view data;
  bool is_dense = false;
};

// sensor_msgs/Image: height rows of `step` bytes. Encodings as ROS names them (mono8, mono16,
// bgr8, rgb8, bgra8, rgba8, bayer_rggb8, bayer_bggr8, bayer_gbrg8, bayer_grbg8, their 16-bit
// forms, ...).
struct RosImage {
  RosHeader header;
  uint32_t height = 0, width = 0;
  std::string encoding;
  bool is_bigendian = false;
  uint32_t step = 0;
  std::string_view data;
};
// Channels and bytes per channel of an encoding this reader stores; nullopt for the others.
struct ImageLayout {
  int channels = 1, bytes_per_channel = 1;
};
std::optional<ImageLayout> image_layout(std::string_view encoding);

// sensor_msgs/Imu (orientation x y z w; covariances row-major, -1 at [0] meaning "not given").
struct RosImu {
  RosHeader header;
  std::array<double, 4> orientation_xyzw{};
  std::array<double, 9> orientation_covariance{};
  std::array<double, 3> angular_velocity{};  // rad/s
  std::array<double, 9> angular_velocity_covariance{};
  std::array<double, 3> linear_acceleration{};  // m/s^2
  std::array<double, 9> linear_acceleration_covariance{};
};

// sensor_msgs/NavSatFix (status -1 no fix, 0 fix, 1 SBAS, 2 GBAS/RTK; covariance ENU, m^2).
struct RosNavSatFix {
  RosHeader header;
  int8_t status = -1;
  uint16_t service = 0;
  double latitude_deg = 0, longitude_deg = 0, altitude_m = 0;
  std::array<double, 9> position_covariance{};
  uint8_t position_covariance_type = 0;  // 0 unknown, 1 approximated, 2 diagonal, 3 known
};

// A pose message: geometry_msgs/PoseStamped, geometry_msgs/PoseWithCovarianceStamped or
// nav_msgs/Odometry (its pose part), as T_frame_child (frame_id's frame, child the tracked body).
struct RosPose {
  RosHeader header;
  std::string child_frame_id;  // nav_msgs/Odometry only
  SE3 T_frame_child;
};

RosHeader decode_ros_header(std::string_view bytes);  // a message that starts with a Header
RosPointCloud2 decode_point_cloud2(std::string_view bytes);
RosImage decode_image(std::string_view bytes);
RosImu decode_imu(std::string_view bytes);
RosNavSatFix decode_nav_sat_fix(std::string_view bytes);
// `datatype`: geometry_msgs/PoseStamped, geometry_msgs/PoseWithCovarianceStamped or
// nav_msgs/Odometry.
RosPose decode_pose(std::string_view bytes, std::string_view datatype);

// std_msgs/String (the Ouster driver's metadata topic holds the sensor's metadata JSON).
std::string decode_string_msg(std::string_view bytes);
// A message whose one field is a uint8[]: ouster_ros/PacketMsg (`buf`, one UDP payload).
std::string_view decode_packet_msg(std::string_view bytes);

// The message types the decoders above read, by their ROS names.
enum class RosType { point_cloud2, image, imu, nav_sat_fix, pose, ouster_packets, other };
RosType ros_type(std::string_view datatype);

}  // namespace rigcal::io
