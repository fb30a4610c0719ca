#include "rigcal/io/ouster_packet.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <numbers>

namespace rigcal::io {
namespace {

using F = OusterField;

constexpr OusterFieldSpec kLegacy[] = {{F::Range, 0, 19, 0},
                                       {F::Flags, 28, 31, 0},
                                       {F::Reflectivity, 32, 39, 0},
                                       {F::Signal, 48, 63, 0},
                                       {F::NearIr, 64, 79, 0}};
constexpr OusterFieldSpec kRng19[] = {{F::Range, 0, 18, 0},         {F::Flags, 19, 23, 0},
                                      {F::Reflectivity, 32, 39, 0}, {F::Signal, 48, 63, 0},
                                      {F::NearIr, 64, 79, 0},       {F::Window, 88, 95, 0}};
constexpr OusterFieldSpec kRng19Dual[] = {
    {F::Range, 0, 18, 0},    {F::Flags, 19, 23, 0},   {F::Reflectivity, 24, 31, 0},
    {F::Range2, 32, 50, 0},  {F::Flags2, 51, 55, 0},  {F::Reflectivity2, 56, 63, 0},
    {F::Signal, 64, 79, 0},  {F::Signal2, 80, 95, 0}, {F::NearIr, 96, 111, 0},
    {F::Window, 120, 127, 0}};
constexpr OusterFieldSpec kRng15[] = {{F::Range, 0, 14, 3},
                                      {F::Flags, 15, 15, 0},
                                      {F::Reflectivity, 16, 23, 0},
                                      {F::NearIr, 24, 31, 4}};
constexpr OusterFieldSpec kRng15Dual[] = {{F::Range, 0, 14, 3},          {F::Flags, 15, 15, 0},
                                          {F::Reflectivity, 16, 23, 0},  {F::NearIr, 24, 31, 4},
                                          {F::Range2, 32, 46, 3},        {F::Flags2, 47, 47, 0},
                                          {F::Reflectivity2, 48, 55, 0}, {F::Window, 56, 63, 0}};

uint64_t le(const uint8_t* p, size_t n) {
  uint64_t v = 0;
  for (size_t i = 0; i < n; ++i) v |= uint64_t{p[i]} << (8 * i);
  return v;
}

// Bits [first, last] (inclusive, little-endian bit order) of the bytes at p; reads only the bytes
// the field covers.
uint64_t bits(const uint8_t* p, int first, int last) {
  const int b0 = first / 8, b1 = last / 8;
  const uint64_t word = le(p + b0, static_cast<size_t>(b1 - b0 + 1));
  const int width = last - first + 1;
  const uint64_t mask = width >= 64 ? ~uint64_t{0} : (uint64_t{1} << width) - 1;
  return (word >> (first - 8 * b0)) & mask;
}

}  // namespace

std::string_view to_string(OusterField field) {
  switch (field) {
    case F::Range:
      return "RANGE";
    case F::Range2:
      return "RANGE2";
    case F::Flags:
      return "FLAGS";
    case F::Flags2:
      return "FLAGS2";
    case F::Reflectivity:
      return "REFLECTIVITY";
    case F::Reflectivity2:
      return "REFLECTIVITY2";
    case F::Signal:
      return "SIGNAL";
    case F::Signal2:
      return "SIGNAL2";
    case F::NearIr:
      return "NEAR_IR";
    case F::Window:
      return "WINDOW";
  }
  return "?";
}

std::span<const OusterFieldSpec> ouster_fields(OusterLidarProfile profile) {
  switch (profile) {
    case OusterLidarProfile::Legacy:
      return kLegacy;
    case OusterLidarProfile::Rng19Rfl8Sig16Nir16:
      return kRng19;
    case OusterLidarProfile::Rng19Rfl8Sig16Nir16Dual:
      return kRng19Dual;
    case OusterLidarProfile::Rng15Rfl8Nir8:
      return kRng15;
    case OusterLidarProfile::Rng15Rfl8Nir8Dual:
    case OusterLidarProfile::FusaRng15Rfl8Nir8Dual:
      return kRng15Dual;
  }
  return {};
}

size_t ouster_block_bytes(OusterLidarProfile profile) {
  switch (profile) {
    case OusterLidarProfile::Legacy:
    case OusterLidarProfile::Rng19Rfl8Sig16Nir16:
      return 12;
    case OusterLidarProfile::Rng19Rfl8Sig16Nir16Dual:
      return 16;
    case OusterLidarProfile::Rng15Rfl8Nir8:
      return 4;
    case OusterLidarProfile::Rng15Rfl8Nir8Dual:
    case OusterLidarProfile::FusaRng15Rfl8Nir8Dual:
      return 8;
  }
  return 0;
}

void OusterImages::resize(OusterLidarProfile profile, size_t pixels) {
  *this = OusterImages{};
  for (const OusterFieldSpec& s : ouster_fields(profile)) {
    switch (s.field) {
      case F::Range:
        range.assign(pixels, 0);
        break;
      case F::Range2:
        range2.assign(pixels, 0);
        break;
      case F::Flags:
        flags.assign(pixels, 0);
        break;
      case F::Flags2:
        flags2.assign(pixels, 0);
        break;
      case F::Reflectivity:
        reflectivity.assign(pixels, 0);
        break;
      case F::Reflectivity2:
        reflectivity2.assign(pixels, 0);
        break;
      case F::Signal:
        signal.assign(pixels, 0);
        break;
      case F::Signal2:
        signal2.assign(pixels, 0);
        break;
      case F::NearIr:
        near_ir.assign(pixels, 0);
        break;
      case F::Window:
        window.assign(pixels, 0);
        break;
    }
  }
}

bool OusterImages::has(OusterField f) const {
  switch (f) {
    case F::Range:
      return !range.empty();
    case F::Range2:
      return !range2.empty();
    case F::Flags:
      return !flags.empty();
    case F::Flags2:
      return !flags2.empty();
    case F::Reflectivity:
      return !reflectivity.empty();
    case F::Reflectivity2:
      return !reflectivity2.empty();
    case F::Signal:
      return !signal.empty();
    case F::Signal2:
      return !signal2.empty();
    case F::NearIr:
      return !near_ir.empty();
    case F::Window:
      return !window.empty();
  }
  return false;
}

uint32_t OusterImages::get(OusterField f, size_t i) const {
  switch (f) {
    case F::Range:
      return range[i];
    case F::Range2:
      return range2[i];
    case F::Flags:
      return flags[i];
    case F::Flags2:
      return flags2[i];
    case F::Reflectivity:
      return reflectivity[i];
    case F::Reflectivity2:
      return reflectivity2[i];
    case F::Signal:
      return signal[i];
    case F::Signal2:
      return signal2[i];
    case F::NearIr:
      return near_ir[i];
    case F::Window:
      return window[i];
  }
  return 0;
}

void OusterImages::set(OusterField f, size_t i, uint32_t v) {
  switch (f) {
    case F::Range:
      range[i] = v;
      break;
    case F::Range2:
      range2[i] = v;
      break;
    case F::Flags:
      flags[i] = static_cast<uint8_t>(v);
      break;
    case F::Flags2:
      flags2[i] = static_cast<uint8_t>(v);
      break;
    case F::Reflectivity:
      reflectivity[i] = static_cast<uint8_t>(v);
      break;
    case F::Reflectivity2:
      reflectivity2[i] = static_cast<uint8_t>(v);
      break;
    case F::Signal:
      signal[i] = static_cast<uint16_t>(v);
      break;
    case F::Signal2:
      signal2[i] = static_cast<uint16_t>(v);
      break;
    case F::NearIr:
      near_ir[i] = static_cast<uint16_t>(v);
      break;
    case F::Window:
      window[i] = static_cast<uint8_t>(v);
      break;
  }
}

void OusterImages::zero() {
  for (auto* v : {&range, &range2}) std::fill(v->begin(), v->end(), 0);
  for (auto* v : {&signal, &signal2, &near_ir}) std::fill(v->begin(), v->end(), 0);
  for (auto* v : {&reflectivity, &reflectivity2, &flags, &flags2, &window})
    std::fill(v->begin(), v->end(), 0);
}

uint64_t crc64_xz(std::span<const uint8_t> bytes) {
  static const std::array<uint64_t, 256> table = [] {
    std::array<uint64_t, 256> t{};
    for (uint64_t i = 0; i < 256; ++i) {
      uint64_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? (c >> 1) ^ 0xC96C5795D7870F42ULL : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  uint64_t crc = ~uint64_t{0};
  for (uint8_t b : bytes) crc = table[(crc ^ b) & 0xFF] ^ (crc >> 8);
  return ~crc;
}

OusterPacketResult decode_ouster_lidar_packet(std::span<const uint8_t> bytes,
                                              const OusterMetadata& m, bool check_crc,
                                              OusterLidarPacket& out) {
  if (bytes.size() != ouster_lidar_packet_bytes(m)) return OusterPacketResult::WrongSize;
  const size_t h = m.pixels_per_column, cpp = m.columns_per_packet;
  const bool legacy = m.udp_profile_lidar == OusterLidarProfile::Legacy;
  const uint8_t* p = bytes.data();
  out.crc_checked = false;
  if (legacy) {
    out.packet_type = 0;
    out.frame_id = static_cast<uint32_t>(le(p + 10, 2));
    out.init_id = 0;
    out.prod_sn = 0;
    out.alert_flags = 0;
  } else if (m.header_type == OusterHeaderType::Fusa) {
    out.packet_type = static_cast<uint16_t>(bits(p, 0, 7));
    out.init_id = static_cast<uint32_t>(bits(p, 8, 31));
    out.frame_id = static_cast<uint32_t>(bits(p, 32, 63));
    out.alert_flags = static_cast<uint8_t>(bits(p, 64, 71));
    out.prod_sn = bits(p, 88, 127);
  } else {
    out.packet_type = static_cast<uint16_t>(bits(p, 0, 15));
    out.frame_id = static_cast<uint32_t>(bits(p, 16, 31));
    out.init_id = static_cast<uint32_t>(bits(p, 32, 55));
    out.prod_sn = bits(p, 56, 95);
    out.alert_flags = static_cast<uint8_t>(bits(p, 96, 103));
  }
  if (!legacy && out.packet_type != 1) return OusterPacketResult::NotLidar;
  if (check_crc) {
    const size_t n = bytes.size();
    if (crc64_xz(bytes.first(n - 8)) != le(p + n - 8, 8)) return OusterPacketResult::BadCrc;
    out.crc_checked = true;
  }

  const size_t block = ouster_block_bytes(m.udp_profile_lidar);
  const size_t column_bytes = legacy ? 16 + block * h + 4 : 12 + block * h;
  const uint8_t* columns = legacy ? p : p + 32;
  out.timestamp.resize(cpp);
  out.measurement_id.resize(cpp);
  out.status.resize(cpp);
  out.encoder.assign(cpp, 0);
  out.pixels.resize(m.udp_profile_lidar, h * cpp);
  const std::span<const OusterFieldSpec> fields = ouster_fields(m.udp_profile_lidar);
  for (size_t c = 0; c < cpp; ++c) {
    const uint8_t* col = columns + c * column_bytes;
    out.timestamp[c] = le(col, 8);
    out.measurement_id[c] = static_cast<uint16_t>(le(col + 8, 2));
    if (legacy) {
      out.encoder[c] = static_cast<uint32_t>(le(col + 12, 4));
      out.status[c] = static_cast<uint32_t>(le(col + 16 + block * h, 4));
    } else {
      out.status[c] = static_cast<uint32_t>(le(col + 10, 2));
    }
    const uint8_t* blocks = col + (legacy ? 16 : 12);
    for (size_t u = 0; u < h; ++u) {
      const uint8_t* b = blocks + u * block;
      for (const OusterFieldSpec& s : fields)
        out.pixels.set(s.field, u * cpp + c,
                       static_cast<uint32_t>(bits(b, s.first_bit, s.last_bit) << s.upshift));
    }
  }
  return OusterPacketResult::Ok;
}

std::optional<OusterImuSample> decode_ouster_imu_packet(std::span<const uint8_t> bytes) {
  if (bytes.size() != kOusterLegacyImuPacketBytes) return std::nullopt;
  const uint8_t* p = bytes.data();
  const auto f32 = [&](size_t at) {
    const uint32_t u = static_cast<uint32_t>(le(p + at, 4));
    float f;
    std::memcpy(&f, &u, 4);
    return static_cast<double>(f);
  };
  OusterImuSample s;
  s.sys_stamp = Time::from_ns(static_cast<int64_t>(le(p, 8)));
  s.stamp = Time::from_ns(static_cast<int64_t>(le(p + 8, 8)));
  s.gyro_stamp = Time::from_ns(static_cast<int64_t>(le(p + 16, 8)));
  const double deg = std::numbers::pi / 180.0;
  s.accel_mps2 = Eigen::Vector3d(f32(24), f32(28), f32(32)) * kStandardGravity;
  s.gyro_radps = Eigen::Vector3d(f32(36), f32(40), f32(44)) * deg;
  return s;
}

}  // namespace rigcal::io
