#include "rigcal/io/ouster_frames.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

namespace rigcal::io {

OusterFrameAssembler::OusterFrameAssembler(const OusterMetadata& m)
    : m_(m), expected_(ouster_expected_packets(m)), last_init_id_(m.init_id) {}

int OusterFrameAssembler::frame_id_difference(uint32_t current, uint32_t other) const {
  const int64_t max_id =
      m_.header_type == OusterHeaderType::Fusa && m_.udp_profile_lidar != OusterLidarProfile::Legacy
          ? 0xFFFFFFFFLL
          : 0xFFFFLL;
  const int64_t half = max_id >> 1;
  int64_t delta = static_cast<int64_t>(other) - static_cast<int64_t>(current);
  if (delta < -half)
    delta += max_id + 1;
  else if (delta > half)
    delta -= max_id + 1;
  return static_cast<int>(std::max<int64_t>(std::min<int64_t>(delta, INT32_MAX), INT32_MIN));
}

void OusterFrameAssembler::start(uint32_t frame_id, const OusterLidarPacket& packet) {
  const int h = m_.pixels_per_column, w = m_.columns_per_frame;
  frame_ = OusterFrame{};
  frame_.frame_id = frame_id;
  frame_.init_id = packet.init_id;
  frame_.prod_sn = packet.prod_sn;
  frame_.h = h;
  frame_.w = w;
  frame_.timestamp.assign(w, 0);
  frame_.measurement_id.assign(w, 0);
  frame_.status.assign(w, 0);
  frame_.encoder.assign(w, 0);
  frame_.pixels.resize(m_.udp_profile_lidar, static_cast<size_t>(h) * w);
  frame_.packets_expected = expected_;
  slot_filled_.assign(w / m_.columns_per_packet, false);
  batched_ = 0;
  active_ = true;
  finished_ = false;
}

void OusterFrameAssembler::batch(const OusterLidarPacket& packet) {
  const int h = m_.pixels_per_column, w = m_.columns_per_frame, cpp = m_.columns_per_packet;
  const std::span<const OusterFieldSpec> fields = ouster_fields(m_.udp_profile_lidar);
  for (int c = 0; c < cpp; ++c) {
    const int v = packet.measurement_id[c];
    if (v >= w || (packet.status[c] & 1u) == 0) continue;
    frame_.timestamp[v] = packet.timestamp[c];
    frame_.measurement_id[v] = packet.measurement_id[c];
    frame_.status[v] = packet.status[c];
    frame_.encoder[v] = packet.encoder[c];
    for (int u = 0; u < h; ++u)
      for (const OusterFieldSpec& s : fields)
        frame_.pixels.set(s.field, static_cast<size_t>(u) * w + v,
                          packet.pixels.get(s.field, static_cast<size_t>(u) * cpp + c));
  }
  ++batched_;
  const size_t slot = packet.measurement_id[0] / cpp;
  if (slot < slot_filled_.size() && !slot_filled_[slot]) {
    slot_filled_[slot] = true;
    ++frame_.packets_received;
  }
}

bool OusterFrameAssembler::frame_complete() const {
  return batched_ >= expected_ && frame_.packets_received == expected_;
}

void OusterFrameAssembler::finalize(std::vector<OusterFrame>& released) {
  frame_.complete = frame_complete();
  finished_frame_id_ = frame_.frame_id;
  finished_ = true;
  active_ = false;
  batched_ = 0;
  released.push_back(std::move(frame_));
  frame_ = OusterFrame{};
}

void OusterFrameAssembler::reset() {
  active_ = false;
  finished_ = false;
  batched_ = 0;
  cache_.clear();
}

size_t OusterFrameAssembler::earliest_cached() const {
  size_t best = 0;
  for (size_t i = 1; i < cache_.size(); ++i)
    if (frame_id_difference(cache_[best].frame_id, cache_[i].frame_id) < 0) best = i;
  return best;
}

// Batches cached packets; true when a frame was released. `force` (end of input) releases the
// current frame whenever the next cached packet belongs to a later one.
bool OusterFrameAssembler::batch_with_caching(bool force, std::vector<OusterFrame>& released) {
  while (!cache_.empty()) {
    const size_t i = earliest_cached();
    const uint32_t f = cache_[i].frame_id;
    if (finished_ && frame_id_difference(finished_frame_id_, f) <= 0) {
      ++dropped_;
      cache_.erase(cache_.begin() + static_cast<std::ptrdiff_t>(i));
      continue;
    }
    if (!active_) start(f, cache_[i]);
    const int d = frame_id_difference(frame_.frame_id, f);
    if (d < 0) {
      ++dropped_;
      cache_.erase(cache_.begin() + static_cast<std::ptrdiff_t>(i));
    } else if (d > 0) {
      if (force || cache_.size() >= kMaxCachedPackets) {
        finalize(released);
        return true;
      }
      return false;
    } else {
      batch(cache_[i]);
      cache_.erase(cache_.begin() + static_cast<std::ptrdiff_t>(i));
      if (frame_complete()) {
        finalize(released);
        return true;
      }
    }
  }
  return false;
}

void OusterFrameAssembler::add(const OusterLidarPacket& packet,
                               std::vector<OusterFrame>& released) {
  const uint32_t f = packet.frame_id;
  if (m_.udp_profile_lidar != OusterLidarProfile::Legacy && packet.init_id != last_init_id_) {
    // The sensor restarted or was reconfigured: its frame counter restarted too.
    last_init_id_ = packet.init_id;
    if (!active_) {
      reset();
      start(f, packet);
      batch(packet);
      if (frame_complete()) finalize(released);
      return;
    }
    finalize(released);
    reset();
    cache_.push_back(packet);
    return;
  }
  if (cache_.empty()) {
    if (finished_ && frame_id_difference(finished_frame_id_, f) <= 0) {
      ++dropped_;
      return;
    }
    if (!active_) {
      start(f, packet);
      batch(packet);
      if (frame_complete()) finalize(released);
      return;
    }
  }
  if (active_ && frame_.frame_id == f) {
    batch(packet);
    if (frame_complete()) finalize(released);
    return;
  }
  cache_.push_back(packet);
  batch_with_caching(false, released);
}

void OusterFrameAssembler::finish(std::vector<OusterFrame>& released) {
  while (!cache_.empty()) batch_with_caching(true, released);
  if (active_) finalize(released);
}

OusterXyzLut make_ouster_xyz_lut(const OusterMetadata& m) {
  OusterXyzLut lut;
  lut.h = m.pixels_per_column;
  lut.w = m.columns_per_frame;
  const size_t n = static_cast<size_t>(lut.h) * lut.w;
  lut.direction.resize(n);
  lut.offset.resize(n);
  const double bx = m.beam_to_lidar_mm(0, 3), bz = m.beam_to_lidar_mm(2, 3);
  const double beam_norm = std::sqrt(bx * bx + bz * bz);
  const double two_pi = 2 * std::numbers::pi;
  const Eigen::Matrix3d& R_sensor_lidar = m.T_sensor_lidar.R;
  for (int u = 0; u < lut.h; ++u) {
    const double theta_a = -two_pi * m.beam_azimuth_deg[u] / 360.0;
    const double phi = two_pi * m.beam_altitude_deg[u] / 360.0;
    for (int v = 0; v < lut.w; ++v) {
      const double theta_e = two_pi * (1.0 - static_cast<double>(v) / lut.w);
      const Eigen::Vector3d d(std::cos(theta_e + theta_a) * std::cos(phi),
                              std::sin(theta_e + theta_a) * std::cos(phi), std::sin(phi));
      const Eigen::Vector3d o_lidar_mm =
          -beam_norm * d + Eigen::Vector3d(bx * std::cos(theta_e), bx * std::sin(theta_e), bz);
      const size_t i = static_cast<size_t>(u) * lut.w + v;
      lut.direction[i] = 0.001 * (R_sensor_lidar * d);
      lut.offset[i] = 0.001 * (R_sensor_lidar * o_lidar_mm) + m.T_sensor_lidar.t;
    }
  }
  return lut;
}

int ouster_destaggered_column(const OusterMetadata& m, int u, int v) {
  const int w = m.columns_per_frame;
  return ((v + m.pixel_shift_by_row[u]) % w + w) % w;
}

Scan ouster_scan(const OusterFrame& frame, const OusterMetadata& m, const OusterXyzLut& lut,
                 OusterScanStats* stats) {
  Scan scan;
  OusterScanStats local;
  const int h = frame.h, w = frame.w;
  int first_valid = -1;
  for (int v = 0; v < w; ++v) {
    if (frame.status[v] & 1u) {
      if (first_valid < 0) first_valid = v;
    } else {
      ++local.invalid_columns;
    }
  }
  if (first_valid < 0) {
    if (stats) *stats = local;
    return scan;
  }
  const uint64_t t0 = frame.timestamp[first_valid];
  scan.stamp = Time::from_ns(static_cast<int64_t>(t0));
  const bool has_signal = frame.pixels.has(OusterField::Signal);
  // Row by row, in destaggered column order.
  std::vector<int> staggered(w);
  scan.points.reserve(static_cast<size_t>(h) * w);
  for (int u = 0; u < h; ++u) {
    for (int v = 0; v < w; ++v) staggered[ouster_destaggered_column(m, u, v)] = v;
    for (int col = 0; col < w; ++col) {
      const int v = staggered[col];
      if ((frame.status[v] & 1u) == 0) continue;
      const size_t i = static_cast<size_t>(u) * w + v;
      const uint32_t r = frame.pixels.range[i];
      if (r == 0) {
        ++local.no_return;
        continue;
      }
      ScanPoint p;
      p.p = (lut.direction[i] * static_cast<double>(r) + lut.offset[i]).cast<float>();
      p.t_ns = static_cast<int64_t>(frame.timestamp[v] - t0);
      p.ring = static_cast<uint16_t>(u);
      p.column = static_cast<uint16_t>(col);
      p.reflectivity = frame.pixels.reflectivity.empty() ? 0 : frame.pixels.reflectivity[i];
      p.near_ir = frame.pixels.near_ir.empty() ? 0 : frame.pixels.near_ir[i];
      p.intensity = has_signal ? frame.pixels.signal[i] : p.reflectivity;
      p.range_mm = r;
      scan.points.push_back(p);
    }
  }
  if (stats) *stats = local;
  return scan;
}

}  // namespace rigcal::io
