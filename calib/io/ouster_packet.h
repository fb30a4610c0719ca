#pragma once
// One Ouster UDP packet (doc/formats.md, "Ouster captures"): a lidar packet in the metadata's
// profile (LEGACY, RNG19_RFL8_SIG16_NIR16[_DUAL], RNG15_RFL8_NIR8[_DUAL] and FUSA's dual RNG15)
// decoded to its header, its columns' headers and its pixels; the STANDARD footer's CRC-64/XZ;
// and the LEGACY IMU packet.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "rigcal/core/time.h"
#include "rigcal/io/ouster_metadata.h"

namespace rigcal::io {

enum class OusterField {
  Range,  // mm, u32
  Range2,
  Flags,  // u8
  Flags2,
  Reflectivity,  // u8
  Reflectivity2,
  Signal,  // u16
  Signal2,
  NearIr,  // u16
  Window,  // u8
};
std::string_view to_string(OusterField field);

// A channel-block field: bits [first_bit, last_bit] of the block (inclusive), then shifted left
// by `upshift` (RNG15's range is in 8 mm units, its near-IR in units of 16).
struct OusterFieldSpec {
  OusterField field;
  int first_bit, last_bit, upshift;
};
// The fields of a profile, in the order the profile lists them.
std::span<const OusterFieldSpec> ouster_fields(OusterLidarProfile profile);
// Bytes of one channel block.
size_t ouster_block_bytes(OusterLidarProfile profile);

// Per-pixel images of a profile's fields, row-major (row = beam); a field the profile does not
// have is empty.
struct OusterImages {
  std::vector<uint32_t> range, range2;
  std::vector<uint16_t> signal, signal2, near_ir;
  std::vector<uint8_t> reflectivity, reflectivity2, flags, flags2, window;

  void resize(OusterLidarProfile profile, size_t pixels);  // the profile's fields, zeroed
  bool has(OusterField f) const;
  uint32_t get(OusterField f, size_t i) const;
  void set(OusterField f, size_t i, uint32_t value);
  void zero();
};

struct OusterLidarPacket {
  uint16_t packet_type = 1;  // 1 lidar (0 for LEGACY, which has no packet header)
  uint32_t frame_id = 0;     // u16 (u32 for FUSA)
  uint32_t init_id = 0;      // 0 for LEGACY
  uint64_t prod_sn = 0;      // 0 for LEGACY
  uint8_t alert_flags = 0;
  // Per column (columns_per_packet): timestamp ns (sensor clock), measurement_id (the column of
  // the frame), status (bit 0: valid; LEGACY: 0xFFFFFFFF when valid), encoder (LEGACY only).
  std::vector<uint64_t> timestamp;
  std::vector<uint16_t> measurement_id;
  std::vector<uint32_t> status;
  std::vector<uint32_t> encoder;
  OusterImages pixels;  // h x columns_per_packet
  bool crc_checked = false;
};

enum class OusterPacketResult { Ok, WrongSize, NotLidar, BadCrc };

// CRC-64/XZ (ECMA-182 reflected, init and xorout all ones): "123456789" -> 0x995DC9BBDF1939FA.
uint64_t crc64_xz(std::span<const uint8_t> bytes);

// Decodes `bytes` as one lidar packet of the metadata's profile into `out` (its buffers are
// reused). WrongSize when the size differs from ouster_lidar_packet_bytes (nothing is read);
// NotLidar when the packet header's type is not 1; BadCrc when `check_crc` and the footer's
// CRC-64 does not match.
OusterPacketResult decode_ouster_lidar_packet(std::span<const uint8_t> bytes,
                                              const OusterMetadata& m, bool check_crc,
                                              OusterLidarPacket& out);

inline constexpr size_t kOusterLegacyImuPacketBytes = 48;
inline constexpr double kStandardGravity = 9.80665;  // m/s^2 per g

struct OusterImuSample {
  Time stamp;       // accel_ts: the accelerometer's read time on the LiDAR clock
  Time gyro_stamp;  // gyro_ts, the same clock
  Time sys_stamp;   // sys_ts: the sensor's system time at the packet
  Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();  // IMU frame, m/s^2 (the packet: g)
  Eigen::Vector3d gyro_radps = Eigen::Vector3d::Zero();  // IMU frame, rad/s (the packet: deg/s)
};
// A LEGACY IMU packet (48 bytes); nullopt for any other size.
std::optional<OusterImuSample> decode_ouster_imu_packet(std::span<const uint8_t> bytes);

}  // namespace rigcal::io
