#include "rigcal/io/convert.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <exception>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <thread>

#include "rigcal/core/error.h"
#include "rigcal/core/time.h"
#include "rigcal/io/bag.h"
#include "rigcal/io/files.h"
#include "rigcal/io/image_io.h"
#include "rigcal/io/ouster_frames.h"
#include "rigcal/io/ouster_metadata.h"
#include "rigcal/io/ouster_packet.h"
#include "rigcal/io/ouster_pcap.h"
#include "rigcal/io/point_cloud_io.h"
#include "rigcal/io/ros_messages.h"

namespace rigcal::io {
namespace fs = std::filesystem;
namespace {

// vbr-devkit's IMU CSV header, as its converter writes it (names repeated as it repeats them).
constexpr const char* kImuCsvHeader =
    "acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z,quat_w,quat_x,quat_y,quat_z,"
    "cov_acc_xx,cov_acc_xy,cov_acc_xz,cov_acc_yx,cov_acc_yy,cov_acc_zz,"
    "cov_acc_zx,cov_acc_zy,cov_acc_zz,cov_gyr_xx,cov_gyr_xy,cov_gyr_xz,"
    "cov_gyr_xx,cov_gyr_xy,cov_gyr_xz,cov_gyr_yx,cov_gyr_yy,cov_gyr_zz,"
    "cov_rot_zx,cov_rot_zy,cov_rot_zz,cov_rot_yx,cov_rot_yy,cov_rot_zz,"
    "cov_rot_zx,cov_rot_zy,cov_rot_zz\n";

// One output stream of a topic; every write is checked (a full disk is an error, not a cut file).
class Out {
 public:
  explicit Out(const fs::path& path) : path_(path), out_(path, std::ios::binary | std::ios::trunc) {
    if (!out_) throw Error(fmt::format("{}: cannot be written", path.string()));
  }
  void write(std::string_view bytes) {
    out_.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out_) throw Error(fmt::format("{}: write failed (disk full?)", path_.string()));
  }
  void close() {
    out_.close();
    if (!out_) throw Error(fmt::format("{}: write failed (disk full?)", path_.string()));
  }

 private:
  fs::path path_;
  std::ofstream out_;
};

void write_whole(const fs::path& path, std::string_view bytes) {
  Out out(path);
  out.write(bytes);
  out.close();
}

// PNG encoding and writing on worker threads, one image a job (an image takes ~20 ms to
// encode, the rest of a bag's messages far less): the reading thread hands an image over and
// goes on, waiting only when `kQueued` images are already waiting. The first failure is kept
// with the message it came from and thrown by finish(); the destructor stops the workers.
class ImageWriter {
 public:
  // A failure of the writer, already naming its message.
  struct Failure : Error {
    using Error::Error;
  };
  ImageWriter() {
    const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    for (unsigned i = 0; i < std::min(cores, 4u); ++i) workers_.emplace_back([this] { work(); });
  }
  ~ImageWriter() {  // on an error elsewhere: the images waiting are dropped
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      jobs_.clear();
    }
    stop();
  }
  ImageWriter(const ImageWriter&) = delete;
  ImageWriter& operator=(const ImageWriter&) = delete;

  // `where` names the message for an error ("bag: message 12 (topic ...)").
  void submit(fs::path path, cv::Mat image, std::string where) {
    std::unique_lock<std::mutex> lock(mutex_);
    room_.wait(lock, [&] { return jobs_.size() < kQueued || failure_; });
    if (failure_) rethrow(lock);
    jobs_.push_back({std::move(path), std::move(image), std::move(where)});
    ready_.notify_one();
  }
  // Waits for every image; throws the first failure.
  void finish() {
    stop();
    std::unique_lock<std::mutex> lock(mutex_);
    if (failure_) rethrow(lock);
  }

