// ROS1 bags: reading (io::BagSet), the message decoders (io/ros_messages.h) and the conversion
// into a recording (io::convert_recording, `rigcal convert`), on bags written by ROS's own C++ API
// (bag_writer.h) whose every value is known.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "bag_writer.h"
#include "cli_run.h"
#include "fixtures.h"
#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/io/bag.h"
#include "rigcal/io/convert.h"
#include "rigcal/io/files.h"
#include "rigcal/io/gnss_fixes.h"
#include "rigcal/io/image_sets.h"
#include "rigcal/io/ouster_metadata.h"
#include "rigcal/io/ouster_pcap.h"
#include "rigcal/io/point_cloud_io.h"
#include "rigcal/io/rates_io.h"
#include "rigcal/io/ros_messages.h"
#include "rigcal/io/session.h"

namespace rigcal::io {
namespace {

namespace fs = std::filesystem;
namespace bag = testing::bag;

class Bags : public testing::ScratchTest {
 protected:
  void SetUp() override {
    ScratchTest::SetUp();
    bag::write_recording(dir_.string());
    bags_ = {dir_ / "rec_1.bag", dir_ / "rec_0.bag"};  // any order
  }
  ConvertResult convert(StampSource stamps = StampSource::header) {
    ConvertOptions o;
    o.bags = bags_;
    o.out = dir_ / "rec";
    o.stamps = stamps;
    return convert_recording(o);
  }
  std::string bytes_of(const fs::path& p) { return read_text_file(p); }
  std::vector<fs::path> bags_;
};

template <class T>
T at(std::string_view bytes, size_t offset) {
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof v);
  return v;
}

TEST_F(Bags, TwoChunksReadAsOneStreamInRecordTimeOrder) {
  const BagSet set(bags_);
  ASSERT_EQ(set.topics().size(), 5u);
  std::map<std::string, uint64_t> count;
  for (const BagTopic& t : set.topics()) count[t.topic] = t.messages;
  EXPECT_EQ(count["/imu/data"], uint64_t(bag::kImu));
  EXPECT_EQ(count["/ouster/points"], uint64_t(bag::kClouds));
  EXPECT_EQ(count["/gps/fix"], uint64_t(bag::kFixes));
  EXPECT_EQ(set.start_ns(), bag::kStart_ns + bag::kRecordDelay_ns);
  EXPECT_EQ(set.end_ns(), bag::imu_stamp_ns(bag::kImu - 1) + bag::kRecordDelay_ns);
  int64_t last = 0;
  uint64_t n = 0;
  int imu = 0;
  set.read({"/imu/data"}, [&](const BagMessage& m) {
    EXPECT_GE(m.record_time_ns, last);
    last = m.record_time_ns;
    EXPECT_EQ(m.index, n++);
    const RosImu d = decode_imu(m.bytes);
    EXPECT_EQ(d.header.stamp.ns, bag::imu_stamp_ns(imu));
    EXPECT_EQ(d.angular_velocity[1], bag::gyro(imu, 1));
    EXPECT_EQ(m.bag.filename(),
              bag::imu_stamp_ns(imu) < bag::kSplit_ns ? "rec_0.bag" : "rec_1.bag");
    ++imu;
  });
  EXPECT_EQ(imu, bag::kImu);
}

TEST_F(Bags, ConvertedRecordingHoldsEveryValueWritten) {
  const ConvertResult r = convert();
  ASSERT_EQ(r.converted.size(), 4u);
  ASSERT_EQ(r.skipped.size(), 1u);
  EXPECT_EQ(r.skipped[0].first, "/diagnostics");
  const fs::path rec = dir_ / "rec";
  EXPECT_TRUE(is_recording(rec));

  // Clouds: every record byte for byte (rows' padding dropped), the fields in .metadata.json,
  // and x y z through rigcal's own reader.
  const StampedFolder clouds = read_stamped_folder(rec / "ouster_points", ".bin");
  ASSERT_EQ(clouds.files.size(), size_t(bag::kClouds));
  for (int k = 0; k < bag::kClouds; ++k) {
    EXPECT_EQ(clouds.stamps[k].ns, bag::cloud_stamp_ns(k));
    const std::string b = bytes_of(clouds.files[k]);
    ASSERT_EQ(b.size(), size_t(bag::kCloudWidth * bag::kCloudHeight * bag::kPointStep));
    for (int p = 0; p < bag::kCloudWidth * bag::kCloudHeight; ++p) {
      const size_t o = size_t(p) * bag::kPointStep;
      ASSERT_EQ(at<float>(b, o + 0), bag::point_x(k, p));
      ASSERT_EQ(at<float>(b, o + 8), bag::point_z(k, p));
      ASSERT_EQ(at<float>(b, o + 16), bag::point_intensity(k, p));
      ASSERT_EQ(at<uint32_t>(b, o + 20), bag::point_t_ns(k, p));
      ASSERT_EQ(at<uint16_t>(b, o + 24), bag::point_reflectivity(k, p));
      ASSERT_EQ(at<uint16_t>(b, o + 26), bag::point_ring(k, p));
      ASSERT_EQ(at<uint16_t>(b, o + 28), bag::point_ambient(k, p));
      ASSERT_EQ(at<uint32_t>(b, o + 32), bag::point_range_mm(k, p));
    }
    const std::vector<Eigen::Vector3d> xyz = read_point_cloud(clouds.files[k]);
    ASSERT_EQ(xyz.size(), size_t(bag::kCloudWidth * bag::kCloudHeight));
    EXPECT_EQ(xyz[77].x(), double(bag::point_x(k, 77)));
    EXPECT_EQ(xyz[77].y(), double(bag::point_y(k, 77)));
  }
  const nlohmann::json meta =
      nlohmann::json::parse(bytes_of(rec / "ouster_points" / ".metadata.json"));
  EXPECT_EQ(meta["topic"], "/ouster/points");
  EXPECT_EQ(meta["num_messages"], bag::kClouds);
  EXPECT_EQ(meta["point_step"], bag::kPointStep);
  ASSERT_EQ(meta["fields"].size(), 9u);
  EXPECT_EQ(meta["fields"][4]["name"], "t");
  EXPECT_EQ(meta["fields"][4]["offset"], 20);
  EXPECT_EQ(meta["fields"][4]["datatype"], 6);

  // Images: raw Bayer mosaics, one channel, every pixel; the encoding noted.
  const StampedFolder images = read_stamped_folder(rec / "camera_left", ".png");
  ASSERT_EQ(images.files.size(), size_t(bag::kImages));
  for (int k = 0; k < bag::kImages; ++k) {
    EXPECT_EQ(images.stamps[k].ns, bag::image_stamp_ns(k));
    const cv::Mat img = cv::imread(images.files[k], cv::IMREAD_UNCHANGED);
    ASSERT_EQ(img.type(), CV_8UC1);
    ASSERT_EQ(img.cols, bag::kImageWidth);
    ASSERT_EQ(img.rows, bag::kImageHeight);
    for (int r = 0; r < img.rows; ++r)
      for (int c = 0; c < img.cols; ++c) ASSERT_EQ(img.at<uint8_t>(r, c), bag::pixel(k, r, c));
  }
  EXPECT_EQ(nlohmann::json::parse(bytes_of(rec / "camera_left" / ".metadata.json"))["encoding"],
            "bayer_rggb8");

  // IMU: vbr-devkit's CSV, read back by the time-offset step's reader; the values exact.
  const std::string imu_txt = bytes_of(rec / "imu" / "data" / "imu.txt");
  std::string header;
  const std::vector<TextLine> lines = data_lines(imu_txt, &header);
  ASSERT_EQ(lines.size(), size_t(bag::kImu));
  EXPECT_TRUE(header.starts_with("acc_x,acc_y,acc_z,gyr_x")) << header;
  const std::vector<std::string_view> f = split_fields(lines[5].text);
  ASSERT_EQ(f.size(), 37u);
  EXPECT_EQ(parse_double(f[0], "acc_x"), bag::accel(5, 0));
  EXPECT_EQ(parse_double(f[4], "gyr_y"), bag::gyro(5, 1));
  EXPECT_EQ(parse_double(f[6], "quat_w"), 1.0);
  EXPECT_EQ(parse_double(f[10], "cov_acc_xx"), 3 * bag::imu_covariance(0));
  EXPECT_EQ(parse_double(f[19], "cov_gyr_xx"), 2 * bag::imu_covariance(0));
  EXPECT_EQ(parse_double(f[36], "cov_rot_zz"), bag::imu_covariance(8));
  const RateFile rates = read_rates(rec / "imu");
  ASSERT_EQ(rates.rates.stamps.size(), size_t(bag::kImu));
  EXPECT_EQ(rates.rates.stamps[7].ns, bag::imu_stamp_ns(7));
  EXPECT_EQ(rates.rates.rates[7].z(), bag::gyro(7, 2));

  // Fixes: navsat.csv with the stamps, positions and the whole covariance (standard deviations,
  // then the terms off the diagonal), which the fixes' reader takes whole.
  const std::string navsat = bytes_of(rec / "gps_fix" / "navsat.csv");
  const std::vector<TextLine> fixes = data_lines(navsat, nullptr);
  ASSERT_EQ(fixes.size(), size_t(bag::kFixes));
  const std::vector<std::string_view> g = split_fields(fixes[3].text);
  ASSERT_EQ(g.size(), 13u);
  EXPECT_EQ(g[6], "3");
  EXPECT_EQ(parse_double(g[10], "cov_en"), 0.0003);
  EXPECT_EQ(parse_double(g[12], "cov_nu"), -0.0002);
  const GnssFixes read = read_gnss_fixes(rec / "gps_fix" / "navsat.csv", std::nullopt);
  ASSERT_EQ(read.covariance_enu_m2.size(), size_t(bag::kFixes));
  const Eigen::Matrix3d C_enu = (Eigen::Matrix3d() << 0.0004, 0.0003, 0.0001, 0.0003, 0.0009,
                                 -0.0002, 0.0001, -0.0002, 0.0025)
                                    .finished();
  EXPECT_LT((read.covariance_enu_m2[3] - C_enu).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(parse_time(g[0]).ns, bag::fix_stamp_ns(3));
  EXPECT_EQ(parse_double(g[1], "lat"), bag::latitude(3));
  EXPECT_EQ(parse_double(g[2], "lon"), bag::longitude(3));
  EXPECT_EQ(parse_double(g[3], "height"), bag::altitude(3));
  EXPECT_EQ(g[4], "2");
  EXPECT_NEAR(parse_double(g[8], "std_north"), 0.03, 1e-15);

  // What was done, for people and for provenance.
  const nlohmann::json prov = nlohmann::json::parse(bytes_of(rec / "convert.json"));
  EXPECT_EQ(prov["rigcal_convert"]["stamps"], "header");
  EXPECT_EQ(prov["topics"].size(), 4u);
  EXPECT_EQ(prov["skipped"][0]["datatype"], "std_msgs/String");
  for (const auto& e : fs::directory_iterator(dir_))
    EXPECT_EQ(e.path().filename().string().find(".partial-"), std::string::npos) << e.path();
}

TEST_F(Bags, RecordStampsAreTheBagsClock) {
  const ConvertResult r = convert(StampSource::record);
  EXPECT_EQ(r.stamps, StampSource::record);
  const StampedFolder clouds = read_stamped_folder(dir_ / "rec" / "ouster_points", ".bin");
  ASSERT_EQ(clouds.stamps.size(), size_t(bag::kClouds));
  EXPECT_EQ(clouds.stamps[2].ns, bag::cloud_stamp_ns(2) + bag::kRecordDelay_ns);
}

TEST_F(Bags, BadRequestsAndDamagedBagsAreErrorsAndLeaveNothing) {
  ConvertOptions o;
  o.bags = bags_;
  o.out = dir_ / "rec";
  o.topics = {"/nope"};
  EXPECT_NE(error_of([&] { convert_recording(o); }).find("topic /nope is not in the bags"),
            std::string::npos);
  o.topics = {"/diagnostics"};
  EXPECT_NE(error_of([&] { convert_recording(o); }).find("std_msgs/String, which rigcal does not"),
            std::string::npos);
  o.topics.clear();
  o.folders = {{"/gps/fix", "imu"}};
  EXPECT_NE(error_of([&] { convert_recording(o); }).find("both go to folder imu"),
            std::string::npos);
  o.folders.clear();
  write("rec/keep.txt", "mine");
  EXPECT_NE(error_of([&] { convert_recording(o); }).find("exists and is not empty"),
            std::string::npos);
  EXPECT_EQ(bytes_of(dir_ / "rec" / "keep.txt"), "mine");
  fs::remove_all(dir_ / "rec");

  // Not a bag; a bag cut in its middle (the index at the end is gone).
  o.bags = {write("text.bag", "just text\n")};
  EXPECT_NE(error_of([&] { convert_recording(o); }).find("text.bag: not a ROS1 bag"),
            std::string::npos);
  const std::string whole = bytes_of(dir_ / "rec_0.bag");
  o.bags = {write("cut.bag", whole.substr(0, whole.size() / 2))};
  const std::string e = error_of([&] { convert_recording(o); });
  EXPECT_NE(e.find("cut.bag: "), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(dir_ / "rec"));
  for (const auto& f : fs::directory_iterator(dir_))
    EXPECT_EQ(f.path().filename().string().find(".partial-"), std::string::npos) << f.path();
}

// A folder of bags given as --session: converted once into a temporary recording that serves
// every purpose its topics serve, holding what `rigcal convert` writes; the provenance names the
// bags; the temporary recording is gone when the command ends, whatever its status.
TEST_F(Bags, AFolderOfBagsOrABagIsASessionConvertedOnTheFly) {
  const Session s = read_session(dir_);
  ASSERT_EQ(s.converted.size(), 1u);
  const fs::path converted = s.converted.front().recording;
  EXPECT_EQ(s.converted.front().files,
            (std::vector<fs::path>{dir_ / "rec_0.bag", dir_ / "rec_1.bag"}));
  EXPECT_EQ(s.root, dir_);
  EXPECT_EQ(s.cameras, converted);
  EXPECT_EQ(s.lidar_camera, converted);
  EXPECT_EQ(s.motion, converted);
  EXPECT_EQ(source_path(s, converted / "imu"), dir_ / "imu");
  EXPECT_EQ(source_path(s, dir_ / "elsewhere"), dir_ / "elsewhere");
  EXPECT_EQ(read_session(dir_).converted.front().recording, converted);  // once a process
  convert();
  for (const char* f : {"imu/data/imu.txt", "imu/timestamps.txt", "ouster_points/timestamps.txt",
                        "ouster_points/data/0000000003.bin", "camera_left/data/0000000005.png",
                        "gps_fix/navsat.csv"})
    EXPECT_EQ(bytes_of(converted / f), bytes_of(dir_ / "rec" / f)) << f;
  fs::remove_all(dir_ / "rec");

  // One bag alone is a session too (its first half); a folder with only text is not.
  const Session one = read_session(dir_ / "rec_0.bag");
  ASSERT_EQ(one.converted.size(), 1u);
  EXPECT_EQ(one.converted.front().files, std::vector<fs::path>{dir_ / "rec_0.bag"});
  const std::string imu_stamps = bytes_of(one.motion / "imu" / "timestamps.txt");
  EXPECT_GT(std::count(imu_stamps.begin(), imu_stamps.end(), '\n'), 0);
  EXPECT_LT(std::count(imu_stamps.begin(), imu_stamps.end(), '\n'), bag::kImu);
  write("other/notes.txt", "x");
  EXPECT_NE(error_of([&] {
              recording_for(read_session(dir_ / "other"), "cameras");
            }).find("no recording for cameras"),
            std::string::npos);

  // session.yaml naming a bag for one purpose and a folder of bags for another.
  write("session/session.yaml", "cameras: ../rec_0.bag\nmotion: ..\n");
  const Session named = read_session(dir_ / "session");
  ASSERT_EQ(named.converted.size(), 2u);
  EXPECT_EQ(named.cameras, one.motion);  // rec_0.bag, converted once
  EXPECT_EQ(named.motion, converted);
  EXPECT_TRUE(named.lidar_camera.empty());
  EXPECT_EQ(source_path(named, named.cameras / "camera_left"), dir_ / "rec_0.bag" / "camera_left");
  EXPECT_EQ(source_path(named, named.motion / "imu"), dir_ / "imu");

  // The command line: a step on the bags (the motion lacks the LiDAR's IMU: exit 2, named), and
  // nothing left in TMPDIR.
  fs::create_directories(dir_ / "tmp");
  const testing::CliRun r =
      testing::rigcal_cli(fmt::format("time-offset --session {}", dir_.string()), dir_,
                          fmt::format("TMPDIR={}", (dir_ / "tmp").string()));
  ASSERT_NE(r.status, -1);  // exited
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("ouster_imu"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_empty(dir_ / "tmp"));
}

// A step on a bag directly: the simulator's two IMU logs written as one bag (/ouster/imu and
// /imu/data, vbr-devkit's names); `time-offset --session BAG` finds the offset it finds on the
// bag converted by `rigcal convert` and on the simulator's own folders, to the printed digit.
TEST_F(Bags, TimeOffsetOnABagIsTheOffsetOnItsConversionAndOnTheOriginal) {
  auto cli = [&](const std::string& args) {
    const testing::CliRun r = testing::rigcal_cli(args, dir_);
    EXPECT_EQ(r.status, 0) << args << "\n" << r.err;
    return r.out;
  };
  auto offset_line = [](const std::string& out) {
    const size_t at = out.find("offset: ");
    return at == std::string::npos ? std::string("(no offset line)")
                                   : out.substr(at, out.find('\n', at) - at);
  };
  const fs::path sim = dir_ / "sim";
  cli(fmt::format("simulate --out {} --what imu", sim.string()));
  std::vector<bag::ImuTopic> topics;
  for (const auto& [folder, topic] :
       {std::pair{"ouster_imu", "/ouster/imu"}, {"imu", "/imu/data"}}) {
    const RateFile f = read_rates(sim / folder);
    bag::ImuTopic t{topic, {}, {}};
    for (size_t k = 0; k < f.rates.stamps.size(); ++k) {
      t.stamps_ns.push_back(f.rates.stamps[k].ns);
      t.gyro.push_back({f.rates.rates[k].x(), f.rates.rates[k].y(), f.rates.rates[k].z()});
    }
    ASSERT_GT(t.stamps_ns.size(), 1000u);
    topics.push_back(std::move(t));
  }
  fs::create_directories(dir_ / "motion");
  bag::write_imu_bag((dir_ / "motion" / "motion.bag").string(), topics);

  const std::string on_bag = offset_line(
      cli(fmt::format("time-offset --session {}", (dir_ / "motion" / "motion.bag").string())));
  cli(fmt::format("convert {} --out {}", (dir_ / "motion" / "motion.bag").string(),
                  (dir_ / "converted").string()));
  const std::string on_conversion =
      offset_line(cli(fmt::format("time-offset --session {}", (dir_ / "converted").string())));
  const std::string on_original =
      offset_line(cli(fmt::format("time-offset --session {}", sim.string())));
  EXPECT_NE(on_bag.find("t_reference = t_other + "), std::string::npos) << on_bag;
  EXPECT_EQ(on_bag, on_conversion);
  EXPECT_EQ(on_bag, on_original);
  // The folder of the bag is a session too.
  EXPECT_EQ(offset_line(cli(fmt::format("time-offset --session {}", (dir_ / "motion").string()))),
            on_bag);
}

using OusterConvert = testing::ScratchTest;

// The scans written from raw packets (a bag) or a capture, read back by rigcal's point reader,
// against the capture reader's own scans of the same packets.
TEST_F(OusterConvert, ACaptureAndABagOfRawPacketsBecomeScansAndImuSamples) {
  const std::string pcap =
      testing::fixture("lidar/ouster_os1_128/OS-1-128_v2.3.0_1024x10_lb_n3.pcap");
  const std::string json = testing::fixture("lidar/ouster_os1_128/OS-1-128_v2.3.0_1024x10.json");
  const std::string bag = testing::fixture("lidar/ouster_sdk/512x10_raw.bag");
  if (pcap.empty() || json.empty() || bag.empty())
    GTEST_SKIP() << "Ouster fixtures not found under ../shared/fixtures";

  ConvertOptions o;
  o.bags = {pcap};
  o.out = dir_ / "from_pcap";
  EXPECT_NE(error_of([&] { convert_recording(o); }).find("needs the sensor's metadata JSON"),
            std::string::npos);
  o.ouster_metadata = json;
  const ConvertResult r = convert_recording(o);
  ASSERT_EQ(r.converted.size(), 2u);
  OusterPcapReader reader(pcap, read_ouster_metadata(json));
  std::vector<Scan> scans;
  while (std::optional<Scan> s = reader.next_scan()) scans.push_back(std::move(*s));
  ASSERT_EQ(scans.size(), 3u);
  const StampedFolder points = read_stamped_folder(o.out / "ouster_points", ".bin");
  ASSERT_EQ(points.files.size(), scans.size());
  for (size_t k = 0; k < scans.size(); ++k) {
    EXPECT_EQ(points.stamps[k], scans[k].stamp);
    const std::vector<Eigen::Vector3d> xyz = read_point_cloud(points.files[k]);
    ASSERT_EQ(xyz.size(), scans[k].points.size());
    for (size_t i = 0; i < xyz.size(); i += 997)
      EXPECT_EQ(xyz[i].cast<float>(), scans[k].points[i].p) << k << " " << i;
    const std::string b = read_text_file(points.files[k]);
    ASSERT_EQ(b.size(), 48 * scans[k].points.size());
    const size_t i = scans[k].points.size() / 2;
    EXPECT_EQ(at<uint32_t>(b, 48 * i + 20), uint32_t(scans[k].points[i].t_ns));
    EXPECT_EQ(at<uint16_t>(b, 48 * i + 26), scans[k].points[i].ring);
    EXPECT_EQ(at<uint32_t>(b, 48 * i + 32), scans[k].points[i].range_mm);
  }
  // The capture's 30 IMU packets, readable by the time-offset step, gyro in rad/s.
  const RateFile rates = read_rates(o.out / "ouster_imu");
  EXPECT_EQ(rates.rates.stamps.size(), 30u);

  // The sdk's bag of raw packets with its metadata topic: its one complete frame (1798).
  ConvertOptions ob;
  ob.bags = {bag};
  ob.out = dir_ / "from_bag";
  const ConvertResult rb = convert_recording(ob);
  std::map<std::string, ConvertedTopic> by_folder;
  for (const ConvertedTopic& t : rb.converted) by_folder[t.folder] = t;
  ASSERT_TRUE(by_folder.count("ouster_points"));
  ASSERT_TRUE(by_folder.count("ouster_imu"));
  EXPECT_EQ(by_folder["ouster_points"].messages, 1u) << by_folder["ouster_points"].note;
  EXPECT_EQ(by_folder["ouster_imu"].messages, 10u);
  const StampedFolder bag_points = read_stamped_folder(ob.out / "ouster_points", ".bin");
  ASSERT_EQ(bag_points.files.size(), 1u);
  const std::vector<Eigen::Vector3d> xyz = read_point_cloud(bag_points.files[0]);
  // The same packets batched here, step by step: every valid pixel is a point or a no-return.
  const BagSet set({bag});
  std::string metadata_json;
  set.read({"/os_node0/metadata"},
           [&](const BagMessage& m) { metadata_json = decode_string_msg(m.bytes); });
  const OusterMetadata meta = parse_ouster_metadata(metadata_json, "bag");
  OusterFrameAssembler assembler(meta);
  OusterLidarPacket packet;
  std::vector<OusterFrame> frames;
  set.read({"/os_node0/lidar_packets"}, [&](const BagMessage& m) {
    const std::string_view buf = decode_packet_msg(m.bytes);
    ASSERT_EQ(decode_ouster_lidar_packet({reinterpret_cast<const uint8_t*>(buf.data()), buf.size()},
                                         meta, false, packet),
              OusterPacketResult::Ok);
    assembler.add(packet, frames);
  });
  assembler.finish(frames);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].frame_id, 1798u);
  EXPECT_TRUE(frames[0].complete);
  OusterScanStats stats;
  const Scan scan = ouster_scan(frames[0], meta, make_ouster_xyz_lut(meta), &stats);
  EXPECT_EQ(stats.invalid_columns, 0u);
  EXPECT_EQ(xyz.size() + stats.no_return, size_t(meta.columns_per_frame * meta.pixels_per_column));
  EXPECT_EQ(bag_points.stamps[0], scan.stamp);
  for (const Eigen::Vector3d& p : xyz) ASSERT_LT(p.norm(), 200.0);
}

