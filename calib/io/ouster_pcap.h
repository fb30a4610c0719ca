#pragma once
// A streaming reader of Ouster captures (doc/formats.md, "Ouster captures"): a pcap (or pcapng)
// file of the sensor's UDP packets (Ethernet, 802.1Q or Linux cooked link layer; IPv4 with
// fragment reassembly; UDP) and the sensor's metadata JSON. Frames are handed out one at a time;
// memory stays bounded whatever the capture's length (one frame being assembled, 4 cached
// packets, at most kMaxPendingDatagrams IPv4 datagrams being reassembled).
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/core/scan.h"
#include "rigcal/io/ouster_frames.h"
#include "rigcal/io/ouster_metadata.h"
#include "rigcal/io/ouster_packet.h"

namespace rigcal::io {

// Why a packet of the capture was not used. Each is counted with the first packet it happened to.
enum class OusterSkip {
  NotUdp,          // not an IPv4 UDP datagram (ARP, IPv6, another link payload)
  OtherUdp,        // UDP to another port, or of a size neither lidar nor IMU
  WrongSize,       // to the lidar port but not the size of the metadata's profile
  NotLidarType,    // packet header type is not 1 (lidar)
  InitIdMismatch,  // init_id differs from the metadata's (both nonzero)
  ProdSnMismatch,  // prod_sn differs from the metadata's (both nonzero)
  BadCrc,          // the footer's CRC-64 does not match (FW 3 and later)
  Stale,           // of a frame at or before the last released one
  FragmentLost,    // IPv4 fragments never completed (2 s timeout, or the capture ended)
  ShortCapture,    // the record holds fewer bytes than the packet (capture snap length)
  ImuNotDecoded,   // to the IMU port but not a 48-byte LEGACY IMU packet
};
inline constexpr size_t kOusterSkipReasons = 11;
std::string_view describe(OusterSkip reason);

struct OusterSkipCount {
  size_t count = 0;
  size_t first_packet = 0;  // 1-based record number in the capture (as Wireshark numbers them)
};

struct OusterCaptureCounters {
  size_t records = 0;        // pcap records read
  size_t lidar_packets = 0;  // decoded and batched (stale ones included)
  size_t imu_packets = 0;    // decoded
  size_t crc_good = 0;       // lidar packets whose CRC-64 was checked and matched
  std::array<OusterSkipCount, kOusterSkipReasons> skipped{};
  size_t frames_complete = 0, frames_incomplete = 0;
  bool truncated = false;  // the file ends inside a record
  std::string note;        // what the caller should know: a cut, an empty capture
  const OusterSkipCount& of(OusterSkip r) const { return skipped[static_cast<size_t>(r)]; }
  size_t skipped_total() const;
};

struct OusterPcapOptions {
  enum class Crc { Auto, Always, Never };
  Crc crc = Crc::Auto;  // Auto: checked where ouster_packets_have_crc says the footer is a CRC
};

class OusterPcapReader {
 public:
  static constexpr size_t kMaxPendingDatagrams = 64;
  static constexpr int64_t kFragmentTimeoutNs = 2'000'000'000;

  // Throws rigcal::Error naming the file when it cannot be opened or is not a pcap/pcapng file,
  // or when its link type is not Ethernet or Linux cooked capture.
  OusterPcapReader(const std::filesystem::path& pcap, OusterMetadata metadata,
                   OusterPcapOptions options = {});
  // The same over a capture held in memory; `name` stands for the file in messages.
  struct InMemory {};
  OusterPcapReader(InMemory, std::string name, std::string bytes, OusterMetadata metadata,
                   OusterPcapOptions options = {});
  ~OusterPcapReader();
  OusterPcapReader(const OusterPcapReader&) = delete;
  OusterPcapReader& operator=(const OusterPcapReader&) = delete;

  // Called for each decoded lidar packet, in capture order (before it is batched).
  std::function<void(const OusterLidarPacket&)> on_lidar_packet;
  // Called for each decoded IMU packet, in capture order.
  std::function<void(const OusterImuSample&)> on_imu;

  // The next frame (complete or not), or nullopt when the capture is done; a cut in the file ends
  // it (counters().truncated and note say where).
  std::optional<OusterFrame> next_frame();
  // The next frame as points (ouster_scan with this metadata's look-up table).
  std::optional<Scan> next_scan(OusterScanStats* stats = nullptr);

  const OusterMetadata& metadata() const { return metadata_; }
  const OusterCaptureCounters& counters() const { return counters_; }

 private:
  struct Impl;
  void open_check();
  bool read_record();  // false at the end of the capture
  void handle_datagram(const uint8_t* udp, size_t size);
  void skip(OusterSkip reason);

  OusterMetadata metadata_;
  OusterPcapOptions options_;
  std::string name_;
  std::unique_ptr<Impl> impl_;
  OusterCaptureCounters counters_;
  OusterFrameAssembler assembler_;
  std::vector<OusterFrame> ready_;
  size_t next_ready_ = 0;
  OusterLidarPacket packet_;
  std::optional<OusterXyzLut> lut_;
  bool done_ = false;
};

// True when the file starts as a pcap (microsecond or nanosecond, either byte order) or pcapng
// capture does.
bool is_pcap_capture(const std::filesystem::path& path);

}  // namespace rigcal::io