 private:
  static constexpr size_t kQueued = 8;
  struct Job {
    fs::path path;
    cv::Mat image;
    std::string where;
  };
  void work() {
    for (;;) {
      Job job;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        ready_.wait(lock, [&] { return !jobs_.empty() || closed_; });
        if (jobs_.empty() || failure_) return;
        job = std::move(jobs_.front());
        jobs_.pop_front();
        room_.notify_one();
      }
      try {
        std::vector<uchar> png;
        if (!cv::imencode(".png", job.image, png))
          throw Error("the image could not be encoded as PNG");
        write_whole(job.path,
                    std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
      } catch (const std::exception& e) {
        const std::lock_guard<std::mutex> lock(mutex_);
        if (!failure_)
          failure_ = std::make_exception_ptr(Failure(fmt::format("{}: {}", job.where, e.what())));
        room_.notify_all();
        ready_.notify_all();
      }
    }
  }
  void stop() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    ready_.notify_all();
    for (std::thread& w : workers_) {
      if (w.joinable()) w.join();
    }
  }
  [[noreturn]] void rethrow(std::unique_lock<std::mutex>& lock) {
    const std::exception_ptr e = failure_;
    lock.unlock();
    std::rethrow_exception(e);
  }
  std::mutex mutex_;
  std::condition_variable ready_, room_;
  std::deque<Job> jobs_;
  bool closed_ = false;
  std::exception_ptr failure_;
  std::vector<std::thread> workers_;
};

// Raw packets of one Ouster sensor (a bag's lidar_packets topic): decoded and batched into
// frames as a capture is.
struct OusterStream {
  OusterMetadata metadata;
  OusterXyzLut lut;
  std::unique_ptr<OusterFrameAssembler> assembler;
  OusterLidarPacket packet;
  std::vector<OusterFrame> released;
  bool imu = false;  // the imu_packets topic
  uint64_t skipped = 0;
  std::string first_skip;
};

struct Topic {
  ConvertedTopic info;
  RosType type = RosType::other;
  std::unique_ptr<OusterStream> ouster;
  fs::path dir;
  std::vector<Time> stamps;
  std::unique_ptr<Out> table;  // imu.txt, navsat.csv or poses.tum
  nlohmann::json metadata;     // .metadata.json (clouds and images)
  std::string fields_key;      // a cloud's fields as first seen
};

std::string frame_name(size_t n) { return fmt::format("{:010d}", n); }

std::string fields_key(const RosPointCloud2& m) {
  std::string key = std::to_string(m.point_step);
  for (const RosPointField& f : m.fields)
    key += fmt::format(";{},{},{},{}", f.name, f.offset, f.datatype, f.count);
  return key;
}

void write_cloud(Topic& t, const RosPointCloud2& m) {
  if (m.is_bigendian) throw Error("a big-endian PointCloud2 (not stored)");
  const std::string key = fields_key(m);
  if (t.fields_key.empty()) {
    t.fields_key = key;
    nlohmann::json fields = nlohmann::json::array();
    for (const RosPointField& f : m.fields) {
      fields.push_back(
          {{"name", f.name}, {"offset", f.offset}, {"datatype", f.datatype}, {"count", f.count}});
    }
    t.metadata["msg_type"] = "PointCloudXf";
    t.metadata["fields"] = fields;
    t.metadata["point_step"] = m.point_step;
  } else if (key != t.fields_key) {
    throw Error("the fields or point_step differ from the topic's first message");
  }
  Out out(t.dir / "data" / (frame_name(t.stamps.size()) + ".bin"));
  const size_t row = size_t{m.width} * m.point_step;
  for (uint32_t r = 0; r < m.height; ++r) out.write(m.data.substr(size_t{r} * m.row_step, row));
  out.close();
}

