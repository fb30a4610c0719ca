// The Ouster capture reader against the ouster-sdk's own test captures (../shared/fixtures/lidar):
// every field image of every frame against the sdk's md5 digests, the CRC-64 of FW 3 packets,
// IPv4 fragment reassembly, empty, cut and mismatched captures, the geometry of three frames
// against the poses published with them, and the IMU packets.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <unordered_map>

#include "cli_run.h"
#include "fixtures.h"
#include "rigcal/core/error.h"
#include "rigcal/io/files.h"
#include "rigcal/io/ouster_frames.h"
#include "rigcal/io/ouster_metadata.h"
#include "rigcal/io/ouster_packet.h"
#include "rigcal/io/ouster_pcap.h"
#include "rigcal/lidar/odometry.h"

namespace rigcal {
namespace {

namespace fs = std::filesystem;
using io::OusterField;
using io::OusterFrame;
using io::OusterMetadata;
using io::OusterPcapReader;
using io::OusterSkip;

// MD5 (RFC 1321), only to compare with the sdk's digests; checked on the RFC's own vectors below.
class Md5 {
 public:
  void update(const void* data, size_t n) {
    const auto* p = static_cast<const uint8_t*>(data);
    length_ += n;
    while (n > 0) {
      const size_t take = std::min(n, 64 - used_);
      std::memcpy(buffer_ + used_, p, take);
      used_ += take;
      p += take;
      n -= take;
      if (used_ == 64) {
        block(buffer_);
        used_ = 0;
      }
    }
  }
  template <typename T>
  void update(const std::vector<T>& v) {
    update(v.data(), v.size() * sizeof(T));
  }
  std::string hex() {
    const uint64_t bits = length_ * 8;
    const uint8_t pad = 0x80;
    update(&pad, 1);
    const uint8_t zero = 0;
    while (used_ != 56) update(&zero, 1);
    uint8_t len[8];
    for (int i = 0; i < 8; ++i) len[i] = static_cast<uint8_t>(bits >> (8 * i));
    update(len, 8);
    std::string out;
    for (uint32_t word : state_)
      for (int i = 0; i < 4; ++i) {
        char b[3];
        std::snprintf(b, sizeof b, "%02x", (word >> (8 * i)) & 0xFF);
        out += b;
      }
    return out;
  }

