#pragma once
// ROS1 bags into a recording folder (doc/session.md, "From bags"): the layout vbr-devkit's
// `convert kitti` writes, one folder a topic, so that every step reads the result as it reads a
// devkit conversion.
//  - sensor_msgs/PointCloud2: data/NNNNNNNNNN.bin, each point the message's whole record
//    (point_step bytes, every field kept, rows' padding dropped), the fields and point_step in
//    .metadata.json beside data/ (vbr-devkit's keys plus point_step).
//  - sensor_msgs/Image: data/NNNNNNNNNN.png as recorded: mono and Bayer mosaics one channel
//    (8 or 16 bit, a mosaic stored undebayered), colour as BGR; the encoding in .metadata.json.
//  - sensor_msgs/Imu: data/imu.txt, vbr-devkit's 37-column CSV (acc, gyr, quat wxyz, the three
//    covariances), every value in shortest round-trip form.
//  - each of those: timestamps.txt, one ISO-8601 stamp a message (9 fraction digits).
//  - sensor_msgs/NavSatFix: navsat.csv (time, latitude, longitude, height, status, service,
//    covariance type, std_east, std_north, std_up); geometry_msgs/PoseStamped,
//    PoseWithCovarianceStamped and nav_msgs/Odometry: poses.tum (T_frame_child).
//  - raw Ouster packets (ouster_ros/PacketMsg, the driver's lidar_packets and imu_packets with
//    its metadata topic): decoded as a capture is (doc/formats.md, "Ouster captures") into
//    ouster_points/ (one scan a frame, the ROS driver's 48-byte point records: x y z intensity t
//    reflectivity ring ambient range) and ouster_imu/ (the IMU CSV, no orientation); the stamp
//    of a frame its first valid column's time on the sensor clock.
// Topics of other types are listed, not converted. The stamps are the messages' header stamps
// by default, or the bag's record times (what vbr-devkit writes); a message whose stamp is not
// after its topic's previous one is left out and counted (a topic's frames must increase).
//
// The folder is written under a temporary name beside RECORDING and renamed when complete: a
// failed or interrupted conversion leaves no RECORDING (the temporary, "<name>.partial-<pid>",
// is removed on failure).
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace rigcal::io {

enum class StampSource { header, record };
StampSource stamp_source_from_string(std::string_view name);  // header | record

struct ConvertOptions {
  std::vector<std::filesystem::path> bags;  // one recording's bags (chunks), any order
  std::filesystem::path out;                // the recording folder; must not exist or be empty
  StampSource stamps = StampSource::header;
  // Topics to convert (all of the types above when empty).
  std::vector<std::string> topics;
  // Topic -> folder overrides of default_topic_folder ("/gps/fix" -> "gnss").
  std::vector<std::pair<std::string, std::string>> folders;
  // The sensor's metadata JSON for raw Ouster packets (ouster_ros/PacketMsg) when the bags lack
  // the driver's <ns>/metadata topic.
  std::filesystem::path ouster_metadata;
  // Called now and then with the messages done of all to convert (report::Progress's form).
  std::function<void(std::string_view what, size_t done, size_t total)> progress;
};

struct ConvertedTopic {
  std::string topic, datatype, folder;
  uint64_t messages = 0;           // written
  uint64_t out_of_order = 0;       // left out: stamp not after the previous one
  std::string first_out_of_order;  // "message 12 (stamp ... after ...)" where any
  std::string note;                // raw Ouster packets: those skipped and why
};

struct ConvertResult {
  std::vector<ConvertedTopic> converted;
  std::vector<std::pair<std::string, std::string>> skipped;  // topic, datatype (not converted)
  StampSource stamps = StampSource::header;
  bool capture = false;  // an Ouster capture (stamps on the sensor's clock), not bags
  uint64_t bytes_read = 0;
  int64_t start_ns = 0, end_ns = 0;  // record times of the bags' first and last message
};

// vbr-devkit's folder of a topic: the leading '/' dropped, "/image_raw" and "/data" removed,
// '/' made '_' ("/ouster/points" -> "ouster_points", "/camera_left/image_raw" -> "camera_left",
// "/imu/data" -> "imu").
std::string default_topic_folder(std::string_view topic);

// `options.bags`: a recording's bags, or one Ouster capture (a pcap or pcapng file, told by its
// first bytes) with `ouster_metadata`, which becomes ouster_points/ and ouster_imu/ as above.
// Throws rigcal::Error naming the bag, the topic and the message index on a message that cannot
// be decoded or stored, and when `out` exists and is not empty, or two topics map to one folder.
ConvertResult convert_recording(const ConvertOptions& options);

}  // namespace rigcal::io