// An Ouster scan as the Ouster ROS driver's points: 48-byte records of x y z (float32),
// intensity (float32, at 16), t (uint32 ns since the frame's stamp, at 20), reflectivity, ring,
// ambient (uint16, at 24, 26, 28; ambient is NEAR_IR) and range (uint32 mm, at 32).
void write_scan(Topic& t, const Scan& scan) {
  constexpr size_t kStep = 48;
  if (!t.metadata.contains("fields")) {
    nlohmann::json fields = nlohmann::json::array();
    for (const auto& [name, offset, type] :
         std::vector<std::tuple<const char*, int, int>>{{"x", 0, 7},
                                                        {"y", 4, 7},
                                                        {"z", 8, 7},
                                                        {"intensity", 16, 7},
                                                        {"t", 20, 6},
                                                        {"reflectivity", 24, 4},
                                                        {"ring", 26, 4},
                                                        {"ambient", 28, 4},
                                                        {"range", 32, 6}}) {
      fields.push_back({{"name", name}, {"offset", offset}, {"datatype", type}, {"count", 1}});
    }
    t.metadata["msg_type"] = "PointCloudXf";
    t.metadata["fields"] = fields;
    t.metadata["point_step"] = kStep;
  }
  std::string records(scan.points.size() * kStep, '\0');
  for (size_t i = 0; i < scan.points.size(); ++i) {
    const ScanPoint& q = scan.points[i];
    char* r = records.data() + i * kStep;
    const uint32_t t_ns = static_cast<uint32_t>(std::clamp<int64_t>(q.t_ns, 0, UINT32_MAX));
    std::memcpy(r + 0, q.p.data(), 12);
    std::memcpy(r + 16, &q.intensity, 4);
    std::memcpy(r + 20, &t_ns, 4);
    std::memcpy(r + 24, &q.reflectivity, 2);
    std::memcpy(r + 26, &q.ring, 2);
    std::memcpy(r + 28, &q.near_ir, 2);
    std::memcpy(r + 32, &q.range_mm, 4);
  }
  write_whole(t.dir / "data" / (frame_name(t.stamps.size()) + ".bin"), records);
}

void write_image(Topic& t, const RosImage& m, ImageWriter& images, std::string where) {
  const std::optional<ImageLayout> layout = image_layout(m.encoding);
  if (!layout) throw Error(fmt::format("image encoding '{}' is not stored", m.encoding));
  if (m.width < kMinImageSide || m.height < kMinImageSide ||
      !within_image_limits(m.width, m.height)) {
    throw Error(fmt::format("a {} x {} image, outside {} to {} px a side", m.width, m.height,
                            kMinImageSide, kMaxImageSide));
  }
  if (!t.metadata.contains("encoding")) {
    t.metadata["msg_type"] = "Image";
    t.metadata["encoding"] = m.encoding;
  } else if (t.metadata["encoding"] != m.encoding) {
    throw Error(fmt::format("encoding '{}' differs from the topic's first message's ({})",
                            m.encoding, t.metadata["encoding"].get<std::string>()));
  }
  const int depth = layout->bytes_per_channel == 1 ? CV_8U : CV_16U;
  cv::Mat image(static_cast<int>(m.height), static_cast<int>(m.width),
                CV_MAKETYPE(depth, layout->channels));
  const size_t row = image.cols * image.elemSize();
  for (int r = 0; r < image.rows; ++r)
    std::memcpy(image.ptr(r), m.data.data() + size_t(r) * m.step, row);
  if (depth == CV_16U && m.is_bigendian) {
    for (int r = 0; r < image.rows; ++r) {
      auto* p = image.ptr<uint16_t>(r);
      for (int c = 0; c < image.cols * layout->channels; ++c)
        p[c] = static_cast<uint16_t>((p[c] >> 8) | (p[c] << 8));
    }
  }
  if (m.encoding.starts_with("rgba"))
    cv::cvtColor(image, image, cv::COLOR_RGBA2BGRA);
  else if (m.encoding.starts_with("rgb"))
    cv::cvtColor(image, image, cv::COLOR_RGB2BGR);
  images.submit(t.dir / "data" / (frame_name(t.stamps.size()) + ".png"), std::move(image),
                std::move(where));
}