TEST(RosMessages, TruncationsAndInconsistentSizesAreNamed) {
  // A PointCloud2 with one field, serialized by hand: header, 1 x 2 points of 4 bytes.
  std::string m;
  auto u32 = [&](uint32_t v) { m.append(reinterpret_cast<const char*>(&v), 4); };
  auto u8 = [&](uint8_t v) { m.push_back(static_cast<char>(v)); };
  auto str = [&](std::string_view s) { u32(uint32_t(s.size())), m.append(s); };
  u32(0), u32(12), u32(5), str("os");       // header: seq, stamp 12 s 5 ns, frame
  u32(1), u32(2);                           // height, width
  u32(1), str("x"), u32(0), u8(7), u32(1);  // fields
  u8(0), u32(4), u32(8);                    // is_bigendian, point_step, row_step
  str(std::string(8, '\0')), u8(1);         // data, is_dense
  const RosPointCloud2 c = decode_point_cloud2(m);
  EXPECT_EQ(c.header.stamp.ns, 12'000'000'005);
  EXPECT_EQ(c.header.frame_id, "os");
  EXPECT_EQ(c.data.size(), 8u);
  for (size_t cut : {size_t{3}, size_t{20}, m.size() - 1}) {
    try {
      decode_point_cloud2(std::string_view(m).substr(0, cut));
      ADD_FAILURE() << cut;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("PointCloud2: cut short at byte"), std::string::npos);
    }
  }
  std::string wide = m;
  wide[wide.size() - 21] = 8;  // point_step 8 with row_step 8 and width 2: 16 bytes needed
  EXPECT_THROW(decode_point_cloud2(wide), Error);
  EXPECT_EQ(default_topic_folder("/camera_left/image_raw"), "camera_left");
  EXPECT_EQ(default_topic_folder("/imu/data"), "imu");
  EXPECT_EQ(default_topic_folder("/ouster/points"), "ouster_points");
  EXPECT_EQ(default_topic_folder("/gps/fix"), "gps_fix");
}

}  // namespace
}  // namespace rigcal::io