 private:
  void block(const uint8_t* p) {
    static const std::array<uint32_t, 64> K = [] {
      std::array<uint32_t, 64> k{};
      for (int i = 0; i < 64; ++i)
        k[i] = static_cast<uint32_t>(std::floor(std::fabs(std::sin(i + 1.0)) * 4294967296.0));
      return k;
    }();
    static constexpr int S[4][4] = {
        {7, 12, 17, 22}, {5, 9, 14, 20}, {4, 11, 16, 23}, {6, 10, 15, 21}};
    uint32_t M[16];
    for (int i = 0; i < 16; ++i)
      M[i] = uint32_t{p[4 * i]} | uint32_t{p[4 * i + 1]} << 8 | uint32_t{p[4 * i + 2]} << 16 |
             uint32_t{p[4 * i + 3]} << 24;
    uint32_t A = state_[0], B = state_[1], C = state_[2], D = state_[3];
    for (int i = 0; i < 64; ++i) {
      uint32_t F;
      int g;
      if (i < 16) {
        F = (B & C) | (~B & D);
        g = i;
      } else if (i < 32) {
        F = (D & B) | (~D & C);
        g = (5 * i + 1) % 16;
      } else if (i < 48) {
        F = B ^ C ^ D;
        g = (3 * i + 5) % 16;
      } else {
        F = C ^ (B | ~D);
        g = (7 * i) % 16;
      }
      F += A + K[i] + M[g];
      A = D;
      D = C;
      C = B;
      const int s = S[i / 16][i % 4];
      B += (F << s) | (F >> (32 - s));
    }
    state_[0] += A;
    state_[1] += B;
    state_[2] += C;
    state_[3] += D;
  }
  std::array<uint32_t, 4> state_ = {0x67452301, 0xefcdab89, 0x98badcfe, 0x10325476};
  uint8_t buffer_[64] = {};
  size_t used_ = 0;
  uint64_t length_ = 0;
};

std::string md5_of(const std::string& s) {
  Md5 m;
  m.update(s.data(), s.size());
  return m.hex();
}

TEST(OusterMd5, Rfc1321Vectors) {
  EXPECT_EQ(md5_of(""), "d41d8cd98f00b204e9800998ecf8427e");
  EXPECT_EQ(md5_of("abc"), "900150983cd24fb0d6963f7d28e17f72");
  EXPECT_EQ(md5_of("message digest"), "f96b697d7cb7938d525a2f31aaf161d0");
  EXPECT_EQ(md5_of("abcdefghijklmnopqrstuvwxyz"), "c3fcd3d76192e4007dfb496cca67e13b");
  EXPECT_EQ(md5_of("1234567890123456789012345678901234567890123456789012345678901234567890123456"
                   "7890"),
            "57edf4a22be3c955ac49da2e2107b67a");
}

TEST(OusterCrc, Crc64XzCheckValue) {
  const std::string s = "123456789";
  EXPECT_EQ(io::crc64_xz({reinterpret_cast<const uint8_t*>(s.data()), s.size()}),
            0x995DC9BBDF1939FAULL);
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Capture {
  std::vector<OusterFrame> frames;
  io::OusterCaptureCounters counters;
};

Capture read_capture(OusterPcapReader& reader) {
  Capture c;
  while (auto f = reader.next_frame()) c.frames.push_back(std::move(*f));
  c.counters = reader.counters();
  return c;
}

Capture read_capture(const std::string& pcap, const std::string& json) {
  OusterPcapReader reader(pcap, io::read_ouster_metadata(json));
  return read_capture(reader);
}

template <typename T>
std::string md5_widened(const std::vector<T>& v) {
  std::vector<uint64_t> wide(v.begin(), v.end());
  Md5 m;
  m.update(wide);
  return m.hex();
}

std::string md5_field(const io::OusterImages& px, OusterField f) {
  Md5 m;
  switch (f) {
    case OusterField::Range:
      m.update(px.range);
      break;
    case OusterField::Range2:
      m.update(px.range2);
      break;
    case OusterField::Signal:
      m.update(px.signal);
      break;
    case OusterField::Signal2:
      m.update(px.signal2);
      break;
    case OusterField::NearIr:
      m.update(px.near_ir);
      break;
    case OusterField::Reflectivity:
      m.update(px.reflectivity);
      break;
    case OusterField::Reflectivity2:
      m.update(px.reflectivity2);
      break;
    case OusterField::Flags:
      m.update(px.flags);
      break;
    case OusterField::Flags2:
      m.update(px.flags2);
      break;
    case OusterField::Window:
      m.update(px.window);
      break;
  }
  return m.hex();
}

const std::vector<OusterField> kAllFields = {OusterField::Range,        OusterField::Range2,
                                             OusterField::Flags,        OusterField::Flags2,
                                             OusterField::Reflectivity, OusterField::Reflectivity2,
                                             OusterField::Signal,       OusterField::Signal2,
                                             OusterField::NearIr,       OusterField::Window};

class OusterDigest : public ::testing::TestWithParam<std::string> {};

// Every frame's header columns and staggered field images, and the running per-packet hashes,
// against the md5s the ouster-sdk's digest tool wrote for the same capture.
TEST_P(OusterDigest, FramesAndPacketsMatchTheSdkDigest) {
  const std::string base = "lidar/ouster_sdk/" + GetParam();
  RIGCAL_REQUIRE_FIXTURE(pcap, base + ".pcap");
  RIGCAL_REQUIRE_FIXTURE(json, base + ".json");
  RIGCAL_REQUIRE_FIXTURE(digest_path, base + "_digest.json");
  const nlohmann::json digest = nlohmann::json::parse(io::read_text_file(digest_path));
  const OusterMetadata m = io::read_ouster_metadata(json);

  // Running per-packet hashes (packet_hash).
  std::map<std::string, Md5> running;
  OusterPcapReader reader(pcap, m);
  const size_t cpp = m.columns_per_packet;
  const bool legacy = m.udp_profile_lidar == io::OusterLidarProfile::Legacy;
  reader.on_lidar_packet = [&](const io::OusterLidarPacket& p) {
    running["TIMESTAMP"].update(p.timestamp);
    running["MEASUREMENT_ID"].update(p.measurement_id);
    running["STATUS"].update(p.status);
    running["ENCODER_COUNT"].update(p.encoder);
    running["FRAME_ID"].update(std::vector<uint16_t>(cpp, legacy ? p.frame_id : 0));
    for (OusterField f : kAllFields)
      if (p.pixels.has(f)) {
        switch (f) {
          case OusterField::Range:
            running["RANGE"].update(p.pixels.range);
            break;
          case OusterField::Range2:
            running["RANGE2"].update(p.pixels.range2);
            break;
          case OusterField::Signal:
            running["SIGNAL"].update(p.pixels.signal);
            break;
          case OusterField::Signal2:
            running["SIGNAL2"].update(p.pixels.signal2);
            break;
          case OusterField::NearIr:
            running["NEAR_IR"].update(p.pixels.near_ir);
            break;
          case OusterField::Reflectivity:
            running["REFLECTIVITY"].update(p.pixels.reflectivity);
            break;
          case OusterField::Reflectivity2:
            running["REFLECTIVITY2"].update(p.pixels.reflectivity2);
            break;
          case OusterField::Flags:
            running["FLAGS"].update(p.pixels.flags);
            break;
          case OusterField::Flags2:
            running["FLAGS2"].update(p.pixels.flags2);
            break;
          case OusterField::Window:
            running["WINDOW"].update(p.pixels.window);
            break;
        }
      }
  };
  const Capture c = read_capture(reader);

  const auto& scans = digest.at("scans");
  ASSERT_EQ(c.frames.size(), scans.size());
  for (size_t i = 0; i < scans.size(); ++i) {
    size_t compared = 0;
    const OusterFrame& f = c.frames[i];
    const auto& s = scans[i];
    EXPECT_EQ(std::to_string(f.frame_id), s.at("FRAME_ID").get<std::string>());
    EXPECT_EQ(md5_widened(f.timestamp), s.at("TIMESTAMP").get<std::string>());
    EXPECT_EQ(md5_widened(f.status), s.at("STATUS").get<std::string>());
    Md5 mid;
    mid.update(f.measurement_id);
    EXPECT_EQ(mid.hex(), s.at("MEASUREMENT_ID").get<std::string>());
    EXPECT_EQ(md5_widened(f.encoder), s.at("ENCODER_COUNT").get<std::string>());  // u64[w]
    compared += 5;
    for (OusterField field : kAllFields) {
      const std::string key(io::to_string(field));
      if (!s.contains(key)) continue;
      ASSERT_TRUE(f.pixels.has(field)) << key;
      EXPECT_EQ(md5_field(f.pixels, field), s.at(key).get<std::string>()) << key;
      ++compared;
    }
    EXPECT_EQ(compared, s.size());  // every key of the digest
  }

  const auto& packet_hash = digest.at("packet_hash");
  size_t packet_keys = 0;
  for (auto& [key, md5] : running) {
    if (!packet_hash.contains(key)) continue;
    EXPECT_EQ(md5.hex(), packet_hash.at(key).get<std::string>()) << "packet_hash " << key;
    ++packet_keys;
  }
  // All but the RAW32_WORD keys (the raw words of a channel block, not decoded here).
  size_t raw_words = 0;
  for (auto& [key, md5] : packet_hash.items()) raw_words += key.starts_with("RAW32_WORD");
  EXPECT_EQ(packet_keys + raw_words, packet_hash.size());
}

INSTANTIATE_TEST_SUITE_P(Captures, OusterDigest,
                         ::testing::Values("OS-0-128-U1_v2.3.0_1024x10",
                                           "OS-0-32-U1_v2.2.0_1024x10", "OS-1-32-G_v2.1.1_1024x10",
                                           "OS-2-128-U1_v2.3.0_1024x10"),
                         [](const auto& info) {
                           std::string n = info.param.substr(0, info.param.find('_'));
                           std::replace(n.begin(), n.end(), '-', '_');
                           return n;
                         });

// ---- Metadata ----

TEST(OusterMetadata, NestedFormWithItsKeys) {
  RIGCAL_REQUIRE_FIXTURE(json, "lidar/ouster_sdk/crc_test.json");
  const OusterMetadata m = io::read_ouster_metadata(json);
  EXPECT_EQ(m.prod_line, "OS-0-128");
  EXPECT_EQ(m.prod_sn, "122247000785");
  EXPECT_EQ(m.prod_sn_number, 122247000785ULL);
  EXPECT_EQ(m.init_id, 11394290u);
  EXPECT_EQ(m.fw_version, (std::array<int, 3>{3, 2, 0}));
  EXPECT_EQ(m.mode_columns, 512);
  EXPECT_EQ(m.mode_hz, 10);
  EXPECT_EQ(m.pixels_per_column, 128);
  EXPECT_EQ(m.columns_per_frame, 512);
  EXPECT_EQ(m.columns_per_packet, 16);
  EXPECT_EQ(m.column_window, (std::array<int, 2>{0, 511}));
  EXPECT_EQ(m.udp_profile_lidar, io::OusterLidarProfile::Rng15Rfl8Nir8);
  EXPECT_EQ(m.udp_port_lidar, 7502);
  EXPECT_EQ(m.udp_port_imu, 7503);
  ASSERT_EQ(m.pixel_shift_by_row.size(), 128u);
  EXPECT_EQ(m.pixel_shift_by_row[0], 15);
  EXPECT_EQ(m.pixel_shift_by_row[2], -5);
  EXPECT_DOUBLE_EQ(m.beam_altitude_deg[0], 45.16);
  EXPECT_DOUBLE_EQ(m.beam_azimuth_deg[0], 10.86);
  EXPECT_DOUBLE_EQ(m.lidar_origin_to_beam_origin_mm, 27.116);
  // lidar_to_sensor: diag(-1, -1, 1), z 38.195 mm as the file says, in metres.
  EXPECT_DOUBLE_EQ(m.T_sensor_lidar.R(0, 0), -1.0);
  EXPECT_DOUBLE_EQ(m.T_sensor_lidar.R(1, 1), -1.0);
  EXPECT_DOUBLE_EQ(m.T_sensor_lidar.R(2, 2), 1.0);
  EXPECT_NEAR(m.T_sensor_lidar.t.z(), 0.038195, 1e-12);
  EXPECT_NEAR(m.T_sensor_lidar.t.x(), 0.0, 1e-12);
  // beam_to_lidar_transform as stored (mm): x is the beam origin offset.
  EXPECT_DOUBLE_EQ(m.beam_to_lidar_mm(0, 3), 27.116);
  EXPECT_EQ(io::ouster_lidar_packet_bytes(m), 8448u);
  EXPECT_TRUE(io::ouster_packets_have_crc(m));
  EXPECT_EQ(io::ouster_expected_packets(m), 32);
}

TEST(OusterMetadata, FlatFormWithDefaults) {
  RIGCAL_REQUIRE_FIXTURE(json, "lidar/ouster_sdk/OS-1-32-G_v2.1.1_1024x10.json");
  const OusterMetadata m = io::read_ouster_metadata(json);
  EXPECT_EQ(m.prod_line, "OS-1-32-G");
  EXPECT_EQ(m.init_id, 0u);  // absent in v2.1.1
  EXPECT_EQ(m.fw_version, (std::array<int, 3>{2, 1, 1}));
  EXPECT_EQ(m.udp_profile_lidar, io::OusterLidarProfile::Legacy);
  EXPECT_EQ(m.udp_port_lidar, 0);
  EXPECT_EQ(m.pixels_per_column, 32);
  EXPECT_EQ(io::ouster_lidar_packet_bytes(m), 6464u);
  EXPECT_FALSE(io::ouster_packets_have_crc(m));
  // No beam_to_lidar_transform: identity with x = lidar_origin_to_beam_origin_mm.
  EXPECT_DOUBLE_EQ(m.beam_to_lidar_mm(0, 3), 15.806);
  EXPECT_DOUBLE_EQ(m.beam_to_lidar_mm(2, 3), 0.0);

  RIGCAL_REQUIRE_FIXTURE(dual, "lidar/ouster_sdk/OS-0-32-U1_v2.2.0_1024x10.json");
  const OusterMetadata d = io::read_ouster_metadata(dual);
  EXPECT_EQ(d.udp_profile_lidar, io::OusterLidarProfile::Rng19Rfl8Sig16Nir16Dual);
  EXPECT_EQ(io::ouster_lidar_packet_bytes(d), 8448u);
  EXPECT_EQ(d.init_id, 9599938u);
  EXPECT_FALSE(io::ouster_packets_have_crc(d));  // FW 2.2: the footer is no CRC
}

class OusterMetadataErrors : public testing::ScratchTest {
 protected:
  std::string with(const std::string& key, const nlohmann::json& value) {
    nlohmann::json j = nlohmann::json::parse(io::read_text_file(json_));
    j["lidar_data_format"][key] = value;
    return j.dump();
  }
  std::string error_for(const std::string& text) {
    return error_of([&] { io::parse_ouster_metadata(text, "meta.json"); });
  }
  std::string json_ = testing::fixture("lidar/ouster_sdk/crc_test.json");
};

TEST_F(OusterMetadataErrors, InconsistentMetadataIsRefusedNamingTheKey) {
  if (json_.empty()) GTEST_SKIP() << "fixture crc_test.json not found under ../shared/fixtures";
  nlohmann::json j = nlohmann::json::parse(io::read_text_file(json_));
  j["beam_intrinsics"]["beam_altitude_angles"].erase(0);
  std::string e = error_for(j.dump());
  EXPECT_NE(e.find("meta.json"), std::string::npos) << e;
  EXPECT_NE(e.find("beam_intrinsics.beam_altitude_angles"), std::string::npos) << e;
  EXPECT_NE(e.find("127 angles for 128"), std::string::npos) << e;

  e = error_for(with("columns_per_frame", 1024));
  EXPECT_NE(e.find("lidar_data_format.columns_per_frame"), std::string::npos) << e;
  EXPECT_NE(e.find("does not match lidar_mode '512x10'"), std::string::npos) << e;

  e = error_for(with("udp_profile_lidar", "RNG99_MAGIC"));
  EXPECT_NE(e.find("udp_profile_lidar"), std::string::npos) << e;
  EXPECT_NE(e.find("RNG99_MAGIC"), std::string::npos) << e;

  e = error_for(with("columns_per_packet", 0));
  EXPECT_NE(e.find("columns_per_packet"), std::string::npos) << e;

  e = error_for("{\"sensor_info\": ");
  EXPECT_NE(e.find("not valid JSON"), std::string::npos) << e;

  nlohmann::json t = nlohmann::json::parse(io::read_text_file(json_));
  t["lidar_intrinsics"]["lidar_to_sensor_transform"] = {1, 2, 3};
  e = error_for(t.dump());
  EXPECT_NE(e.find("lidar_intrinsics.lidar_to_sensor_transform"), std::string::npos) << e;
  EXPECT_NE(e.find("16 numbers"), std::string::npos) << e;

  t["lidar_intrinsics"]["lidar_to_sensor_transform"] = {-1, 0, 0, 0,   0, -1, 0, 0,
                                                        0,  0, 1, 1e9, 0, 0,  0, 1};
  e = error_for(t.dump());
  EXPECT_NE(e.find("translation beyond"), std::string::npos) << e;
}

TEST_F(OusterMetadataErrors, MissingTransformsTakeTheSensorsDefaults) {
  if (json_.empty()) GTEST_SKIP() << "fixture crc_test.json not found under ../shared/fixtures";
  nlohmann::json j = nlohmann::json::parse(io::read_text_file(json_));
  j["lidar_intrinsics"].erase("lidar_to_sensor_transform");
  j["imu_intrinsics"].erase("imu_to_sensor_transform");
  j["beam_intrinsics"].erase("beam_to_lidar_transform");
  j["beam_intrinsics"].erase("lidar_origin_to_beam_origin_mm");
  const OusterMetadata m = io::parse_ouster_metadata(j.dump(), "meta.json");
  EXPECT_NEAR(m.T_sensor_lidar.t.z(), 0.03618, 1e-12);
  EXPECT_DOUBLE_EQ(m.T_sensor_lidar.R(0, 0), -1.0);
  EXPECT_NEAR((m.T_sensor_imu.t - Eigen::Vector3d(0.006253, -0.011775, 0.007645)).norm(), 0, 1e-12);
  EXPECT_DOUBLE_EQ(m.lidar_origin_to_beam_origin_mm, 27.67);  // OS-0
  EXPECT_DOUBLE_EQ(m.beam_to_lidar_mm(0, 3), 27.67);
}

TEST_F(OusterMetadataErrors, OverOneMebibyteIsRefusedBeforeParsing) {
  const auto big =
      write("big.json", "{\"pad\": \"" + std::string(io::kMaxOusterMetadataBytes, 'x') + "\"}");
  const std::string e = error_of([&] { io::read_ouster_metadata(big); });
  EXPECT_NE(e.find("big.json"), std::string::npos) << e;
}

// ---- Frame assembly rules on hand-made packets ----

// A 4-beam, 32-column sensor: two packets of 16 columns a frame.
OusterMetadata tiny_sensor() {
  return io::parse_ouster_metadata(R"({"prod_line": "OS-1-16", "lidar_mode": "32x10",
      "initialization_id": 5, "beam_altitude_angles": [15, 5, -5, -15],
      "beam_azimuth_angles": [3, 1, -1, -3], "data_format": {"pixels_per_column": 4,
      "columns_per_frame": 32, "columns_per_packet": 16, "udp_profile_lidar": "RNG15_RFL8_NIR8"}})",
                                   "tiny.json");
}

io::OusterLidarPacket tiny_packet(const OusterMetadata& m, uint32_t frame_id, int slot,
                                  uint32_t init_id = 5, uint32_t range_mm = 1000) {
  io::OusterLidarPacket p;
  p.frame_id = frame_id;
  p.init_id = init_id;
  for (int c = 0; c < 16; ++c) {
    p.timestamp.push_back(1000 + 16 * slot + c);
    p.measurement_id.push_back(static_cast<uint16_t>(16 * slot + c));
    p.status.push_back(1);
    p.encoder.push_back(0);
  }
  p.pixels.resize(m.udp_profile_lidar, 4 * 16);
  std::fill(p.pixels.range.begin(), p.pixels.range.end(), range_mm);
  return p;
}

TEST(OusterFrames, ReleasedWhenEveryDistinctSlotArrived) {
  const OusterMetadata m = tiny_sensor();
  io::OusterFrameAssembler a(m);
  std::vector<OusterFrame> out;
  a.add(tiny_packet(m, 20, 0, 5, 1000), out);
  a.add(tiny_packet(m, 20, 0, 5, 2000), out);  // a duplicate: overwrites, does not complete
  EXPECT_TRUE(out.empty());
  a.add(tiny_packet(m, 20, 1), out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_TRUE(out[0].complete);
  EXPECT_EQ(out[0].packets_received, 2);
  EXPECT_EQ(out[0].pixels.range[0], 2000u);  // the later duplicate's
  EXPECT_EQ(out[0].timestamp[31], 1000u + 31);
}

TEST(OusterFrames, AFullCacheReleasesTheFrameIncompleteAndStalePacketsAreDropped) {
  const OusterMetadata m = tiny_sensor();
  io::OusterFrameAssembler a(m);
  std::vector<OusterFrame> out;
  a.add(tiny_packet(m, 65535, 0), out);  // frame 65535 lacks its second packet
  for (int i = 0; i < 3; ++i) a.add(tiny_packet(m, 0, i % 2), out);  // frame 0 (after the wrap)
  EXPECT_TRUE(out.empty());                                          // 3 packets wait in the cache
  a.add(tiny_packet(m, 0, 1), out);                                  // the fourth fills it
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].frame_id, 65535u);
  EXPECT_FALSE(out[0].complete);
  EXPECT_EQ(out[0].packets_received, 1);
  EXPECT_EQ(out[0].status[16], 0u);  // the missing columns are zero
  EXPECT_EQ(out[0].pixels.range[16], 0u);
  // A packet of frame 65535 now is stale: 65535 is before 0 modulo 2^16.
  a.add(tiny_packet(m, 65535, 1), out);
  EXPECT_EQ(a.dropped_packets(), 1u);
  a.finish(out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[1].frame_id, 0u);
  EXPECT_TRUE(out[1].complete);
}

