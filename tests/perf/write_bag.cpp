// rigcal_perf_write_bag OUT.bag --mb N: a ROS1 bag the size of a real recording, for the bag
// conversion benchmark (doc/performance.md, "Bags"). Its topics are a VBR session's, at their
// rates: an Ouster OS0-128 (/ouster/points, 128 x 1024 points of the driver's 48-byte records,
// 10 Hz), two global-shutter cameras (/camera_left/image_raw and /camera_right/image_raw,
// 1388 x 700 bayer_rggb8, 10 Hz), two IMUs at 100 Hz (/imu/data, /ouster/imu) and a GNSS
// receiver (/gps/fix, 10 Hz). The bag ends with the first whole 100 ms of messages that takes it
// past N MB. Images are smooth shading with sensor noise, clouds a room's ranges with noise:
// content that compresses as real data does, not zeros.
//
// Built as C++17 with ROS's own headers (calib/io/bag.h says why).
#include <rosbag/bag.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/NavSatFix.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/PointField.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>

#include "../unit/ros_test_messages.h"

namespace {

constexpr int kRows = 128, kCols = 1024, kPointStep = 48;
constexpr int kWidth = 1388, kHeight = 700;
constexpr int64_t kStart_ns = 1'700'000'000'000'000'000;

using rigcal::testing::ros_msgs::ros_time;

template <class T>
void put(uint8_t* at, T v) {
  std::memcpy(at, &v, sizeof v);
}

sensor_msgs::PointCloud2 cloud(int k, std::mt19937& rng) {
  sensor_msgs::PointCloud2 m;
  m.header.stamp = ros_time(kStart_ns + k * 100'000'000LL);
  m.header.frame_id = "os_sensor";
  m.header.seq = k;
  m.height = kRows, m.width = kCols;
  rigcal::testing::ros_msgs::add_ouster_fields(m);
  m.point_step = kPointStep;
  m.row_step = kCols * kPointStep;
  m.data.assign(size_t(m.row_step) * kRows, 0);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  for (int r = 0; r < kRows; ++r) {
    const float elevation = (45.0f - 90.0f * r / (kRows - 1)) * float(M_PI) / 180.0f;
    for (int c = 0; c < kCols; ++c) {
      const float azimuth = 2.0f * float(M_PI) * c / kCols + 0.01f * k;
      // A 10 m x 6 m room, 3 m high, the sensor 1.2 m above its floor.
      const float dx = std::cos(elevation) * std::cos(azimuth);
      const float dy = std::cos(elevation) * std::sin(azimuth);
      const float dz = std::sin(elevation);
      float range =
          std::min(5.0f / std::max(std::abs(dx), 1e-3f), 3.0f / std::max(std::abs(dy), 1e-3f));
      range = std::min(range, (dz < 0 ? 1.2f : 1.8f) / std::max(std::abs(dz), 1e-3f));
      range += noise(rng);
      uint8_t* p = m.data.data() + size_t(r) * m.row_step + size_t(c) * kPointStep;
      put(p + 0, range * dx), put(p + 4, range * dy), put(p + 8, range * dz);
      put(p + 16, float(int(200 + 50 * std::sin(0.1 * c + r)) % 400));
      put(p + 20, uint32_t(c) * 97656u);
      put(p + 24, uint16_t((c + 3 * r) % 256)), put(p + 26, uint16_t(r));
      put(p + 28, uint16_t(300 + (c % 64))), put(p + 32, uint32_t(range * 1000.0f));
    }
  }
  m.is_dense = true;
  return m;
}

sensor_msgs::Image image(int k, const char* frame, std::mt19937& rng) {
  sensor_msgs::Image m;
  m.header.stamp = ros_time(kStart_ns + 5'000'000 + k * 100'000'000LL);
  m.header.frame_id = frame;
  m.header.seq = k;
  m.height = kHeight, m.width = kWidth;
  m.encoding = "bayer_rggb8";
  m.step = kWidth;
  m.data.resize(size_t(kWidth) * kHeight);
  std::uniform_int_distribution<int> noise(-2, 2);
  for (int r = 0; r < kHeight; ++r) {
    for (int c = 0; c < kWidth; ++c) {
      const double shade = 120 + 60 * std::sin(0.004 * (c + 7 * k)) * std::cos(0.006 * r);
      m.data[size_t(r) * kWidth + c] = uint8_t(std::clamp(int(shade) + noise(rng), 0, 255));
    }
  }
  return m;
}

sensor_msgs::Imu imu(int64_t stamp_ns, int k, const char* frame) {
  sensor_msgs::Imu m;
  m.header.stamp = ros_time(stamp_ns);
  m.header.frame_id = frame;
  m.header.seq = k;
  m.orientation.w = 1.0;
  m.angular_velocity.x = 0.3 * std::sin(0.05 * k);
  m.angular_velocity.y = 0.2 * std::cos(0.03 * k);
  m.angular_velocity.z = 0.1 * std::sin(0.02 * k);
  m.linear_acceleration.z = 9.81 + 0.01 * std::sin(0.1 * k);
  return m;
}

sensor_msgs::NavSatFix fix(int k) {
  sensor_msgs::NavSatFix m;
  m.header.stamp = ros_time(kStart_ns + k * 100'000'000LL);
  m.header.frame_id = "gps";
  m.status.status = 2, m.status.service = 1;
  m.latitude = 41.89 + 1e-6 * k, m.longitude = 12.49 - 2e-6 * k, m.altitude = 50.0;
  m.position_covariance = {0.0004, 0, 0, 0, 0.0009, 0, 0, 0, 0.0025};
  m.position_covariance_type = 2;
  return m;
}

int usage() {
  std::fprintf(stderr,
               "usage: rigcal_perf_write_bag OUT.bag --mb N [--lz4]\n"
               "  writes a VBR-like bag (OS0-128 clouds, two 1388x700 Bayer cameras, two 100 Hz\n"
               "  IMUs, GNSS fixes) of about N MB; --lz4 compresses its chunks\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4 || std::strcmp(argv[2], "--mb") != 0) return usage();
  const std::string out = argv[1];
  char* end = nullptr;
  const double mb = std::strtod(argv[3], &end);
  if (*end != '\0' || !(mb > 0)) return usage();
  const bool lz4 = argc > 4 && std::strcmp(argv[4], "--lz4") == 0;
  try {
    rosbag::Bag bag(out, rosbag::bagmode::Write);
    if (lz4) bag.setCompression(rosbag::compression::LZ4);
    std::mt19937 rng(7);
    const double limit = mb * 1e6;
    int k = 0;
    for (; double(bag.getSize()) < limit; ++k) {  // one 100 ms of the recording
      const int64_t t0 = kStart_ns + k * 100'000'000LL;
      const sensor_msgs::PointCloud2 c = cloud(k, rng);
      bag.write("/ouster/points", ros_time(c.header.stamp.toNSec() + 2'000'000), c);
      for (const char* cam : {"camera_left", "camera_right"}) {
        const sensor_msgs::Image i = image(k, cam, rng);
        bag.write(std::string("/") + cam + "/image_raw",
                  ros_time(i.header.stamp.toNSec() + 3'000'000), i);
      }
      for (int j = 0; j < 10; ++j) {
        const int64_t s = t0 + j * 10'000'000LL;
        bag.write("/imu/data", ros_time(s + 1'000'000), imu(s, 10 * k + j, "imu_link"));
        bag.write("/ouster/imu", ros_time(s + 1'500'000), imu(s + 700'000, 10 * k + j, "os_imu"));
      }
      bag.write("/gps/fix", ros_time(t0 + 4'000'000), fix(k));
    }
    bag.close();
    std::printf("%s: %d clouds, %d images, %d IMU samples, %d fixes\n", out.c_str(), k, 2 * k,
                20 * k, k);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rigcal_perf_write_bag: %s\n", e.what());
    return 1;
  }
  return 0;
}
