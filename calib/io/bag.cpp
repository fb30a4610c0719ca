// Built as C++17 (see bag.h): the only file of rigcal that includes ROS headers.
#include "rigcal/io/bag.h"

#include <console_bridge/console.h>
#include <rosbag/bag.h>
#include <rosbag/exceptions.h>
#include <rosbag/query.h>
#include <rosbag/view.h>

#include <algorithm>
#include <fstream>
#include <map>

#include "rigcal/core/error.h"

namespace rigcal::io {
namespace fs = std::filesystem;

namespace {

int64_t to_ns(const ros::Time& t) { return int64_t{t.sec} * 1000000000 + t.nsec; }

std::string bag_error(const fs::path& bag, const std::string& what) {
  return bag.string() + ": " + what;
}

}  // namespace

struct BagSet::Impl {
  std::vector<fs::path> paths;
  std::vector<std::unique_ptr<rosbag::Bag>> bags;
  std::vector<std::pair<int64_t, int64_t>> spans;  // each bag's first and last record time
  std::vector<BagTopic> topics;
  int64_t start_ns = 0, end_ns = 0;

  // The bag a message of record time t comes from, for messages (split bags do not overlap).
  const fs::path& path_at(int64_t t) const {
    for (size_t i = 0; i < spans.size(); ++i)
      if (spans[i].first <= t && t <= spans[i].second) return paths[i];
    return paths.front();
  }
  uint64_t size_bytes = 0;
};

bool is_ros1_bag(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[13] = {};
  in.read(magic, sizeof magic);
  return in.gcount() == sizeof magic && std::string(magic, sizeof magic) == "#ROSBAG V2.0\n";
}

BagSet::BagSet(const std::vector<fs::path>& paths) : impl_(std::make_unique<Impl>()) {
  // rosbag reports through console_bridge on stderr besides throwing: keep stderr rigcal's.
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
  if (paths.empty()) throw Error("no bag given");
  std::map<std::string, BagTopic> topics;
  bool any = false;
  for (const fs::path& path : paths) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) {
      throw Error(bag_error(path, fs::exists(path, ec) ? "not a regular file" : "no such file"));
    }
    if (!is_ros1_bag(path)) {
      throw Error(bag_error(path, "not a ROS1 bag (no '#ROSBAG V2.0' at its start)"));
    }
    impl_->size_bytes += fs::file_size(path, ec);
    auto bag = std::make_unique<rosbag::Bag>();
    std::pair<int64_t, int64_t> span{0, -1};
    try {
      bag->open(path.string(), rosbag::bagmode::Read);
      rosbag::View all(*bag);
      for (const rosbag::ConnectionInfo* c : all.getConnections()) {
        BagTopic& t = topics[c->topic];
        if (!t.datatype.empty() && t.datatype != c->datatype) {
          throw Error(bag_error(path, "topic " + c->topic + " is " + c->datatype + " here and " +
                                          t.datatype + " elsewhere"));
        }
        t.topic = c->topic, t.datatype = c->datatype, t.md5sum = c->md5sum;
        t.definition = c->msg_def;
      }
      for (auto& [name, t] : topics) {
        rosbag::View one(*bag, rosbag::TopicQuery(name));
        t.messages += one.size();
      }
      if (all.size() > 0) {
        const int64_t begin = to_ns(all.getBeginTime()), end = to_ns(all.getEndTime());
        span = {begin, end};
        impl_->start_ns = any ? std::min(impl_->start_ns, begin) : begin;
        impl_->end_ns = any ? std::max(impl_->end_ns, end) : end;
        any = true;
      }
    } catch (const rosbag::BagUnindexedException&) {
      throw Error(bag_error(path,
                            "the bag is unindexed (recording not closed?); run `rosbag "
                            "reindex` on a copy, then read the copy"));
    } catch (const rosbag::BagException& e) {
      throw Error(bag_error(path, std::string("cannot read the bag (") + e.what() + ")"));
    } catch (const std::bad_alloc&) {
      throw Error(bag_error(path, "cannot read the bag (an index claims more than memory)"));
    }
    impl_->paths.push_back(path);
    impl_->spans.push_back(span);
    impl_->bags.push_back(std::move(bag));
  }
  for (auto& [name, t] : topics) impl_->topics.push_back(std::move(t));
}

BagSet::~BagSet() = default;

const std::vector<BagTopic>& BagSet::topics() const { return impl_->topics; }
int64_t BagSet::start_ns() const { return impl_->start_ns; }
int64_t BagSet::end_ns() const { return impl_->end_ns; }
uint64_t BagSet::size_bytes() const { return impl_->size_bytes; }

void BagSet::read(const std::vector<std::string>& topics,
                  const std::function<void(const BagMessage&)>& on_message) const {
  rosbag::View view;
  for (const auto& bag : impl_->bags) {
    if (topics.empty()) {
      view.addQuery(*bag);
    } else {
      view.addQuery(*bag, rosbag::TopicQuery(topics));
    }
  }
  std::vector<uint8_t> buffer;
  uint64_t index = 0;
  std::string topic = "?";
  const fs::path* path = &impl_->paths.front();
  try {
    for (const rosbag::MessageInstance& m : view) {
      topic = m.getTopic();
      const int64_t t = to_ns(m.getTime());
      path = &impl_->path_at(t);
      const uint32_t size = m.size();
      buffer.resize(size);
      ros::serialization::OStream stream(buffer.data(), size);
      m.write(stream);
      on_message(BagMessage{m.getTopic(), m.getDataType(), t,
                            std::string_view(reinterpret_cast<const char*>(buffer.data()), size),
                            index, *path});
      ++index;
    }
  } catch (const ros::Exception& e) {  // rosbag::BagException and the serializer's
    throw Error(bag_error(*path, "message " + std::to_string(index) + " (topic " + topic +
                                     ") cannot be read (" + e.what() + ")"));
  } catch (const std::bad_alloc&) {
    throw Error(bag_error(*path, "message " + std::to_string(index) + " (topic " + topic +
                                     ") claims more than memory"));
  }
}

}  // namespace rigcal::io
