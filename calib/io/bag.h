#pragma once
// ROS1 bags (doc/formats.md, "ROS1 bags") through Debian's librosbag-storage, without a ROS
// installation: one or more bag files (a recording split in chunks of about 10 GB) read as one
// stream of messages in time order, each as its serialized bytes (calib/io/ros_messages.h
// decodes them). Memory holds the bags' indexes and one decompressed chunk, never the messages
// of a whole bag.
//
// This header stays C++17 and free of ROS types: the ROS headers Debian ships do not compile as
// C++20 (std::allocator<void>::rebind), so bag.cpp is built as C++17 in its own library.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace rigcal::io {

// A topic of the bags: its message type, as many messages as the indexes count.
struct BagTopic {
  std::string topic;
  std::string datatype;  // "sensor_msgs/PointCloud2"
  std::string md5sum;
  std::string definition;  // the message definition the recorder stored
  uint64_t messages = 0;
};

struct BagMessage {
  const std::string& topic;
  const std::string& datatype;
  int64_t record_time_ns;  // when the recorder received it (the bag's clock)
  std::string_view bytes;  // valid during the callback only
  uint64_t index;          // 0-based position in the merged stream of the topics read
  const std::filesystem::path& bag;
};

class BagSet {
 public:
  // Opens every bag (their indexes only). Throws rigcal::Error naming the file when one is
  // missing, is not a ROS1 bag (version 2.0), is unindexed (recorded but never closed: run
  // `rosbag reindex`) or damaged. Nothing reaches stderr (rosbag's console output is silenced).
  explicit BagSet(const std::vector<std::filesystem::path>& bags);
  ~BagSet();
  BagSet(const BagSet&) = delete;
  BagSet& operator=(const BagSet&) = delete;

  // Every topic of every bag, sorted by name; a topic in several bags once, counts summed.
  const std::vector<BagTopic>& topics() const;
  // The record time of the first and last message (ns); 0, 0 for bags without messages.
  int64_t start_ns() const;
  int64_t end_ns() const;
  uint64_t size_bytes() const;  // the files' sizes together

  // Calls `on_message` for each message of `topics` (all when empty) in record-time order across
  // the bags. A message that cannot be read (a damaged chunk) throws rigcal::Error naming the
  // bag, the topic and the message index.
  void read(const std::vector<std::string>& topics,
            const std::function<void(const BagMessage&)>& on_message) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// True when the file starts with the ROS1 bag magic "#ROSBAG V2.0\n".
bool is_ros1_bag(const std::filesystem::path& path);

}  // namespace rigcal::io