TEST(OusterFrames, AnInitIdChangeEndsTheFrameAndStartsAfresh) {
  const OusterMetadata m = tiny_sensor();
  io::OusterFrameAssembler a(m);
  std::vector<OusterFrame> out;
  a.add(tiny_packet(m, 300, 0, 5), out);
  a.add(tiny_packet(m, 2, 0, 6), out);  // the sensor restarted: frame ids start again
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].frame_id, 300u);
  EXPECT_FALSE(out[0].complete);
  a.add(tiny_packet(m, 2, 1, 6), out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[1].frame_id, 2u);
  EXPECT_EQ(out[1].init_id, 6u);
  EXPECT_TRUE(out[1].complete);
  EXPECT_EQ(a.dropped_packets(), 0u);  // frame 2 < 300 was not taken for stale
}

// ---- Captures that test the edges ----

TEST(OusterPcap, CrcTestChecksEveryFooterAndKeepsThePartialFrame) {
  RIGCAL_REQUIRE_FIXTURE(pcap, "lidar/ouster_sdk/crc_test.pcap");
  RIGCAL_REQUIRE_FIXTURE(json, "lidar/ouster_sdk/crc_test.json");
  const Capture c = read_capture(pcap, json);
  EXPECT_EQ(c.counters.lidar_packets, 34u);
  EXPECT_EQ(c.counters.crc_good, 34u);
  EXPECT_EQ(c.counters.of(OusterSkip::BadCrc).count, 0u);
  EXPECT_EQ(c.counters.imu_packets, 10u);
  ASSERT_EQ(c.frames.size(), 2u);
  EXPECT_TRUE(c.frames[0].complete);
  EXPECT_EQ(c.frames[0].packets_received, 32);
  EXPECT_FALSE(c.frames[1].complete);
  EXPECT_EQ(c.frames[1].packets_received, 2);
  EXPECT_EQ(c.counters.frames_complete, 1u);
  EXPECT_EQ(c.counters.frames_incomplete, 1u);
}