template <size_t N>
void append(std::string& line, const std::array<double, N>& values) {
  for (double v : values) fmt::format_to(std::back_inserter(line), ",{}", v);
}

void write_imu(Topic& t, const RosImu& m) {
  if (!t.table) {
    t.table = std::make_unique<Out>(t.dir / "data" / "imu.txt");
    t.table->write(kImuCsvHeader);
    t.metadata["msg_type"] = "Imu";
  }
  std::string line;
  const auto& a = m.linear_acceleration;
  const auto& q = m.orientation_xyzw;
  fmt::format_to(std::back_inserter(line), "{},{},{}", a[0], a[1], a[2]);
  append(line, m.angular_velocity);
  append(line, std::array<double, 4>{q[3], q[0], q[1], q[2]});
  append(line, m.linear_acceleration_covariance);
  append(line, m.angular_velocity_covariance);
  append(line, m.orientation_covariance);
  line += '\n';
  t.table->write(line);
}

void write_fix(Topic& t, Time stamp, const RosNavSatFix& m) {
  if (!t.table) {
    t.table = std::make_unique<Out>(t.dir / "navsat.csv");
    t.table->write(
        "time,latitude,longitude,height,status,service,covariance_type,std_east,std_north,"
        "std_up,cov_en,cov_eu,cov_nu\n");
  }
  // The covariance is row-major ENU (m^2): its diagonal as standard deviations, then the terms
  // off it, which a receiver that knows its whole covariance (type 3) gives.
  const auto& c = m.position_covariance;
  t.table->write(fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{}\n", to_seconds_text(stamp),
                             m.latitude_deg, m.longitude_deg, m.altitude_m, int{m.status},
                             m.service, int{m.position_covariance_type}, std::sqrt(c[0]),
                             std::sqrt(c[4]), std::sqrt(c[8]), c[1], c[2], c[5]));
}

void write_pose(Topic& t, Time stamp, const RosPose& m) {
  if (!t.table) {
    t.table = std::make_unique<Out>(t.dir / "poses.tum");
    t.table->write(fmt::format("# {} ({}): T_{}_{} as timestamp tx ty tz qx qy qz qw\n",
                               t.info.topic, t.info.datatype, m.header.frame_id,
                               m.child_frame_id.empty() ? "body" : m.child_frame_id));
  }
  t.table->write(fmt::format("{} {}\n", to_seconds_text(stamp), to_text(m.T_frame_child)));
}

// False (and counted) when `stamp` is not after the topic's previous one.
bool in_order(Topic& t, Time stamp, uint64_t index) {
  if (t.stamps.empty() || stamp > t.stamps.back()) return true;
  if (t.info.out_of_order++ == 0) {
    t.info.first_out_of_order =
        fmt::format("message {} (stamp {} after {})", index, to_seconds_text(stamp),
                    to_seconds_text(t.stamps.back()));
  }
  return false;
}

void store_scan(Topic& t, const Scan& scan, Time stamp, uint64_t index) {
  if (scan.points.empty() || !in_order(t, stamp, index)) return;
  write_scan(t, scan);
  t.stamps.push_back(stamp);
  ++t.info.messages;
}

void store_ouster_imu(Topic& t, const OusterImuSample& s, Time stamp, uint64_t index) {
  if (!in_order(t, stamp, index)) return;
  RosImu m;  // no orientation: its covariance's first entry -1, as ROS says
  m.orientation_xyzw = {0, 0, 0, 1};
  m.orientation_covariance[0] = -1;
  for (int i = 0; i < 3; ++i) {
    m.angular_velocity[i] = s.gyro_radps[i];
    m.linear_acceleration[i] = s.accel_mps2[i];
  }
  write_imu(t, m);
  t.stamps.push_back(stamp);
  ++t.info.messages;
}

