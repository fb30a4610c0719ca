#include "rigcal/io/ros_messages.h"

#include <fmt/format.h>

#include <cmath>
#include <cstring>

#include "rigcal/core/error.h"
#include "rigcal/core/text.h"

namespace rigcal::io {
namespace {

// A cursor over serialized bytes; every read checks the bytes are there.
class Reader {
 public:
  Reader(std::string_view bytes, std::string_view type) : bytes_(bytes), type_(type) {}

  template <class T>
  T pod(std::string_view what) {
    need(sizeof(T), what);
    T v;
    std::memcpy(&v, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  std::string_view bytes(size_t n, std::string_view what) {
    need(n, what);
    const std::string_view v = bytes_.substr(pos_, n);
    pos_ += n;
    return v;
  }
  // A uint32 length, then that many bytes.
  std::string_view sized(std::string_view what) { return bytes(pod<uint32_t>(what), what); }
  std::string string(std::string_view what) { return std::string(sized(what)); }
  template <size_t N>
  std::array<double, N> doubles(std::string_view what) {
    std::array<double, N> v;
    for (double& x : v) x = pod<double>(what);
    return v;
  }
  RosHeader header() {
    RosHeader h;
    h.seq = pod<uint32_t>("header.seq");
    const uint32_t sec = pod<uint32_t>("header.stamp");
    const uint32_t nsec = pod<uint32_t>("header.stamp");
    if (nsec >= 1'000'000'000u) fail(fmt::format("header.stamp has {} ns past the second", nsec));
    h.stamp = Time{int64_t{sec} * 1'000'000'000 + nsec};
    h.frame_id = printable(sized("header.frame_id"), 256);
    return h;
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw Error(fmt::format("{}: {}", type_, what));
  }
  // Trailing bytes are allowed (a newer message definition may append fields).
  size_t position() const { return pos_; }

 private:
  void need(size_t n, std::string_view what) const {
    if (n > bytes_.size() - pos_) {
      fail(fmt::format("cut short at byte {} of {} reading {} ({} bytes needed)", pos_,
                       bytes_.size(), what, n));
    }
  }
  std::string_view bytes_;
  size_t pos_ = 0;
  std::string_view type_;
};

SE3 pose_from(Reader& r, std::string_view what) {
  const std::array<double, 3> p = r.doubles<3>(what);
  const std::array<double, 4> q = r.doubles<4>(what);  // x y z w
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (double x : p)
    if (!std::isfinite(x)) r.fail(fmt::format("{} position is not finite", what));
  if (!std::isfinite(norm) || std::abs(norm - 1) > 1e-3) {
    r.fail(fmt::format("{} orientation is not a unit quaternion (norm {})", what, norm));
  }
  return SE3::from_quaternion(Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized(),
                              Eigen::Vector3d(p[0], p[1], p[2]));
}

}  // namespace

size_t point_field_size(uint8_t datatype) {
  switch (datatype) {
    case 1:
    case 2:
      return 1;
    case 3:
    case 4:
      return 2;
    case 5:
    case 6:
    case 7:
      return 4;
    case 8:
      return 8;
    default:
      return 0;
  }
}

std::optional<ImageLayout> image_layout(std::string_view e) {
  if (e == "mono8" || e == "8UC1" || (e.starts_with("bayer_") && e.ends_with("8"))) {
    return ImageLayout{1, 1};
  }
  if (e == "mono16" || e == "16UC1" || (e.starts_with("bayer_") && e.ends_with("16"))) {
    return ImageLayout{1, 2};
  }
  if (e == "bgr8" || e == "rgb8" || e == "8UC3") return ImageLayout{3, 1};
  if (e == "bgra8" || e == "rgba8" || e == "8UC4") return ImageLayout{4, 1};
  if (e == "bgr16" || e == "rgb16" || e == "16UC3") return ImageLayout{3, 2};
  return std::nullopt;
}

RosHeader decode_ros_header(std::string_view bytes) {
  Reader r(bytes, "header");
  return r.header();
}

RosPointCloud2 decode_point_cloud2(std::string_view bytes) {
  Reader r(bytes, "PointCloud2");
  RosPointCloud2 m;
  m.header = r.header();
  m.height = r.pod<uint32_t>("height");
  m.width = r.pod<uint32_t>("width");
  const uint32_t n_fields = r.pod<uint32_t>("fields");
  // A field takes at least 13 bytes: never reserve more than the bytes can hold.
  if (n_fields > bytes.size() / 13) r.fail(fmt::format("{} fields cannot fit", n_fields));
  m.fields.reserve(n_fields);
  for (uint32_t i = 0; i < n_fields; ++i) {
    RosPointField f;
    f.name = printable(r.sized("fields.name"), 64);
    f.offset = r.pod<uint32_t>("fields.offset");
    f.datatype = r.pod<uint8_t>("fields.datatype");
    f.count = r.pod<uint32_t>("fields.count");
    m.fields.push_back(std::move(f));
  }
  m.is_bigendian = r.pod<uint8_t>("is_bigendian") != 0;
  m.point_step = r.pod<uint32_t>("point_step");
  m.row_step = r.pod<uint32_t>("row_step");
  m.data = r.sized("data");
  m.is_dense = r.pod<uint8_t>("is_dense") != 0;

  for (const RosPointField& f : m.fields) {
    const size_t size = point_field_size(f.datatype);
    if (size == 0) r.fail(fmt::format("field '{}' has datatype {}, not 1..8", f.name, f.datatype));
    if (uint64_t{f.offset} + uint64_t{size} * f.count > m.point_step) {
      r.fail(fmt::format("field '{}' (offset {}, {} x {} bytes) lies past point_step {}", f.name,
                         f.offset, f.count, size, m.point_step));
    }
  }
  if (uint64_t{m.width} * m.point_step > m.row_step) {
    r.fail(fmt::format("row_step {} is less than width {} x point_step {}", m.row_step, m.width,
                       m.point_step));
  }
  // The last row may end at its last record (row_step's padding is not required after it).
  const uint64_t need =
      m.height == 0 ? 0 : uint64_t{m.row_step} * (m.height - 1) + uint64_t{m.width} * m.point_step;
  if (m.data.size() < need) {
    r.fail(fmt::format("data holds {} bytes; height {} x row_step {} needs {}", m.data.size(),
                       m.height, m.row_step, need));
  }
  return m;
}

RosImage decode_image(std::string_view bytes) {
  Reader r(bytes, "Image");
  RosImage m;
  m.header = r.header();
  m.height = r.pod<uint32_t>("height");
  m.width = r.pod<uint32_t>("width");
  m.encoding = printable(r.sized("encoding"), 32);
  m.is_bigendian = r.pod<uint8_t>("is_bigendian") != 0;
  m.step = r.pod<uint32_t>("step");
  m.data = r.sized("data");
  if (const std::optional<ImageLayout> l = image_layout(m.encoding)) {
    const uint64_t row = uint64_t{m.width} * l->channels * l->bytes_per_channel;
    if (row > m.step) {
      r.fail(fmt::format("step {} is less than width {} x {} bytes of {}", m.step, m.width,
                         row / std::max<uint32_t>(m.width, 1), m.encoding));
    }
  }
  if (m.data.size() < uint64_t{m.step} * m.height) {
    r.fail(fmt::format("data holds {} bytes; height {} x step {} needs {}", m.data.size(), m.height,
                       m.step, uint64_t{m.step} * m.height));
  }
  return m;
}

RosImu decode_imu(std::string_view bytes) {
  Reader r(bytes, "Imu");
  RosImu m;
  m.header = r.header();
  m.orientation_xyzw = r.doubles<4>("orientation");
  m.orientation_covariance = r.doubles<9>("orientation_covariance");
  m.angular_velocity = r.doubles<3>("angular_velocity");
  m.angular_velocity_covariance = r.doubles<9>("angular_velocity_covariance");
  m.linear_acceleration = r.doubles<3>("linear_acceleration");
  m.linear_acceleration_covariance = r.doubles<9>("linear_acceleration_covariance");
  return m;
}

RosNavSatFix decode_nav_sat_fix(std::string_view bytes) {
  Reader r(bytes, "NavSatFix");
  RosNavSatFix m;
  m.header = r.header();
  m.status = r.pod<int8_t>("status.status");
  m.service = r.pod<uint16_t>("status.service");
  m.latitude_deg = r.pod<double>("latitude");
  m.longitude_deg = r.pod<double>("longitude");
  m.altitude_m = r.pod<double>("altitude");
  m.position_covariance = r.doubles<9>("position_covariance");
  m.position_covariance_type = r.pod<uint8_t>("position_covariance_type");
  return m;
}

RosPose decode_pose(std::string_view bytes, std::string_view datatype) {
  Reader r(bytes, datatype);
  RosPose m;
  m.header = r.header();
  if (datatype == "nav_msgs/Odometry") m.child_frame_id = printable(r.sized("child_frame_id"), 256);
  m.T_frame_child = pose_from(r, "pose");
  return m;
}

std::string decode_string_msg(std::string_view bytes) {
  Reader r(bytes, "String");
  return std::string(r.sized("data"));
}

std::string_view decode_packet_msg(std::string_view bytes) {
  Reader r(bytes, "PacketMsg");
  return r.sized("buf");
}

RosType ros_type(std::string_view d) {
  if (d == "sensor_msgs/PointCloud2") return RosType::point_cloud2;
  if (d == "sensor_msgs/Image") return RosType::image;
  if (d == "sensor_msgs/Imu") return RosType::imu;
  if (d == "sensor_msgs/NavSatFix") return RosType::nav_sat_fix;
  if (d == "geometry_msgs/PoseStamped" || d == "geometry_msgs/PoseWithCovarianceStamped" ||
      d == "nav_msgs/Odometry") {
    return RosType::pose;
  }
  if (d == "ouster_ros/PacketMsg" || d == "ouster_sensor_msgs/PacketMsg") {
    return RosType::ouster_packets;
  }
  return RosType::other;
}

}  // namespace rigcal::io
