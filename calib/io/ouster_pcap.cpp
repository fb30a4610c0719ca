#include "rigcal/io/ouster_pcap.h"

#include <fmt/format.h>
#include <pcap/pcap.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "rigcal/core/error.h"

namespace rigcal::io {
namespace {

constexpr int kLinkEthernet = 1;       // DLT_EN10MB
constexpr int kLinkLinuxCooked = 113;  // DLT_LINUX_SLL

uint16_t be16(const uint8_t* p) { return static_cast<uint16_t>((p[0] << 8) | p[1]); }

// One IPv4 datagram being reassembled from its fragments.
struct Datagram {
  uint32_t src = 0, dst = 0;
  uint16_t id = 0;
  int64_t first_seen_ns = 0;
  std::map<size_t, std::vector<uint8_t>> fragments;  // by byte offset; a repeat replaces
  size_t total = 0;                                  // known once the last fragment arrived
  size_t first_record = 0;
};

}  // namespace

std::string_view describe(OusterSkip reason) {
  switch (reason) {
    case OusterSkip::NotUdp:
      return "not an IPv4 UDP datagram";
    case OusterSkip::OtherUdp:
      return "UDP to another port or of a size neither lidar nor IMU";
    case OusterSkip::WrongSize:
      return "packet size does not match the metadata's profile";
    case OusterSkip::NotLidarType:
      return "packet type is not lidar";
    case OusterSkip::InitIdMismatch:
      return "init_id differs from the metadata's";
    case OusterSkip::ProdSnMismatch:
      return "prod_sn differs from the metadata's";
    case OusterSkip::BadCrc:
      return "CRC-64 of the footer does not match";
    case OusterSkip::Stale:
      return "stale: of a frame at or before the last released one";
    case OusterSkip::FragmentLost:
      return "IPv4 fragments never completed";
    case OusterSkip::ShortCapture:
      return "record shorter than the packet (capture snap length)";
    case OusterSkip::ImuNotDecoded:
      return "IMU packet not of the 48-byte LEGACY profile";
  }
  return "?";
}

size_t OusterCaptureCounters::skipped_total() const {
  size_t n = 0;
  for (const OusterSkipCount& s : skipped) n += s.count;
  return n;
}

struct OusterPcapReader::Impl {
  std::string bytes;  // the capture, when read from memory
  FILE* memory_file = nullptr;
  pcap_t* pcap = nullptr;
  int link = 0;
  std::vector<Datagram> pending;
  ~Impl() {
    if (pcap) pcap_close(pcap);  // closes memory_file too
  }
};

OusterPcapReader::OusterPcapReader(const std::filesystem::path& pcap, OusterMetadata metadata,
                                   OusterPcapOptions options)
    : metadata_(std::move(metadata)),
      options_(options),
      name_(pcap.string()),
      impl_(std::make_unique<Impl>()),
      assembler_(metadata_) {
  char err[PCAP_ERRBUF_SIZE] = {};
  impl_->pcap =
      pcap_open_offline_with_tstamp_precision(name_.c_str(), PCAP_TSTAMP_PRECISION_NANO, err);
  if (!impl_->pcap) fail_at(name_, 0, "", fmt::format("not a readable pcap capture: {}", err));
  open_check();
}

OusterPcapReader::OusterPcapReader(InMemory, std::string name, std::string bytes,
                                   OusterMetadata metadata, OusterPcapOptions options)
    : metadata_(std::move(metadata)),
      options_(options),
      name_(std::move(name)),
      impl_(std::make_unique<Impl>()),
      assembler_(metadata_) {
  impl_->bytes = std::move(bytes);
  if (impl_->bytes.empty()) fail_at(name_, 0, "", "not a pcap capture: empty");
  impl_->memory_file = fmemopen(impl_->bytes.data(), impl_->bytes.size(), "rb");
  if (!impl_->memory_file) fail_at(name_, 0, "", "cannot open the capture in memory");
  char err[PCAP_ERRBUF_SIZE] = {};
  impl_->pcap =
      pcap_fopen_offline_with_tstamp_precision(impl_->memory_file, PCAP_TSTAMP_PRECISION_NANO, err);
  if (!impl_->pcap) {
    std::fclose(impl_->memory_file);
    fail_at(name_, 0, "", fmt::format("not a readable pcap capture: {}", err));
  }
  open_check();
}

OusterPcapReader::~OusterPcapReader() = default;

void OusterPcapReader::open_check() {
  impl_->link = pcap_datalink(impl_->pcap);
  if (impl_->link != kLinkEthernet && impl_->link != kLinkLinuxCooked)
    fail_at(name_, 0, "",
            fmt::format("link type {} not read (Ethernet {} and Linux cooked {} are)", impl_->link,
                        kLinkEthernet, kLinkLinuxCooked));
}

void OusterPcapReader::skip(OusterSkip reason) {
  OusterSkipCount& s = counters_.skipped[static_cast<size_t>(reason)];
  if (s.count++ == 0) s.first_packet = counters_.records;
}

void OusterPcapReader::handle_datagram(const uint8_t* udp, size_t size) {
  if (size < 8) return skip(OusterSkip::NotUdp);
  const uint16_t dst_port = be16(udp + 2);
  const size_t udp_length = be16(udp + 4);
  if (udp_length < 8) return skip(OusterSkip::NotUdp);
  if (udp_length > size) return skip(OusterSkip::ShortCapture);
  const std::span<const uint8_t> payload(udp + 8, udp_length - 8);
  const size_t lidar_bytes = ouster_lidar_packet_bytes(metadata_);
  const int lidar_port = metadata_.udp_port_lidar, imu_port = metadata_.udp_port_imu;
  const bool to_lidar = lidar_port != 0 ? dst_port == lidar_port : payload.size() == lidar_bytes;
  const bool to_imu =
      imu_port != 0 ? dst_port == imu_port : payload.size() == kOusterLegacyImuPacketBytes;
  if (to_imu && payload.size() == kOusterLegacyImuPacketBytes &&
      !(to_lidar && payload.size() == lidar_bytes)) {
    if (metadata_.udp_profile_imu != "LEGACY") return skip(OusterSkip::ImuNotDecoded);
    ++counters_.imu_packets;
    if (on_imu) on_imu(*decode_ouster_imu_packet(payload));
    return;
  }
  if (to_lidar) {
    if (payload.size() != lidar_bytes) return skip(OusterSkip::WrongSize);
    const bool check_crc =
        options_.crc == OusterPcapOptions::Crc::Always ||
        (options_.crc == OusterPcapOptions::Crc::Auto && ouster_packets_have_crc(metadata_));
    switch (decode_ouster_lidar_packet(payload, metadata_, check_crc, packet_)) {
      case OusterPacketResult::Ok:
        break;
      case OusterPacketResult::WrongSize:
        return skip(OusterSkip::WrongSize);
      case OusterPacketResult::NotLidar:
        return skip(OusterSkip::NotLidarType);
      case OusterPacketResult::BadCrc:
        return skip(OusterSkip::BadCrc);
    }
    if (metadata_.init_id != 0 && packet_.init_id != 0 && packet_.init_id != metadata_.init_id)
      return skip(OusterSkip::InitIdMismatch);
    if (metadata_.prod_sn_number != 0 && packet_.prod_sn != 0 &&
        packet_.prod_sn != metadata_.prod_sn_number)
      return skip(OusterSkip::ProdSnMismatch);
    ++counters_.lidar_packets;
    if (packet_.crc_checked) ++counters_.crc_good;
    if (on_lidar_packet) on_lidar_packet(packet_);
    const size_t dropped = assembler_.dropped_packets();
    assembler_.add(packet_, ready_);
    // Drops found now may be of packets cached earlier; they are counted at this record.
    for (size_t i = dropped; i < assembler_.dropped_packets(); ++i) skip(OusterSkip::Stale);
    return;
  }
  if (to_imu) return skip(OusterSkip::ImuNotDecoded);
  skip(OusterSkip::OtherUdp);
}

bool OusterPcapReader::read_record() {
  pcap_pkthdr* header = nullptr;
  const u_char* data = nullptr;
  const int rc = pcap_next_ex(impl_->pcap, &header, &data);
  if (rc == PCAP_ERROR_BREAK) return false;
  if (rc != 1) {
    counters_.truncated = true;
    counters_.note = fmt::format(
        "{}: the capture is cut short after packet {} ({}); the frames up to the cut are kept",
        name_, counters_.records, pcap_geterr(impl_->pcap));
    return false;
  }
  ++counters_.records;
  // Record time, ns (only the fragment timeout uses it). Seconds are clamped to +-4e9 (year 2096)
  // so that a damaged pcapng stamp cannot overflow the sum or a difference of two.
  const int64_t seconds = std::clamp<int64_t>(header->ts.tv_sec, -4'000'000'000, 4'000'000'000);
  const int64_t stamp_ns =
      seconds * 1'000'000'000 + std::clamp<int64_t>(header->ts.tv_usec, 0, 999'999'999);
  const uint8_t* p = data;
  size_t n = header->caplen;

  // Link layer.
  uint16_t ether_type = 0;
  if (impl_->link == kLinkEthernet) {
    if (n < 14) return skip(OusterSkip::NotUdp), true;
    ether_type = be16(p + 12);
    p += 14;
    n -= 14;
    while (ether_type == 0x8100 || ether_type == 0x88A8) {  // VLAN tags
      if (n < 4) return skip(OusterSkip::NotUdp), true;
      ether_type = be16(p + 2);
      p += 4;
      n -= 4;
    }
  } else {
    if (n < 16) return skip(OusterSkip::NotUdp), true;
    ether_type = be16(p + 14);
    p += 16;
    n -= 16;
  }
  if (ether_type != 0x0800 || n < 20 || (p[0] >> 4) != 4) return skip(OusterSkip::NotUdp), true;
  const size_t ihl = static_cast<size_t>(p[0] & 0x0F) * 4;
  const size_t total = be16(p + 2);
  if (ihl < 20 || total < ihl) return skip(OusterSkip::NotUdp), true;
  if (total > n) return skip(OusterSkip::ShortCapture), true;
  if (p[9] != 17) return skip(OusterSkip::NotUdp), true;
  const uint16_t id = be16(p + 4);
  const uint16_t flags_offset = be16(p + 6);
  const bool more = (flags_offset & 0x2000) != 0;
  const size_t offset = static_cast<size_t>(flags_offset & 0x1FFF) * 8;
  uint32_t src, dst;
  std::memcpy(&src, p + 12, 4);
  std::memcpy(&dst, p + 16, 4);
  const uint8_t* body = p + ihl;
  const size_t body_n = total - ihl;

  // Datagrams whose fragments are older than the timeout are given up.
  auto& pending = impl_->pending;
  for (size_t i = 0; i < pending.size();) {
    if (stamp_ns - pending[i].first_seen_ns > kFragmentTimeoutNs) {
      OusterSkipCount& s = counters_.skipped[static_cast<size_t>(OusterSkip::FragmentLost)];
      if (s.count++ == 0) s.first_packet = pending[i].first_record;
      pending.erase(pending.begin() + static_cast<std::ptrdiff_t>(i));
    } else {
      ++i;
    }
  }
  if (!more && offset == 0) {
    handle_datagram(body, body_n);
    return true;
  }
  if (offset + body_n > 65535) return skip(OusterSkip::NotUdp), true;
  Datagram* d = nullptr;
  for (Datagram& x : pending)
    if (x.src == src && x.dst == dst && x.id == id) d = &x;
  if (!d) {
    if (pending.size() >= kMaxPendingDatagrams) {
      OusterSkipCount& s = counters_.skipped[static_cast<size_t>(OusterSkip::FragmentLost)];
      if (s.count++ == 0) s.first_packet = pending.front().first_record;
      pending.erase(pending.begin());
    }
    pending.push_back(Datagram{src, dst, id, stamp_ns, {}, 0, counters_.records});
    d = &pending.back();
  }
  d->fragments[offset] = std::vector<uint8_t>(body, body + body_n);
  if (!more) d->total = offset + body_n;
  if (d->total == 0) return true;
  // Complete when the fragments cover [0, total) without a gap.
  size_t covered = 0;
  for (const auto& [at, bytes] : d->fragments) {
    if (at > covered) return true;
    covered = std::max(covered, at + bytes.size());
  }
  if (covered < d->total) return true;
  std::vector<uint8_t> whole(d->total);
  for (const auto& [at, bytes] : d->fragments) {
    const size_t end = std::min(at + bytes.size(), d->total);
    if (at < end) std::memcpy(whole.data() + at, bytes.data(), end - at);
  }
  pending.erase(pending.begin() + (d - pending.data()));
  handle_datagram(whole.data(), whole.size());
  return true;
}

std::optional<OusterFrame> OusterPcapReader::next_frame() {
  while (next_ready_ >= ready_.size()) {
    ready_.clear();
    next_ready_ = 0;
    if (done_) return std::nullopt;
    if (!read_record()) {
      done_ = true;
      for (const Datagram& d : impl_->pending) {
        OusterSkipCount& s = counters_.skipped[static_cast<size_t>(OusterSkip::FragmentLost)];
        if (s.count++ == 0) s.first_packet = d.first_record;
      }
      impl_->pending.clear();
      const size_t dropped = assembler_.dropped_packets();
      assembler_.finish(ready_);
      for (size_t i = dropped; i < assembler_.dropped_packets(); ++i) skip(OusterSkip::Stale);
      if (counters_.records == 0 && !counters_.truncated)
        counters_.note = fmt::format("{}: the capture holds no packets", name_);
      else if (counters_.lidar_packets == 0 && counters_.note.empty())
        counters_.note = fmt::format("{}: no lidar packet of the metadata's sensor in {} packets",
                                     name_, counters_.records);
    }
  }
  OusterFrame frame = std::move(ready_[next_ready_++]);
  ++(frame.complete ? counters_.frames_complete : counters_.frames_incomplete);
  return frame;
}

std::optional<Scan> OusterPcapReader::next_scan(OusterScanStats* stats) {
  std::optional<OusterFrame> frame = next_frame();
  if (!frame) return std::nullopt;
  if (!lut_) lut_ = make_ouster_xyz_lut(metadata_);
  return ouster_scan(*frame, metadata_, *lut_, stats);
}

bool is_pcap_capture(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char m[4] = {};
  in.read(reinterpret_cast<char*>(m), 4);
  const uint32_t v =
      uint32_t(m[0]) | uint32_t(m[1]) << 8 | uint32_t(m[2]) << 16 | uint32_t(m[3]) << 24;
  return v == 0xa1b2c3d4 || v == 0xd4c3b2a1 || v == 0xa1b23c4d || v == 0x4d3cb2a1 ||
         v == 0x0a0d0d0a;
}

}  // namespace rigcal::io