// The frames the stream released, as scans stamped on the sensor clock or at `record`.
void store_frames(Topic& t, StampSource source, Time record, uint64_t index) {
  OusterStream& o = *t.ouster;
  for (const OusterFrame& frame : o.released) {
    const Scan scan = ouster_scan(frame, o.metadata, o.lut);
    store_scan(t, scan, source == StampSource::header ? scan.stamp : record, index);
  }
  o.released.clear();
}

void skip_packet(OusterStream& o, uint64_t index, std::string_view why) {
  if (o.skipped++ == 0) o.first_skip = fmt::format("message {}: {}", index, why);
}

void store_ouster(Topic& t, const BagMessage& msg, StampSource source) {
  OusterStream& o = *t.ouster;
  const std::string_view payload = decode_packet_msg(msg.bytes);
  const auto* data = reinterpret_cast<const uint8_t*>(payload.data());
  const Time record{msg.record_time_ns};
  if (o.imu) {
    const std::optional<OusterImuSample> s = decode_ouster_imu_packet({data, payload.size()});
    if (!s) return skip_packet(o, msg.index, "not a 48-byte IMU packet");
    return store_ouster_imu(t, *s, source == StampSource::header ? s->stamp : record, msg.index);
  }
  const OusterPacketResult r = decode_ouster_lidar_packet(
      {data, payload.size()}, o.metadata, ouster_packets_have_crc(o.metadata), o.packet);
  if (r != OusterPacketResult::Ok) {
    return skip_packet(o, msg.index,
                       r == OusterPacketResult::WrongSize ? "not the size of the metadata's profile"
                       : r == OusterPacketResult::BadCrc  ? "bad CRC"
                                                          : "not a lidar packet");
  }
  o.assembler->add(o.packet, o.released);
  store_frames(t, source, record, msg.index);
}

// "BAG: message N (topic T)": a message named in an error.
std::string message_name(const BagMessage& msg) {
  return fmt::format("{}: message {} (topic {})", msg.bag.string(), msg.index, msg.topic);
}

// Decodes the message, checks its stamp's order and stores it.
void store(Topic& t, const BagMessage& msg, StampSource source, ImageWriter& images) {
  if (t.ouster) return store_ouster(t, msg, source);
  const Time record{msg.record_time_ns};
  std::optional<RosPointCloud2> cloud;
  std::optional<RosImage> image;
  std::optional<RosImu> imu;
  std::optional<RosNavSatFix> fix;
  std::optional<RosPose> pose;
  Time header;
  switch (t.type) {
    case RosType::point_cloud2:
      header = (cloud = decode_point_cloud2(msg.bytes))->header.stamp;
      break;
    case RosType::image:
      header = (image = decode_image(msg.bytes))->header.stamp;
      break;
    case RosType::imu:
      header = (imu = decode_imu(msg.bytes))->header.stamp;
      break;
    case RosType::nav_sat_fix:
      header = (fix = decode_nav_sat_fix(msg.bytes))->header.stamp;
      break;
    case RosType::pose:
      header = (pose = decode_pose(msg.bytes, msg.datatype))->header.stamp;
      break;
    case RosType::ouster_packets:
    case RosType::other:
      return;
  }
  const Time stamp = source == StampSource::header ? header : record;
  if (!in_order(t, stamp, msg.index)) return;
  if (cloud) write_cloud(t, *cloud);
  if (image) write_image(t, *image, images, message_name(msg));
  if (imu) write_imu(t, *imu);
  if (fix) write_fix(t, stamp, *fix);
  if (pose) write_pose(t, stamp, *pose);
  t.stamps.push_back(stamp);
  ++t.info.messages;
}

