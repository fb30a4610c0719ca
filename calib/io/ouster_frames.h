#pragma once
// Ouster frames (doc/formats.md, "Ouster captures"): lidar packets batched into frames by
// frame_id as the sensor's own software does it, and a frame turned into points in the sensor
// frame with per-point times (rigcal::Scan).
#include <cstddef>
#include <cstdint>
#include <deque>
#include <vector>

#include "rigcal/core/scan.h"
#include "rigcal/io/ouster_metadata.h"
#include "rigcal/io/ouster_packet.h"

namespace rigcal::io {

// One frame, staggered (column index = measurement_id), h x w row-major. Missing or invalid
// columns are zero in every field and in timestamp, measurement_id and status.
struct OusterFrame {
  uint32_t frame_id = 0;
  uint32_t init_id = 0;
  uint64_t prod_sn = 0;
  int h = 0, w = 0;
  std::vector<uint64_t> timestamp;       // w, ns, sensor clock
  std::vector<uint16_t> measurement_id;  // w
  std::vector<uint32_t> status;          // w
  std::vector<uint32_t> encoder;         // w (LEGACY only, else zero)
  OusterImages pixels;                   // h x w
  int packets_expected = 0;
  int packets_received = 0;  // distinct packet slots filled
  bool complete = false;     // released because every expected packet slot arrived
};

// Batches packets into frames (the rules of doc/formats.md: expected packets from
// column_window; released when as many packets arrived as expected and they fill distinct
// slots; packets of later frames wait in a cache of 4, and a full cache releases the current
// frame incomplete; packets of frames at or before the last released one are dropped (modular
// frame_id comparison); an init_id change releases the current frame and starts afresh).
// Memory: one frame and at most 4 packets.
class OusterFrameAssembler {
 public:
  static constexpr size_t kMaxCachedPackets = 4;

  explicit OusterFrameAssembler(const OusterMetadata& m);
  // Adds a packet; frames it releases are appended to `released`.
  void add(const OusterLidarPacket& packet, std::vector<OusterFrame>& released);
  // End of input: the cached packets are batched and the frame in progress is released.
  void finish(std::vector<OusterFrame>& released);
  // Packets dropped as stale (of a frame at or before the last released one).
  size_t dropped_packets() const { return dropped_; }

 private:
  int frame_id_difference(uint32_t current, uint32_t other) const;
  void start(uint32_t frame_id, const OusterLidarPacket& packet);
  void batch(const OusterLidarPacket& packet);
  bool frame_complete() const;
  void finalize(std::vector<OusterFrame>& released);
  void reset();
  // The cached packet of the earliest frame (first cached among equals).
  size_t earliest_cached() const;
  bool batch_with_caching(bool force, std::vector<OusterFrame>& released);

  const OusterMetadata& m_;
  int expected_ = 0;
  uint32_t last_init_id_ = 0;
  bool active_ = false;    // a frame is being batched
  bool finished_ = false;  // finished_frame_id_ is valid
  uint32_t finished_frame_id_ = 0;
  int batched_ = 0;
  std::vector<bool> slot_filled_;
  OusterFrame frame_;
  std::deque<OusterLidarPacket> cache_;
  size_t dropped_ = 0;
};

// Per pixel (u, v) of the staggered frame: the point is direction * range_mm + offset, in the
// sensor frame, metres (the LiDAR frame's beam model, then T_sensor_lidar).
struct OusterXyzLut {
  int h = 0, w = 0;
  std::vector<Eigen::Vector3d> direction;  // m per mm of range
  std::vector<Eigen::Vector3d> offset;     // m
};
OusterXyzLut make_ouster_xyz_lut(const OusterMetadata& m);

// The destaggered column of staggered column v in row u: (v + shift[u]) mod w.
int ouster_destaggered_column(const OusterMetadata& m, int u, int v);

struct OusterScanStats {
  size_t no_return = 0;        // pixels of valid columns with range 0 (not in the scan)
  size_t invalid_columns = 0;  // columns missing or not valid (no points)
};

// The frame's points: stamp = the timestamp of the first valid column (lowest measurement_id);
// t_ns = the point's column timestamp minus the stamp; ring = row u; column = destaggered column;
// intensity = SIGNAL where the profile has it, else REFLECTIVITY; range 0 is no point. Points are
// ordered by row, then by destaggered column. A frame without a valid column gives no points and
// stamp 0.
Scan ouster_scan(const OusterFrame& frame, const OusterMetadata& m, const OusterXyzLut& lut,
                 OusterScanStats* stats = nullptr);

}  // namespace rigcal::io
