// Built as C++17: ROS's generated message headers do not compile as C++20 (see calib/io/bag.h).
#include "bag_writer.h"

#include <rosbag/bag.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/NavSatFix.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/PointField.h>
#include <std_msgs/String.h>

#include <algorithm>
#include <climits>
#include <cstring>
#include <tuple>

#include "ros_test_messages.h"

namespace rigcal::testing::bag {
namespace {

using ros_msgs::ros_time;

template <class T>
void put(std::vector<uint8_t>& data, size_t at, T v) {
  std::memcpy(data.data() + at, &v, sizeof v);
}

sensor_msgs::PointCloud2 cloud(int k) {
  sensor_msgs::PointCloud2 m;
  m.header.stamp = ros_time(cloud_stamp_ns(k));
  m.header.frame_id = "os_sensor";
  m.header.seq = k;
  m.height = kCloudHeight;
  m.width = kCloudWidth;
  ros_msgs::add_ouster_fields(m);
  m.is_bigendian = false;
  m.point_step = kPointStep;
  m.row_step = kCloudWidth * kPointStep + kRowPadding;
  m.data.assign(size_t(m.row_step) * m.height, 0xAB);  // padding bytes: not zero, to be seen
  for (int r = 0; r < kCloudHeight; ++r) {
    for (int c = 0; c < kCloudWidth; ++c) {
      const int p = r * kCloudWidth + c;
      const size_t at = size_t(r) * m.row_step + size_t(c) * kPointStep;
      std::memset(m.data.data() + at, 0, kPointStep);
      put(m.data, at + 0, point_x(k, p)), put(m.data, at + 4, point_y(k, p));
      put(m.data, at + 8, point_z(k, p)), put(m.data, at + 16, point_intensity(k, p));
      put(m.data, at + 20, point_t_ns(k, p)), put(m.data, at + 24, point_reflectivity(k, p));
      put(m.data, at + 26, point_ring(k, p)), put(m.data, at + 28, point_ambient(k, p));
      put(m.data, at + 32, point_range_mm(k, p));
    }
  }
  m.is_dense = true;
  return m;
}

sensor_msgs::Image image(int k) {
  sensor_msgs::Image m;
  m.header.stamp = ros_time(image_stamp_ns(k));
  m.header.frame_id = "camera_left";
  m.height = kImageHeight, m.width = kImageWidth;
  m.encoding = "bayer_rggb8";
  m.is_bigendian = 0;
  m.step = kImageWidth + kImageStepPadding;
  m.data.assign(size_t(m.step) * m.height, 0xCD);
  for (int r = 0; r < kImageHeight; ++r)
    for (int c = 0; c < kImageWidth; ++c) m.data[size_t(r) * m.step + c] = pixel(k, r, c);
  return m;
}

sensor_msgs::Imu imu(int k) {
  sensor_msgs::Imu m;
  m.header.stamp = ros_time(imu_stamp_ns(k));
  m.header.frame_id = "imu_link";
  m.orientation.x = imu_quat(k, 0), m.orientation.y = imu_quat(k, 1);
  m.orientation.z = imu_quat(k, 2), m.orientation.w = imu_quat(k, 3);
  m.angular_velocity.x = gyro(k, 0), m.angular_velocity.y = gyro(k, 1);
  m.angular_velocity.z = gyro(k, 2);
  m.linear_acceleration.x = accel(k, 0), m.linear_acceleration.y = accel(k, 1);
  m.linear_acceleration.z = accel(k, 2);
  for (int i = 0; i < 9; ++i) {
    m.orientation_covariance[i] = imu_covariance(i);
    m.angular_velocity_covariance[i] = 2 * imu_covariance(i);
    m.linear_acceleration_covariance[i] = 3 * imu_covariance(i);
  }
  return m;
}

sensor_msgs::NavSatFix fix(int k) {
  sensor_msgs::NavSatFix m;
  m.header.stamp = ros_time(fix_stamp_ns(k));
  m.header.frame_id = "gps";
  m.status.status = 2, m.status.service = 1;
  m.latitude = latitude(k), m.longitude = longitude(k), m.altitude = altitude(k);
  // A receiver that knows its whole covariance (row-major ENU, m^2): east and north correlated.
  m.position_covariance = {0.0004,  0.0003, 0.0001,  0.0003, 0.0009,
                           -0.0002, 0.0001, -0.0002, 0.0025};
  m.position_covariance_type = 3;
  return m;
}

sensor_msgs::Imu gyro_message(const ImuTopic& t, size_t k) {
  sensor_msgs::Imu m;
  m.header.stamp = ros_time(t.stamps_ns[k]);
  m.header.seq = static_cast<uint32_t>(k);
  m.header.frame_id = t.topic;
  m.orientation.w = 1.0;
  m.angular_velocity.x = t.gyro[k][0];
  m.angular_velocity.y = t.gyro[k][1];
  m.angular_velocity.z = t.gyro[k][2];
  m.linear_acceleration.z = 9.81;
  return m;
}

}  // namespace

void write_recording(const std::string& dir, bool extra_topic) {
  rosbag::Bag first(dir + "/rec_0.bag", rosbag::bagmode::Write);
  first.setCompression(rosbag::compression::LZ4);
  rosbag::Bag second(dir + "/rec_1.bag", rosbag::bagmode::Write);
  second.setCompression(rosbag::compression::BZ2);
  auto write = [&](const std::string& topic, int64_t stamp_ns, const auto& message) {
    rosbag::Bag& bag = stamp_ns < kSplit_ns ? first : second;
    bag.write(topic, ros_time(stamp_ns + kRecordDelay_ns), message);
  };
  // Written in time order per topic; the bags index by record time.
  for (int k = 0; k < kImu; ++k) write("/imu/data", imu_stamp_ns(k), imu(k));
  for (int k = 0; k < kClouds; ++k) write("/ouster/points", cloud_stamp_ns(k), cloud(k));
  for (int k = 0; k < kImages; ++k) write("/camera_left/image_raw", image_stamp_ns(k), image(k));
  for (int k = 0; k < kFixes; ++k) write("/gps/fix", fix_stamp_ns(k), fix(k));
  if (extra_topic) {
    std_msgs::String s;
    s.data = "ok";
    write("/diagnostics", kStart_ns, s);
  }
  first.close();
  second.close();
}

void write_imu_bag(const std::string& file, const std::vector<ImuTopic>& topics) {
  std::vector<std::tuple<int64_t, size_t, size_t>> order;  // stamp, topic, sample
  for (size_t t = 0; t < topics.size(); ++t) {
    for (size_t k = 0; k < topics[t].stamps_ns.size(); ++k)
      order.emplace_back(topics[t].stamps_ns[k], t, k);
  }
  std::sort(order.begin(), order.end());
  rosbag::Bag out(file, rosbag::bagmode::Write);
  out.setCompression(rosbag::compression::LZ4);
  for (const auto& [stamp_ns, t, k] : order)
    out.write(topics[t].topic, ros_time(stamp_ns + kRecordDelay_ns), gyro_message(topics[t], k));
  out.close();
}

void write_split_bags(const std::string& stem, const Recording& r) {
  int64_t first_ns = INT64_MAX, last_ns = INT64_MIN;
  auto span = [&](int64_t ns) {
    first_ns = std::min(first_ns, ns), last_ns = std::max(last_ns, ns);
  };
  for (const ImageMessage& m : r.images) span(m.stamp_ns);
  for (const CloudMessage& m : r.clouds) span(m.stamp_ns);
  for (const ImuTopic& t : r.imus)
    for (const int64_t ns : t.stamps_ns) span(ns);
  const int64_t split_ns = first_ns + (last_ns - first_ns) / 2;
  rosbag::Bag first(stem + "_0.bag", rosbag::bagmode::Write);
  first.setCompression(rosbag::compression::LZ4);
  rosbag::Bag second(stem + "_1.bag", rosbag::bagmode::Write);
  second.setCompression(rosbag::compression::BZ2);
  auto write = [&](const std::string& topic, int64_t stamp_ns, const auto& message) {
    (stamp_ns < split_ns ? first : second)
        .write(topic, ros_time(stamp_ns + kRecordDelay_ns), message);
  };
  // As a recorder does: in time order over every topic (a time-ordered read of a bag written
  // topic after topic decompresses a chunk per message).
  std::vector<std::tuple<int64_t, int, size_t, size_t>> order;  // stamp, kind, index, sample
  for (size_t i = 0; i < r.images.size(); ++i) order.emplace_back(r.images[i].stamp_ns, 0, i, 0);
  for (size_t i = 0; i < r.clouds.size(); ++i) order.emplace_back(r.clouds[i].stamp_ns, 1, i, 0);
  for (size_t i = 0; i < r.imus.size(); ++i)
    for (size_t k = 0; k < r.imus[i].stamps_ns.size(); ++k)
      order.emplace_back(r.imus[i].stamps_ns[k], 2, i, k);
  std::sort(order.begin(), order.end());
  for (const auto& [stamp_ns, kind, i, k] : order) {
    if (kind == 0) {
      const ImageMessage& image = r.images[i];
      sensor_msgs::Image m;
      m.header.stamp = ros_time(image.stamp_ns);
      m.header.frame_id = image.topic;
      m.width = image.width, m.height = image.height;
      m.encoding = image.encoding;
      m.step = static_cast<uint32_t>(image.data.size() / std::max(image.height, 1));
      m.data = image.data;
      write(image.topic, stamp_ns, m);
    } else if (kind == 1) {
      const CloudMessage& cloud = r.clouds[i];
      sensor_msgs::PointCloud2 m;
      m.header.stamp = ros_time(cloud.stamp_ns);
      m.header.frame_id = "os_sensor";
      ros_msgs::add_ouster_fields(m);
      m.point_step = kPointStep;
      m.height = 1;
      m.width = static_cast<uint32_t>(cloud.records.size() / kPointStep);
      m.row_step = m.width * kPointStep;
      m.is_bigendian = false;
      m.is_dense = true;
      m.data = cloud.records;
      write(cloud.topic, stamp_ns, m);
    } else {
      write(r.imus[i].topic, stamp_ns, gyro_message(r.imus[i], k));
    }
  }
  first.close();
  second.close();
}

}  // namespace rigcal::testing::bag
