// An Ouster capture (io::OusterPcapReader): the metadata JSON, a line `--pcap--`, then the pcap
// bytes. Every frame read must have the metadata's size and give finite points with times inside
// the frame; the counters must add up.
#include <cmath>
#include <string>

#include "fuzz_common.h"
#include "rigcal/io/ouster_metadata.h"
#include "rigcal/io/ouster_pcap.h"

static int fuzz_ouster(const uint8_t* data, size_t size) {
  using namespace rigcal;
  const std::vector<std::string_view> parts =
      fuzz::split_parts(fuzz::as_text(data, size), "--pcap--");
  fuzz::expect_only_rigcal_errors([&] {
    io::OusterMetadata m = io::parse_ouster_metadata(parts[0], "fuzz.json");
    if (parts.size() < 2) return;
    const size_t h = m.pixels_per_column, w = m.columns_per_frame;
    io::OusterPcapReader reader(io::OusterPcapReader::InMemory{}, "fuzz.pcap",
                                std::string(parts[1]), std::move(m));
    size_t frames = 0, imu = 0;
    reader.on_imu = [&](const io::OusterImuSample&) { ++imu; };
    io::OusterScanStats stats;
    while (auto scan = reader.next_scan(&stats)) {
      ++frames;
      if (scan->points.size() + stats.no_return > h * (w - stats.invalid_columns))
        fuzz::finding("more points than pixels", std::to_string(scan->points.size()));
      for (const ScanPoint& p : scan->points) {
        if (!p.p.allFinite()) fuzz::finding("a point not finite", std::to_string(p.range_mm));
        if (p.ring >= h || p.column >= w) fuzz::finding("a pixel outside the frame", "");
        if (p.range_mm == 0) fuzz::finding("a point without a return", "");
      }
    }
    const io::OusterCaptureCounters& c = reader.counters();
    if (c.frames_complete + c.frames_incomplete != frames)
      fuzz::finding("frame counts disagree", std::to_string(frames));
    if (c.imu_packets != imu) fuzz::finding("IMU counts disagree", std::to_string(imu));
  });
  return 0;
}
RIGCAL_FUZZ_TARGET(ouster, fuzz_ouster)