TEST(OusterPcap, ABadCrcSkipsThatPacketOnly) {
  RIGCAL_REQUIRE_FIXTURE(pcap, "lidar/ouster_sdk/crc_test.pcap");
  RIGCAL_REQUIRE_FIXTURE(json, "lidar/ouster_sdk/crc_test.json");
  std::string bytes = read_bytes(pcap);
  // The first record holding a lidar payload: its UDP payload starts 14 + 20 + 8 bytes into the
  // record; flip a bit well inside it (a pixel of column 3).
  const OusterMetadata m = io::read_ouster_metadata(json);
  size_t at = 24, flipped_record = 0;
  for (size_t record = 1; at + 16 <= bytes.size(); ++record) {
    uint32_t caplen;
    std::memcpy(&caplen, bytes.data() + at + 8, 4);
    if (caplen == 14 + 20 + 8 + io::ouster_lidar_packet_bytes(m)) {
      bytes[at + 16 + 42 + 2000] ^= 0x10;
      flipped_record = record;
      break;
    }
    at += 16 + caplen;
  }
  ASSERT_GT(flipped_record, 0u);
  OusterPcapReader reader(OusterPcapReader::InMemory{}, "flipped.pcap", bytes, m);
  const Capture c = read_capture(reader);
  EXPECT_EQ(c.counters.of(OusterSkip::BadCrc).count, 1u);
  EXPECT_EQ(c.counters.of(OusterSkip::BadCrc).first_packet, flipped_record);
  EXPECT_EQ(c.counters.crc_good, 33u);
  ASSERT_EQ(c.frames.size(), 2u);
  EXPECT_FALSE(c.frames[0].complete);  // one packet of 32 missing
  EXPECT_EQ(c.frames[0].packets_received, 31);
}