void finish(Topic& t) {
  if (t.table) t.table->close();
  if (t.type == RosType::nav_sat_fix || t.type == RosType::pose) return;
  std::string text;
  for (Time s : t.stamps) text += to_iso8601(s) + '\n';
  write_whole(t.dir / "timestamps.txt", text);
  t.metadata["topic"] = t.info.topic;
  t.metadata["num_messages"] = t.info.messages;
  write_whole(t.dir / ".metadata.json",
              t.metadata.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

bool empty_or_missing(const fs::path& dir) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) return true;
  return fs::is_directory(dir, ec) && fs::is_empty(dir, ec);
}

// Writes the recording below a temporary folder beside o.out, renamed into place when complete
// (removed on failure): every topic's folder, `feed` storing the data, each topic finished, and
// convert.json.
void write_recording(const ConvertOptions& o, std::map<std::string, Topic>& topics,
                     ConvertResult& result, const std::function<void()>& feed) {
  const fs::path out = fs::absolute(o.out).lexically_normal();
  const fs::path partial =
      out.parent_path() / fmt::format("{}.partial-{}", out.filename().string(), ::getpid());
  std::error_code ec;
  fs::remove_all(partial, ec);
  if (fs::create_directories(partial, ec); ec) {
    throw Error(fmt::format("{}: cannot be created ({})", partial.string(), ec.message()));
  }
  try {
    for (auto& [name, t] : topics) {
      t.dir = partial / t.info.folder;
      // Fixes and poses are one table at the topic's root; the rest keep data/.
      const bool table = t.type == RosType::nav_sat_fix || t.type == RosType::pose;
      fs::create_directories(table ? t.dir : t.dir / "data");
    }
    feed();
    for (auto& [name, t] : topics) {
      if (t.ouster && t.ouster->skipped) {
        t.info.note =
            fmt::format("{} packets skipped (first: {})", t.ouster->skipped, t.ouster->first_skip);
      }
      finish(t);
      result.converted.push_back(t.info);
    }
    nlohmann::json provenance;
    provenance["rigcal_convert"] = {
        {"stamps", o.stamps == StampSource::header ? "header" : "record"}};
    for (const fs::path& b : o.bags) provenance["inputs"].push_back(b.filename().string());
    for (const ConvertedTopic& c : result.converted) {
      provenance["topics"].push_back({{"topic", c.topic},
                                      {"datatype", c.datatype},
                                      {"folder", c.folder},
                                      {"messages", c.messages},
                                      {"out_of_order", c.out_of_order},
                                      {"note", c.note}});
    }
    for (const auto& [topic, type] : result.skipped)
      provenance["skipped"].push_back({{"topic", topic}, {"datatype", type}});
    write_whole(partial / "convert.json",
                provenance.dump(1, ' ', false, nlohmann::json::error_handler_t::replace));
    if (fs::exists(out, ec)) fs::remove(out);  // an empty folder
    fs::rename(partial, out);
  } catch (const fs::filesystem_error& e) {
    fs::remove_all(partial, ec);
    throw Error(fmt::format("{}: {}", e.path1().string(), e.code().message()));
  } catch (...) {
    fs::remove_all(partial, ec);
    throw;
  }
}

