#pragma once
// A recording written as ROS1 bags with ROS's own C++ API (bag_writer.cpp, built as C++17 like
// calib/io/bag.cpp), for the tests of rigcal's bag reading and conversion. The content follows
// the formulas below, which the tests evaluate again to check what rigcal read: Ouster-style
// clouds (x y z intensity t reflectivity ring ambient range, 48-byte records, rows padded), raw
// bayer_rggb8 images (rows padded), Imu at 100 Hz and NavSatFix at 10 Hz, over two bags split
// at 1.5 s, the first LZ4- and the second BZ2-compressed. Header stamps start at 1000 s; each
// message is recorded 1 ms after its header stamp (the record time).
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace rigcal::testing::bag {

constexpr int kClouds = 6, kCloudWidth = 64, kCloudHeight = 16, kPointStep = 48;
constexpr int kRowPadding = 16;  // bytes after each cloud row
constexpr int kImages = 6, kImageWidth = 32, kImageHeight = 24, kImageStepPadding = 8;
constexpr int kImu = 300, kFixes = 30;
constexpr int64_t kStart_ns = 1000'000'000'000, kRecordDelay_ns = 1'000'000;
constexpr int64_t kSplit_ns = kStart_ns + 1'500'000'000;

inline int64_t cloud_stamp_ns(int k) { return kStart_ns + k * 500'000'000LL; }  // 2 Hz
inline int64_t image_stamp_ns(int k) { return kStart_ns + 250'000'000 + k * 500'000'000LL; }
inline int64_t imu_stamp_ns(int k) { return kStart_ns + k * 10'000'000LL; }   // 100 Hz
inline int64_t fix_stamp_ns(int k) { return kStart_ns + k * 100'000'000LL; }  // 10 Hz

// Point p (row-major over the cloud) of cloud k.
inline float point_x(int k, int p) { return 1.0f + 0.01f * p + k; }
inline float point_y(int, int p) { return -2.0f + 0.003f * p; }
inline float point_z(int k, int p) { return 0.5f + 0.1f * (p % kCloudHeight) - 0.01f * k; }
inline float point_intensity(int k, int p) { return static_cast<float>((p * 7 + k) % 500); }
inline uint32_t point_t_ns(int, int p) { return static_cast<uint32_t>(p / kCloudHeight) * 48828u; }
inline uint16_t point_ring(int, int p) { return static_cast<uint16_t>(p % kCloudHeight); }
inline uint16_t point_reflectivity(int k, int p) { return static_cast<uint16_t>((p + k) % 256); }
inline uint16_t point_ambient(int k, int p) { return static_cast<uint16_t>(100 + p + k); }
inline uint32_t point_range_mm(int k, int p) { return static_cast<uint32_t>(3000 + p * 3 + k); }
// Pixel (r, c) of image k.
inline uint8_t pixel(int k, int r, int c) {
  return static_cast<uint8_t>((k * 7 + r * 3 + c) % 256);
}
// IMU sample k.
inline double gyro(int k, int axis) { return 0.01 * (axis + 1) * ((k % 17) - 8); }
inline double accel(int k, int axis) { return axis == 2 ? 9.81 : 0.001 * k * (axis + 1); }
inline double imu_quat(int k, int i) { return i == 3 ? 1.0 : 0.0 * k; }  // x y z w: identity
inline double imu_covariance(int i) { return i % 4 == 0 ? 1e-4 * (i + 1) : 0.0; }
// Fix k.
inline double latitude(int k) { return 41.8902 + 1e-6 * k; }
inline double longitude(int k) { return 12.4922 - 2e-6 * k; }
inline double altitude(int k) { return 50.0 + 0.01 * k; }

// Writes <dir>/rec_0.bag (LZ4, stamps before kSplit_ns) and <dir>/rec_1.bag (BZ2, the rest)
// with the topics /ouster/points, /camera_left/image_raw, /imu/data, /gps/fix and, when
// `extra_topic`, /diagnostics as a std_msgs/String (a type rigcal does not convert).
void write_recording(const std::string& dir, bool extra_topic = true);

// A gyro log as sensor_msgs/Imu on `topic`: header stamps as given, angular velocity in rad/s,
// the accelerometer at rest on z (9.81 m/s^2), identity orientation.
struct ImuTopic {
  std::string topic;
  std::vector<int64_t> stamps_ns;
  std::vector<std::array<double, 3>> gyro;
};
// One LZ4 bag `file` with every topic's messages, recorded in header-stamp order 1 ms after
// their stamps.
void write_imu_bag(const std::string& file, const std::vector<ImuTopic>& topics);

// Any recording as messages: images (rows unpadded, `encoding` as ROS names it), clouds of the
// Ouster driver's 48-byte records (add_ouster_fields, one row), gyro logs.
struct ImageMessage {
  std::string topic;
  int64_t stamp_ns = 0;
  int width = 0, height = 0;
  std::string encoding;
  std::vector<uint8_t> data;
};
struct CloudMessage {
  std::string topic;
  int64_t stamp_ns = 0;
  std::vector<uint8_t> records;
};
struct Recording {
  std::vector<ImageMessage> images;
  std::vector<CloudMessage> clouds;
  std::vector<ImuTopic> imus;
};
// Writes `r` as two bags split at the middle of its time span: <stem>_0.bag (LZ4, the earlier
// half) and <stem>_1.bag (BZ2), every message recorded 1 ms after its header stamp.
void write_split_bags(const std::string& stem, const Recording& r);

}  // namespace rigcal::testing::bag