TEST(OusterPcap, DuplicateIdNeedsFragmentReassembly) {
  RIGCAL_REQUIRE_FIXTURE(pcap, "lidar/ouster_sdk/duplicate_id.pcap");
  RIGCAL_REQUIRE_FIXTURE(json, "lidar/ouster_sdk/duplicate_id.json");
  const Capture c = read_capture(pcap, json);
  EXPECT_EQ(c.counters.lidar_packets, 1u);
  ASSERT_EQ(c.frames.size(), 1u);
  EXPECT_FALSE(c.frames[0].complete);
  EXPECT_EQ(c.frames[0].packets_received, 1);
  EXPECT_EQ(c.frames[0].packets_expected, 64);
  // Its 16 columns are valid, the rest zero.
  int valid = 0;
  for (uint32_t s : c.frames[0].status) valid += (s & 1u) != 0;
  EXPECT_EQ(valid, 16);
  // The first record is a fragment of the same IP id 88 s before the others: given up after 2 s.
  EXPECT_EQ(c.counters.of(OusterSkip::FragmentLost).count, 1u);
  EXPECT_EQ(c.counters.of(OusterSkip::FragmentLost).first_packet, 1u);

  // Stamped 1 ms before the rest instead, that fragment is replaced by the later one at its
  // offset: the same packet, nothing lost.
  std::string bytes = read_bytes(pcap);
  uint32_t sec, usec;
  const size_t second = 24 + 16 + 1514;
  std::memcpy(&sec, bytes.data() + second, 4);
  std::memcpy(&usec, bytes.data() + second + 4, 4);
  usec -= 1000;
  std::memcpy(bytes.data() + 24, &sec, 4);
  std::memcpy(bytes.data() + 28, &usec, 4);
  OusterPcapReader reader(OusterPcapReader::InMemory{}, "restamped.pcap", bytes,
                          io::read_ouster_metadata(json));
  const Capture r = read_capture(reader);
  EXPECT_EQ(r.counters.of(OusterSkip::FragmentLost).count, 0u);
  ASSERT_EQ(r.frames.size(), 1u);
  EXPECT_EQ(r.frames[0].pixels.range, c.frames[0].pixels.range);
  EXPECT_EQ(r.frames[0].timestamp, c.frames[0].timestamp);
}

TEST(OusterPcap, EmptyCaptureGivesNoFramesAndSaysSo) {
  RIGCAL_REQUIRE_FIXTURE(pcap, "lidar/ouster_sdk/empty_pcap.pcap");
  RIGCAL_REQUIRE_FIXTURE(json, "lidar/ouster_sdk/empty_pcap.json");
  const Capture c = read_capture(pcap, json);
  EXPECT_TRUE(c.frames.empty());
  EXPECT_EQ(c.counters.records, 0u);
  EXPECT_FALSE(c.counters.truncated);
  EXPECT_NE(c.counters.note.find("no packets"), std::string::npos) << c.counters.note;
}

class OusterPcapFiles : public testing::ScratchTest {};

