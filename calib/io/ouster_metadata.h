#pragma once
// The metadata JSON of an Ouster sensor (doc/formats.md, "Ouster captures"): the nested form
// (FW 2.4+: sensor_info, beam_intrinsics, ..., lidar_data_format) and the flat ("legacy") form
// of older firmware and tools, with the sensor's documented defaults for missing keys. Everything
// a capture needs to be decoded: the frame size, the packet profile, the beam angles and the
// transforms between the beam, LiDAR, sensor and IMU frames.
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "rigcal/core/se3.h"

namespace rigcal::io {

// Larger metadata is refused before it is parsed (a 128-beam sensor's is ~10 KB).
inline constexpr size_t kMaxOusterMetadataBytes = 1 << 20;

enum class OusterLidarProfile {
  Legacy,               // LEGACY
  Rng19Rfl8Sig16Nir16,  // RNG19_RFL8_SIG16_NIR16
  Rng19Rfl8Sig16Nir16Dual,
  Rng15Rfl8Nir8,  // RNG15_RFL8_NIR8 (the "low bandwidth" profile)
  Rng15Rfl8Nir8Dual,
  FusaRng15Rfl8Nir8Dual,  // FUSA_RNG15_RFL8_NIR8_DUAL (FUSA header)
};
enum class OusterHeaderType { Standard, Fusa };

std::string_view to_string(OusterLidarProfile profile);

struct OusterMetadata {
  std::string source;  // the file (or what the text came from), for messages

  std::string prod_line;        // model, "OS-1-128"
  std::string prod_sn;          // serial, as text
  uint64_t prod_sn_number = 0;  // the serial as the packets carry it (0 when not a number)
  uint32_t init_id = 0;         // initialization_id (0 when absent)
  std::string build_rev, image_rev;
  std::array<int, 3> fw_version = {0, 0, 0};  // from image_rev or build_rev ("v2.3.0"), 0 unknown

  std::string lidar_mode;  // "1024x10"
  int mode_columns = 0, mode_hz = 0;

  int pixels_per_column = 0;  // h
  int columns_per_frame = 0;  // w
  int columns_per_packet = 0;
  std::array<int, 2> column_window = {0, 0};  // first, last column measured (inclusive; may wrap)
  std::vector<int> pixel_shift_by_row;        // h entries (destagger shifts)
  OusterLidarProfile udp_profile_lidar = OusterLidarProfile::Legacy;
  std::string udp_profile_imu = "LEGACY";
  OusterHeaderType header_type = OusterHeaderType::Standard;
  int udp_port_lidar = 0, udp_port_imu = 0;  // 0 when absent

  std::vector<double> beam_altitude_deg, beam_azimuth_deg;         // h entries each, degrees
  Eigen::Matrix4d beam_to_lidar_mm = Eigen::Matrix4d::Identity();  // as stored (translation mm)
  double lidar_origin_to_beam_origin_mm = 0;

  // Transforms in metres: lidar frame -> sensor frame, IMU frame -> sensor frame.
  SE3 T_sensor_lidar;
  SE3 T_sensor_imu;
};

// Throws rigcal::Error naming `source` and the key for malformed or inconsistent metadata: beam
// angle counts not matching pixels_per_column, columns_per_frame not matching lidar_mode, an
// unknown packet profile, a transform that is not 16 finite numbers of a rigid 4x4.
OusterMetadata parse_ouster_metadata(std::string_view json_text, std::string_view source);
// Reads the file (at most kMaxOusterMetadataBytes) and parses it.
OusterMetadata read_ouster_metadata(const std::filesystem::path& path);

// Bytes of one lidar packet in the metadata's profile.
size_t ouster_lidar_packet_bytes(const OusterMetadata& m);
// Whether the packets' footer holds a real CRC-64 (STANDARD header on FW 3 and later; the v2.x
// footers are not CRCs).
bool ouster_packets_have_crc(const OusterMetadata& m);
// Packets a complete frame needs: those whose columns touch column_window.
int ouster_expected_packets(const OusterMetadata& m);

}  // namespace rigcal::io