// An Ouster capture (pcap) with its metadata JSON: ouster_points/ and ouster_imu/.
ConvertResult convert_capture(const ConvertOptions& o) {
  if (o.ouster_metadata.empty()) {
    throw Error(fmt::format("{}: an Ouster capture needs the sensor's metadata JSON (--metadata)",
                            o.bags.front().string()));
  }
  if (o.stamps == StampSource::record) {
    throw Error("--stamps record: a capture has no record times; its stamps are the sensor's");
  }
  if (!o.topics.empty() || !o.folders.empty()) throw Error("--topics and --topic are for bags");
  OusterPcapReader reader(o.bags.front(), read_ouster_metadata(o.ouster_metadata));
  ConvertResult result;
  result.capture = true;
  std::error_code ec;
  result.bytes_read = fs::file_size(o.bags.front(), ec);
  std::map<std::string, Topic> topics;
  for (const char* folder : {"ouster_points", "ouster_imu"}) {
    Topic& t = topics[folder];
    t.info.topic = o.bags.front().filename().string();
    t.info.datatype =
        std::string_view(folder) == "ouster_points" ? "Ouster lidar packets" : "Ouster IMU packets";
    t.info.folder = folder;
  }
  Topic& lidar = topics["ouster_points"];
  Topic& imu = topics["ouster_imu"];
  write_recording(o, topics, result, [&] {
    uint64_t imu_index = 0, frame_index = 0;
    reader.on_imu = [&](const OusterImuSample& s) {
      store_ouster_imu(imu, s, s.stamp, imu_index++);
    };
    while (const std::optional<Scan> scan = reader.next_scan()) {
      store_scan(lidar, *scan, scan->stamp, frame_index++);
      if (o.progress) o.progress("frames", frame_index, 0);
    }
    const OusterCaptureCounters& c = reader.counters();
    lidar.info.note =
        fmt::format("{} frames complete, {} incomplete; {} packets skipped{}{}", c.frames_complete,
                    c.frames_incomplete, c.skipped_total(), c.note.empty() ? "" : "; ", c.note);
    for (const Topic* t : {&lidar, &imu}) {
      if (t->stamps.empty()) continue;
      const int64_t a = t->stamps.front().ns, b = t->stamps.back().ns;
      result.start_ns = result.start_ns ? std::min(result.start_ns, a) : a;
      result.end_ns = std::max(result.end_ns, b);
    }
  });
  return result;
}

}  // namespace

StampSource stamp_source_from_string(std::string_view name) {
  if (name == "header") return StampSource::header;
  if (name == "record") return StampSource::record;
  throw Error(fmt::format("stamps: expected header or record, got '{}'", name));
}

std::string default_topic_folder(std::string_view topic) {
  std::string s(topic.starts_with('/') ? topic.substr(1) : topic);
  for (const std::string_view drop : {"/image_raw", "/data"}) {
    for (size_t at; (at = s.find(drop)) != std::string::npos;) s.erase(at, drop.size());
  }
  for (char& c : s)
    if (c == '/') c = '_';
  return s;
}