TEST_F(OusterPcapFiles, ACutCaptureKeepsTheFramesBeforeTheCut) {
  RIGCAL_REQUIRE_FIXTURE(pcap, "lidar/ouster_os1_128/OS-1-128_v2.3.0_1024x10_lb_n3.pcap");
  RIGCAL_REQUIRE_FIXTURE(json, "lidar/ouster_os1_128/OS-1-128_v2.3.0_1024x10.json");
  const Capture whole = read_capture(pcap, json);
  ASSERT_EQ(whole.frames.size(), 3u);
  // Cut in the middle of the second frame's packets (inside a record).
  const std::string bytes = read_bytes(pcap);
  const auto cut = write("cut.pcap", bytes.substr(0, bytes.size() / 2 + 1001));
  const Capture c = read_capture(cut.string(), json);
  EXPECT_TRUE(c.counters.truncated);
  EXPECT_NE(c.counters.note.find("cut.pcap"), std::string::npos) << c.counters.note;
  EXPECT_NE(c.counters.note.find("after packet " + std::to_string(c.counters.records)),
            std::string::npos)
      << c.counters.note;
  EXPECT_GT(c.counters.records, 50u);
  EXPECT_LT(c.counters.records, 222u);
  ASSERT_EQ(c.frames.size(), 2u);  // the first, complete; the second, up to the cut
  EXPECT_TRUE(c.frames[0].complete);
  EXPECT_EQ(c.frames[0].frame_id, whole.frames[0].frame_id);
  EXPECT_EQ(c.frames[0].pixels.range, whole.frames[0].pixels.range);
  EXPECT_FALSE(c.frames[1].complete);
  EXPECT_EQ(c.frames[1].frame_id, whole.frames[1].frame_id);
}

// Another sensor's metadata with the OS-1-128 capture: never frames of garbage.
TEST_F(OusterPcapFiles, AnotherModelsMetadataSkipsEveryPacket) {
  RIGCAL_REQUIRE_FIXTURE(pcap, "lidar/ouster_os1_128/OS-1-128_v2.3.0_1024x10_lb_n3.pcap");
  // OS-2-128, RNG19: 24832-byte packets expected, 8448 found.
  RIGCAL_REQUIRE_FIXTURE(os2, "lidar/ouster_sdk/OS-2-128-U1_v2.3.0_1024x10.json");
  Capture c = read_capture(pcap, os2);
  EXPECT_TRUE(c.frames.empty());
  EXPECT_EQ(c.counters.lidar_packets, 0u);
  EXPECT_EQ(c.counters.of(OusterSkip::WrongSize).count, 192u);
  EXPECT_EQ(c.counters.of(OusterSkip::WrongSize).first_packet, 1u);
  EXPECT_EQ(io::describe(OusterSkip::WrongSize),
            "packet size does not match the metadata's profile");
  EXPECT_NE(c.counters.note.find("no lidar packet"), std::string::npos) << c.counters.note;
  // OS-0-32, RNG19 dual: 32 beams of 16 bytes make 8448 bytes too (sizes collide across
  // profiles), but the packets' init_id is not this metadata's.
  RIGCAL_REQUIRE_FIXTURE(os0, "lidar/ouster_sdk/OS-0-32-U1_v2.2.0_1024x10.json");
  c = read_capture(pcap, os0);
  EXPECT_TRUE(c.frames.empty());
  EXPECT_EQ(c.counters.lidar_packets, 0u);
  EXPECT_EQ(c.counters.of(OusterSkip::InitIdMismatch).count, 192u);
}

TEST_F(OusterPcapFiles, ANonPcapFileIsAnErrorNamingIt) {
  RIGCAL_REQUIRE_FIXTURE(json, "lidar/ouster_os1_128/OS-1-128_v2.3.0_1024x10.json");
  const OusterMetadata m = io::read_ouster_metadata(json);
  const auto bad = write("not_a.pcap", "this is not a capture, only some text of some length\n");
  std::string e = error_of([&] { OusterPcapReader r(bad, m); });
  EXPECT_NE(e.find("not_a.pcap"), std::string::npos) << e;
  e = error_of([&] { OusterPcapReader r(dir_ / "missing.pcap", m); });
  EXPECT_NE(e.find("missing.pcap"), std::string::npos) << e;
}

// ---- Geometry and time ----

std::vector<SE3> read_kitti_poses(const std::string& path) {
  std::vector<SE3> poses;
  std::istringstream in(io::read_text_file(path));
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream l(line);
    Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) l >> M(r, c);
    if (l) poses.push_back(SE3::from_matrix(M));
  }
  return poses;
}

// Nearest-neighbour look-up in a hash of cubic voxels (the test needs no k-d tree).
class VoxelGrid {
 public:
  VoxelGrid(const std::vector<Eigen::Vector3d>& points, double voxel)
      : pts_(points), voxel_(voxel) {
    for (size_t i = 0; i < pts_.size(); ++i) cells_[key(cell(pts_[i]))].push_back(i);
  }
  // Up to k nearest within the 27 voxels around p.
  std::vector<Eigen::Vector3d> nearest(const Eigen::Vector3d& p, size_t k) const {
    std::vector<std::pair<double, size_t>> cand;
    const Eigen::Vector3i c = cell(p);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(key(c + Eigen::Vector3i(dx, dy, dz)));
          if (it == cells_.end()) continue;
          for (size_t i : it->second) cand.emplace_back((pts_[i] - p).squaredNorm(), i);
        }
    const size_t n = std::min(k, cand.size());
    std::partial_sort(cand.begin(), cand.begin() + n, cand.end());
    std::vector<Eigen::Vector3d> out;
    for (size_t i = 0; i < n; ++i) out.push_back(pts_[cand[i].second]);
    return out;
  }

 private:
  Eigen::Vector3i cell(const Eigen::Vector3d& p) const {
    return (p / voxel_).array().floor().cast<int>().matrix();
  }
  static int64_t key(const Eigen::Vector3i& c) {
    return (int64_t{c.x()} * 73856093) ^ (int64_t{c.y()} * 19349663) ^ (int64_t{c.z()} * 83492791);
  }
  const std::vector<Eigen::Vector3d>& pts_;
  double voxel_;
  std::unordered_map<int64_t, std::vector<size_t>> cells_;
};

struct Os1128 {
  OusterMetadata metadata;
  std::vector<Scan> scans;
  std::vector<io::OusterScanStats> stats;
};

Os1128 read_os1_128(const std::string& pcap, const std::string& json) {
  Os1128 out{io::read_ouster_metadata(json), {}, {}};
  OusterPcapReader reader(pcap, out.metadata);
  io::OusterScanStats s;
  while (auto scan = reader.next_scan(&s)) {
    out.scans.push_back(std::move(*scan));
    out.stats.push_back(s);
  }
  return out;
}

