#include "rigcal/io/bag_scans.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>
#include <utility>

#include "rigcal/core/error.h"
#include "rigcal/io/bag.h"
#include "rigcal/io/point_cloud_io.h"
#include "rigcal/io/ros_messages.h"

namespace rigcal::io {

namespace fs = std::filesystem;

namespace {

constexpr size_t kScansAhead = 3;  // scans decoded ahead of the reader

// Thrown inside the reading thread's callback to end BagSet::read when the reader is gone.
struct Stopped {};

std::string message_name(const BagMessage& m) {
  return fmt::format("{}: message {} (topic {})", m.bag.string(), m.index, m.topic);
}

// The cloud's records, rows without their padding, as a scan.
Scan scan_of(const RosPointCloud2& cloud, const std::string& what) {
  if (cloud.is_bigendian) throw Error(what + ": a big-endian PointCloud2 (not read)");
  std::vector<PointField> fields;
  for (const RosPointField& f : cloud.fields)
    fields.push_back({f.name, f.offset, f.datatype, f.count});
  const size_t row = size_t{cloud.width} * cloud.point_step;
  std::string_view records = cloud.data.substr(0, row * cloud.height);
  std::string unpadded;
  if (cloud.height > 1 && cloud.row_step != row) {
    unpadded.reserve(row * cloud.height);
    for (uint32_t r = 0; r < cloud.height; ++r)
      unpadded.append(cloud.data.substr(size_t{r} * cloud.row_step, row));
    records = unpadded;
  }
  return scan_from_records(records, cloud.point_step, fields, what);
}

}  // namespace

std::vector<fs::path> ros1_bags_at(const fs::path& path) {
  std::error_code ec;
  std::vector<fs::path> bags;
  if (fs::is_regular_file(path, ec)) {
    if (is_ros1_bag(path)) bags.push_back(path);
    return bags;
  }
  if (!fs::is_directory(path, ec)) return bags;
  for (const fs::directory_entry& e : fs::directory_iterator(path, ec)) {
    if (e.is_regular_file() && e.path().extension() == ".bag" && is_ros1_bag(e.path()))
      bags.push_back(e.path());
  }
  std::sort(bags.begin(), bags.end());
  return bags;
}

std::string scan_topic(const std::vector<fs::path>& bags) {
  const BagSet set(bags);
  std::vector<std::string> clouds, points;
  for (const BagTopic& t : set.topics()) {
    if (t.datatype != "sensor_msgs/PointCloud2") continue;
    clouds.push_back(t.topic);
    if (t.topic.size() >= 6 && t.topic.compare(t.topic.size() - 6, 6, "points") == 0)
      points.push_back(t.topic);
  }
  if (clouds.size() == 1) return clouds.front();
  if (points.size() == 1) return points.front();
  if (clouds.empty()) return "";
  throw Error(
      fmt::format("{}: {} PointCloud2 topics ({}) and not one alone ending in 'points'; "
                  "convert the one to use (rigcal convert --topic)",
                  bags.front().string(), clouds.size(), fmt::join(clouds, ", ")));
}

struct BagScanStream::Impl {
  std::unique_ptr<BagSet> bags;
  std::string topic, first_bag;
  uint64_t total = 0;
  std::mutex mutex;
  std::condition_variable changed;
  std::deque<std::pair<Scan, std::string>> ready;  // decoded scans and their messages' names
  std::string last;
  bool done = false, stop = false;
  std::exception_ptr error;
  std::thread reader;
};

BagScanStream::BagScanStream(const std::vector<fs::path>& bags, const std::string& topic)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.bags = std::make_unique<BagSet>(bags);
  s.topic = topic;
  s.first_bag = bags.front().string();
  for (const BagTopic& t : s.bags->topics())
    if (t.topic == topic) s.total = t.messages;
  s.reader = std::thread([&s] {
    try {
      s.bags->read({s.topic}, [&s](const BagMessage& m) {
        const std::string name = message_name(m);
        Scan scan;
        try {
          const RosPointCloud2 cloud = decode_point_cloud2(m.bytes);
          scan = scan_of(cloud, name);
          scan.stamp = cloud.header.stamp;
        } catch (const Error& e) {
          const std::string what = e.what();
          throw Error(what.rfind(name, 0) == 0 ? what : name + ": " + what);
        }
        std::unique_lock lock(s.mutex);
        s.changed.wait(lock, [&s] { return s.stop || s.ready.size() < kScansAhead; });
        if (s.stop) throw Stopped{};
        s.ready.emplace_back(std::move(scan), name);
        s.changed.notify_all();
      });
    } catch (const Stopped&) {
    } catch (...) {
      const std::lock_guard lock(s.mutex);
      s.error = std::current_exception();
    }
    const std::lock_guard lock(s.mutex);
    s.done = true;
    s.changed.notify_all();
  });
}

BagScanStream::~BagScanStream() {
  {
    const std::lock_guard lock(impl_->mutex);
    impl_->stop = true;
  }
  impl_->changed.notify_all();
  impl_->reader.join();
}

std::optional<Scan> BagScanStream::next() {
  Impl& s = *impl_;
  std::unique_lock lock(s.mutex);
  s.changed.wait(lock, [&s] { return !s.ready.empty() || s.done; });
  if (s.ready.empty()) {
    if (s.error) std::rethrow_exception(std::exchange(s.error, nullptr));
    return std::nullopt;
  }
  Scan scan = std::move(s.ready.front().first);
  s.last = std::move(s.ready.front().second);
  s.ready.pop_front();
  s.changed.notify_all();
  return scan;
}

uint64_t BagScanStream::total() const { return impl_->total; }

std::string BagScanStream::source() const {
  const std::lock_guard lock(impl_->mutex);
  return impl_->last.empty() ? impl_->first_bag : impl_->last;
}

}  // namespace rigcal::io
