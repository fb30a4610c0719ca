#pragma once
// The LiDAR scans of ROS1 bags read as they stream (doc/odometry.md): the sensor_msgs/PointCloud2
// messages of one topic, each decoded into a Scan when the reader asks for it, nothing written.
// The bags are read in a thread of their own that stays at most a few scans ahead, so memory
// holds the bags' indexes, a decompressed chunk and those scans, whatever the bags' size.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/core/scan.h"

namespace rigcal::io {

// The bags `path` stands for: the file itself when it is a ROS1 bag, or the ROS1 bags directly
// in the folder (a recording split in chunks), in name order; none otherwise.
std::vector<std::filesystem::path> ros1_bags_at(const std::filesystem::path& path);

// The PointCloud2 topic of the bags to take scans from: the only one, or among several the only
// one whose name ends in "points" (the Ouster driver's /ouster/points); "" when the bags have no
// PointCloud2 topic. Throws rigcal::Error listing them when several remain.
std::string scan_topic(const std::vector<std::filesystem::path>& bags);

class BagScanStream {
 public:
  // Opens the bags (their indexes) and starts reading `topic`. Throws rigcal::Error naming the
  // file when a bag does not open.
  BagScanStream(const std::vector<std::filesystem::path>& bags, const std::string& topic);
  ~BagScanStream();  // stops the reading thread; what it had not read is left
  BagScanStream(const BagScanStream&) = delete;
  BagScanStream& operator=(const BagScanStream&) = delete;

  // The next scan in the bags' order, stamped with its message's header stamp (the Ouster
  // driver's: the sweep's first column, the time its per-point `t` counts from; what `rigcal
  // convert` stores by default); none after the last. Throws rigcal::Error naming the bag, the
  // message and what is wrong with it (a damaged chunk, a big-endian cloud, fields without x, y
  // or z).
  std::optional<Scan> next();
  uint64_t total() const;      // the topic's messages, as the indexes count them
  std::string source() const;  // "BAG: message N (topic T)" of the last scan, or the first bag

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rigcal::io