ConvertResult convert_recording(const ConvertOptions& o) {
  if (o.out.empty()) throw Error("no output folder given");
  if (!empty_or_missing(o.out)) {
    throw Error(fmt::format("{}: exists and is not empty; choose a new folder", o.out.string()));
  }
  if (o.bags.size() == 1 && is_pcap_capture(o.bags.front())) return convert_capture(o);
  const BagSet bags(o.bags);
  ConvertResult result;
  result.stamps = o.stamps;
  result.bytes_read = bags.size_bytes();
  result.start_ns = bags.start_ns(), result.end_ns = bags.end_ns();

  // The topics to convert and their folders.
  std::map<std::string, std::string> folder_of(o.folders.begin(), o.folders.end());
  std::set<std::string> wanted(o.topics.begin(), o.topics.end());
  for (const auto& [topic, folder] : o.folders) {
    if (folder.empty() || folder.find('/') != std::string::npos || folder == "." ||
        folder == "..") {
      throw Error(fmt::format("topic {}: folder '{}' is not one folder name", topic, folder));
    }
  }
  std::map<std::string, Topic> topics;
  std::map<std::string, std::string> topic_in;  // folder -> topic
  uint64_t total = 0;
  for (const BagTopic& b : bags.topics()) {
    RosType type = ros_type(b.datatype);
    const bool asked = wanted.erase(b.topic) > 0;
    // Raw Ouster packets: lidar_packets and imu_packets beside the driver's metadata topic.
    std::unique_ptr<OusterStream> ouster;
    if (type == RosType::ouster_packets) {
      const std::string prefix = b.topic.substr(0, b.topic.rfind('/'));
      const bool lidar = b.topic.ends_with("/lidar_packets"),
                 imu = b.topic.ends_with("/imu_packets");
      std::string metadata;
      if (!o.ouster_metadata.empty()) {
        metadata = read_text_file(o.ouster_metadata, kMaxMetadataBytes);
      } else {
        bags.read({prefix + "/metadata"}, [&](const BagMessage& m) {
          if (metadata.empty()) metadata = decode_string_msg(m.bytes);
        });
      }
      if ((!lidar && !imu) || metadata.empty()) {
        if (asked) {
          throw Error(
              fmt::format("topic {}: raw Ouster packets need the driver's {}/metadata "
                          "topic or --metadata JSON",
                          b.topic, prefix));
        }
        result.skipped.emplace_back(b.topic, b.datatype);
        continue;
      }
      ouster = std::make_unique<OusterStream>();
      ouster->metadata = parse_ouster_metadata(
          metadata, o.ouster_metadata.empty() ? prefix + "/metadata" : o.ouster_metadata.string());
      ouster->lut = make_ouster_xyz_lut(ouster->metadata);
      ouster->assembler = std::make_unique<OusterFrameAssembler>(ouster->metadata);
      ouster->imu = imu;
    }
    if (type == RosType::other) {
      if (asked) {
        throw Error(
            fmt::format("topic {} is {}, which rigcal does not convert", b.topic, b.datatype));
      }
      result.skipped.emplace_back(b.topic, b.datatype);
      continue;
    }
    if (!o.topics.empty() && !asked) {
      result.skipped.emplace_back(b.topic, b.datatype);
      continue;
    }
    Topic t;
    t.type = type;
    t.info.topic = b.topic, t.info.datatype = b.datatype;
    const auto f = folder_of.find(b.topic);
    t.info.folder = f != folder_of.end() ? f->second
                    : ouster             ? (ouster->imu ? "ouster_imu" : "ouster_points")
                                         : default_topic_folder(b.topic);
    t.ouster = std::move(ouster);
    if (const auto [it, fresh] = topic_in.emplace(t.info.folder, b.topic); !fresh) {
      throw Error(
          fmt::format("topics {} and {} both go to folder {}; give one another with "
                      "--topic TOPIC=FOLDER",
                      it->second, b.topic, t.info.folder));
    }
    total += b.messages;
    topics.emplace(b.topic, std::move(t));
  }
  if (!wanted.empty()) {
    std::string held;
    for (const BagTopic& b : bags.topics()) held += (held.empty() ? "" : ", ") + b.topic;
    throw Error(fmt::format("topic {} is not in the bags (they hold {})", *wanted.begin(), held));
  }
  for (const auto& [topic, folder] : o.folders) {
    if (!topics.count(topic)) {
      throw Error(fmt::format("--topic {}={}: no such topic converted", topic, folder));
    }
  }

  std::vector<std::string> names;
  for (const auto& [name, t] : topics) names.push_back(name);
  write_recording(o, topics, result, [&] {
    uint64_t done = 0;
    ImageWriter images;
    if (!names.empty()) {
      bags.read(names, [&](const BagMessage& msg) {
        Topic& t = topics.at(msg.topic);
        try {
          store(t, msg, o.stamps, images);
        } catch (const ImageWriter::Failure&) {
          throw;
        } catch (const Error& e) {
          throw Error(fmt::format("{}: {}", message_name(msg), e.what()));
        }
        if (o.progress && ++done % 1000 == 0) o.progress("messages", done, total);
      });
    }
    images.finish();
    for (auto& [name, t] : topics) {
      if (t.ouster && !t.ouster->imu) {  // the frame in progress at the end
        t.ouster->assembler->finish(t.ouster->released);
        store_frames(t, o.stamps, Time{bags.end_ns()}, total);
      }
    }
  });
  if (o.progress) o.progress("messages", total, total);
  return result;
}

}  // namespace rigcal::io