// Median distance of frame `b`'s points (every `step`-th) to the planes of frame `a`'s, both
// taken into the poses' common frame. Planes: PCA of the 10 nearest neighbours, kept when planar.
double median_point_to_plane(const Scan& a, const SE3& T_world_a, const Scan& b,
                             const SE3& T_world_b, size_t step, size_t* used) {
  std::vector<Eigen::Vector3d> map;
  for (const ScanPoint& p : a.points) map.push_back(T_world_a * p.p.cast<double>());
  const VoxelGrid grid(map, 0.5);
  std::vector<double> d;
  for (size_t i = 0; i < b.points.size(); i += step) {
    const Eigen::Vector3d q = T_world_b * b.points[i].p.cast<double>();
    const std::vector<Eigen::Vector3d> nn = grid.nearest(q, 10);
    if (nn.size() < 10 || (nn.back() - q).norm() > 0.5) continue;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& x : nn) mean += x;
    mean /= static_cast<double>(nn.size());
    Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
    for (const auto& x : nn) C += (x - mean) * (x - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(C);
    if (es.eigenvalues()(0) > 0.1 * es.eigenvalues()(1)) continue;  // not a plane
    d.push_back(std::abs(es.eigenvectors().col(0).dot(q - mean)));
  }
  *used = d.size();
  if (d.empty()) return INFINITY;
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

TEST(OusterGeometry, ThreeFramesAgreeWithTheirPublishedPoses) {
  RIGCAL_REQUIRE_FIXTURE(pcap, "lidar/ouster_os1_128/OS-1-128_v2.3.0_1024x10_lb_n3.pcap");
  RIGCAL_REQUIRE_FIXTURE(json, "lidar/ouster_os1_128/OS-1-128_v2.3.0_1024x10.json");
  RIGCAL_REQUIRE_FIXTURE(poses_path,
                         "lidar/ouster_os1_128/OS-1-128_v2.3.0_1024x10_lb_n3_poses_kitti.txt");
  const Os1128 r = read_os1_128(pcap, json);
  ASSERT_EQ(r.scans.size(), 3u);
  const std::vector<SE3> T_world_sensor = read_kitti_poses(poses_path);
  ASSERT_EQ(T_world_sensor.size(), 3u);
  for (const Scan& s : r.scans) EXPECT_GT(s.points.size(), 50'000u);
  size_t used = 0;
  const double d02 =
      median_point_to_plane(r.scans[0], T_world_sensor[0], r.scans[2], T_world_sensor[2], 5, &used);
  size_t used_identity = 0;
  const double d02_identity = median_point_to_plane(r.scans[0], SE3::identity(), r.scans[2],
                                                    SE3::identity(), 5, &used_identity);
  // Read as poses of the LiDAR frame instead (x and y turned half a turn from the sensor's), they
  // move the frames the wrong way.
  const SE3& T_sensor_lidar = r.metadata.T_sensor_lidar;
  size_t used_lidar = 0;
  const double d02_lidar = median_point_to_plane(
      r.scans[0], SE3::identity(), r.scans[2],
      T_sensor_lidar * T_world_sensor[2] * T_sensor_lidar.inverse(), 5, &used_lidar);
  std::printf(
      "OS-1-128 frames 0, 2: median point-to-plane %.4f m over %zu points with the poses "
      "as sensor-frame poses, %.4f m without poses, %.4f m as LiDAR-frame poses\n",
      d02, used, d02_identity, d02_lidar);
  EXPECT_GT(used, 5000u);
  EXPECT_LT(d02, 0.03);
  // The poses matter: without them the frames, 0.5 m apart, disagree more; and they are poses
  // of the sensor frame, which the points are in.
  EXPECT_GT(d02_identity, 1.5 * d02);
  EXPECT_GT(d02_lidar, 1.5 * d02);
}

// rigcal's odometry on the same three frames (the car preset): its poses put frames 0 and 2 on
// each other as well as the published ones do, and lie within centimetres of them.
TEST(OusterGeometry, TheOdometryOfTheThreeFramesAgreesWithThePublishedPoses) {
  RIGCAL_REQUIRE_FIXTURE(pcap, "lidar/ouster_os1_128/OS-1-128_v2.3.0_1024x10_lb_n3.pcap");
  RIGCAL_REQUIRE_FIXTURE(json, "lidar/ouster_os1_128/OS-1-128_v2.3.0_1024x10.json");
  RIGCAL_REQUIRE_FIXTURE(poses_path,
                         "lidar/ouster_os1_128/OS-1-128_v2.3.0_1024x10_lb_n3_poses_kitti.txt");
  const Os1128 r = read_os1_128(pcap, json);
  ASSERT_EQ(r.scans.size(), 3u);
  const std::vector<SE3> T_world_sensor = read_kitti_poses(poses_path);
  lidar::Odometry odometry = lidar::start_odometry(lidar::os1_64_car());
  for (const Scan& s : r.scans) lidar::register_scan(odometry, s);
  const std::vector<SE3>& T_odom_sensor = odometry.T_odom_lidar.T_world_body;
  size_t used = 0, used_published = 0;
  const double d02 =
      median_point_to_plane(r.scans[0], T_odom_sensor[0], r.scans[2], T_odom_sensor[2], 5, &used);
  const double d02_published = median_point_to_plane(r.scans[0], T_world_sensor[0], r.scans[2],
                                                     T_world_sensor[2], 5, &used_published);
  double max_translation_m = 0, max_rotation_deg = 0;
  for (size_t k = 1; k < 3; ++k) {
    const SE3 d = (T_world_sensor[0].inverse() * T_world_sensor[k]).inverse() * T_odom_sensor[k];
    max_translation_m = std::max(max_translation_m, d.t.norm());
    max_rotation_deg = std::max(max_rotation_deg, rotation_angle(d.R) * 180 / M_PI);
  }
  std::printf(
      "[ figures ] OS-1-128 frames 0, 2 (points as measured): median point-to-plane %.4f m with "
      "rigcal's odometry, %.4f m with the published poses; odometry against them: %.4f m, "
      "%.3f deg at most\n",
      d02, d02_published, max_translation_m, max_rotation_deg);
  EXPECT_LT(d02, 0.03);
  EXPECT_LT(max_translation_m, 0.05);
  EXPECT_LT(max_rotation_deg, 0.5);
}

// `rigcal odometry CAPTURE.pcap` reads the capture as it streams (CAPTURE.json beside it): the
// same trajectory, to the last bit, as on the capture's conversion and as a second run.
TEST_F(OusterPcapFiles, TheOdometryOfACaptureStreamsAndRepeatsToTheBit) {
  RIGCAL_REQUIRE_FIXTURE(pcap, "lidar/ouster_os1_128/OS-1-128_v2.3.0_1024x10_lb_n3.pcap");
  RIGCAL_REQUIRE_FIXTURE(json, "lidar/ouster_os1_128/OS-1-128_v2.3.0_1024x10.json");
  const fs::path capture = dir_ / "capture.pcap";
  fs::create_symlink(pcap, capture);
  fs::create_symlink(json, dir_ / "capture.json");
  auto odometry = [&](const fs::path& input, const std::string& out) {
    const testing::CliRun r = testing::rigcal_cli(
        fmt::format("odometry {} --sensor os1-64 --out {}", input.string(), (dir_ / out).string()),
        dir_);
    EXPECT_EQ(r.status, 0) << r.err;
    return testing::slurp(dir_ / out);
  };
  const std::string streamed = odometry(capture, "a.tum");
  EXPECT_EQ(std::count(streamed.begin(), streamed.end(), '\n'), 3);
  EXPECT_EQ(odometry(capture, "b.tum"), streamed);
  const testing::CliRun c =
      testing::rigcal_cli(fmt::format("convert {} --metadata {} --out {}", capture.string(),
                                      (dir_ / "capture.json").string(), (dir_ / "rec").string()),
                          dir_);
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_EQ(odometry(dir_ / "rec", "c.tum"), streamed);
  // Without its metadata beside it: exit 2, what is missing named.
  fs::remove(dir_ / "capture.json");
  const testing::CliRun none = testing::rigcal_cli(
      fmt::format("odometry {} --out {}", capture.string(), (dir_ / "d.tum").string()), dir_);
  EXPECT_EQ(none.status, 2);
  EXPECT_NE(none.err.find("capture.json is not beside it"), std::string::npos) << none.err;
  EXPECT_FALSE(fs::exists(dir_ / "d.tum"));
}

TEST(OusterGeometry, PointTimesLieInTheSweepAndIncreaseWithColumn) {
  RIGCAL_REQUIRE_FIXTURE(pcap, "lidar/ouster_os1_128/OS-1-128_v2.3.0_1024x10_lb_n3.pcap");
  RIGCAL_REQUIRE_FIXTURE(json, "lidar/ouster_os1_128/OS-1-128_v2.3.0_1024x10.json");
  const Os1128 r = read_os1_128(pcap, json);
  ASSERT_EQ(r.scans.size(), 3u);
  const int w = r.metadata.columns_per_frame;
  for (size_t k = 0; k < r.scans.size(); ++k) {
    const Scan& s = r.scans[k];
    EXPECT_GT(s.stamp.ns, 0);
    if (k > 0) {  // 10 Hz: frames 100 ms apart
      EXPECT_NEAR((s.stamp - r.scans[k - 1].stamp).seconds(), 0.1, 0.002);
    }
    // Per row, time as a function of the measured (staggered) column strictly increases.
    std::vector<std::vector<int64_t>> t_by_column(r.metadata.pixels_per_column,
                                                  std::vector<int64_t>(w, -1));
    int64_t t_max = 0;
    for (const ScanPoint& p : s.points) {
      EXPECT_GE(p.t_ns, 0);
      EXPECT_LT(p.t_ns, 100'000'000);
      t_max = std::max(t_max, p.t_ns);
      const int v = ((p.column - r.metadata.pixel_shift_by_row[p.ring]) % w + w) % w;
      t_by_column[p.ring][v] = p.t_ns;
      EXPECT_GT(p.range_mm, 0u);
    }
    EXPECT_GT(t_max, 95'000'000);  // a whole sweep
    size_t pairs = 0;
    for (const auto& row : t_by_column) {
      int64_t last = -1;
      for (int64_t t : row) {
        if (t < 0) continue;
        EXPECT_GT(t, last);
        last = t;
        ++pairs;
      }
    }
    EXPECT_GT(pairs, 50'000u);
    EXPECT_GT(r.stats[k].no_return, 0u);
    EXPECT_EQ(s.points.size() + r.stats[k].no_return,
              static_cast<size_t>(r.metadata.pixels_per_column) * (w - r.stats[k].invalid_columns));
  }
}

TEST(OusterImu, SamplesAreFiniteNearGravityAndIncreasing) {
  RIGCAL_REQUIRE_FIXTURE(pcap, "lidar/ouster_os1_128/OS-1-128_v2.3.0_1024x10_lb_n3.pcap");
  RIGCAL_REQUIRE_FIXTURE(json, "lidar/ouster_os1_128/OS-1-128_v2.3.0_1024x10.json");
  OusterPcapReader reader(pcap, io::read_ouster_metadata(json));
  std::vector<io::OusterImuSample> imu;
  reader.on_imu = [&](const io::OusterImuSample& s) { imu.push_back(s); };
  const Capture c = read_capture(reader);
  ASSERT_EQ(imu.size(), 30u);
  EXPECT_EQ(c.counters.imu_packets, 30u);
  for (size_t i = 0; i < imu.size(); ++i) {
    EXPECT_TRUE(imu[i].accel_mps2.allFinite() && imu[i].gyro_radps.allFinite());
    // The sensor rides a vehicle speeding up (0.4 g forward in the packets) and nearly level:
    // |a| 10.1 to 11.3 m/s^2, z about +1 g; rates below 7 deg/s.
    EXPECT_GT(imu[i].accel_mps2.norm(), 9.5) << i;
    EXPECT_LT(imu[i].accel_mps2.norm(), 11.8) << i;
    EXPECT_NEAR(imu[i].accel_mps2.z(), 9.8, 0.8) << i;
    EXPECT_LT(imu[i].gyro_radps.norm(), 0.15) << i;
    EXPECT_GT(imu[i].gyro_radps.norm(), 0.0) << i;
    if (i > 0) {
      EXPECT_GT(imu[i].stamp, imu[i - 1].stamp);
      EXPECT_GT(imu[i].gyro_stamp, imu[i - 1].gyro_stamp);
    }
  }
  // The IMU stamps are on the lidar clock: they lie within the frames' span.
  // 100 Hz.
  EXPECT_NEAR((imu.back().stamp - imu.front().stamp).seconds() / 29, 0.01, 0.001);
  ASSERT_FALSE(c.frames.empty());
  EXPECT_GT(imu.back().stamp.ns, static_cast<int64_t>(c.frames.front().timestamp[0]));
  EXPECT_LT(imu.front().stamp.ns,
            static_cast<int64_t>(c.frames.back().timestamp.back()) + 100'000'000);
}

}  // namespace
}  // namespace rigcal
