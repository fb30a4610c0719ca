// rigcal convert BAG... --out RECORDING: ROS1 bags into the recording layout (doc/session.md).
#include "rigcal/io/convert.h"

#include <fmt/format.h>

#include <memory>

#include "cli.h"
#include "rigcal/core/error.h"
#include "rigcal/core/time.h"
#include "step_output.h"

namespace rigcal::cli {
namespace convert_command {

struct Options {
  std::vector<std::string> bags, topics, folders;
  std::string out, stamps = "header", metadata;
};

void run(const Options& o) {
  io::ConvertOptions co;
  co.bags.assign(o.bags.begin(), o.bags.end());
  co.out = o.out;
  co.stamps = io::stamp_source_from_string(o.stamps);
  co.topics = o.topics;
  co.ouster_metadata = o.metadata;
  for (const std::string& f : o.folders) {
    const size_t eq = f.rfind('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == f.size())
      throw Error(fmt::format("--topic: expected TOPIC=FOLDER, got '{}'", f));
    co.folders.emplace_back(f.substr(0, eq), f.substr(eq + 1));
  }
  co.progress = console_progress();
  const io::ConvertResult r = io::convert_recording(co);
  fmt::print("{}: {} {}, {:.1f} MB, {} times {} to {} ({:.1f} s)\n", o.out, o.bags.size(),
             r.capture ? "Ouster capture" : "bag(s)", r.bytes_read / 1e6,
             r.capture ? "sensor" : "record", to_iso8601(Time{r.start_ns}),
             to_iso8601(Time{r.end_ns}), (r.end_ns - r.start_ns) * 1e-9);
  if (r.capture) {
    fmt::print(
        "stamps: the sensor's clock (a frame's first valid column, an IMU packet's accel)\n");
  } else {
    fmt::print("stamps: the messages' {}\n",
               r.stamps == io::StampSource::header
                   ? "header stamps (--stamps record: the bag's record times, as vbr-devkit "
                     "writes)"
                   : "record times (the bag's clock, as vbr-devkit)");
  }
  for (const io::ConvertedTopic& t : r.converted) {
    fmt::print("  {} ({}) -> {}/: {} messages", t.topic, t.datatype, t.folder, t.messages);
    if (t.out_of_order)
      fmt::print(", {} left out, stamp not after the previous one (first: {})", t.out_of_order,
                 t.first_out_of_order);
    if (!t.note.empty()) fmt::print("; {}", t.note);
    fmt::print("\n");
  }
  for (const auto& [topic, type] : r.skipped) fmt::print("  {} ({}): not converted\n", topic, type);
}

}  // namespace convert_command

void add_convert(CLI::App& app) {
  using namespace convert_command;
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "convert",
      "ROS1 bags into a recording folder in vbr-devkit's `convert kitti` layout (doc/session.md),\n"
      "which every step reads: one folder a topic (/ouster/points -> ouster_points/,\n"
      "/camera_left/image_raw -> camera_left/, /imu/data -> imu/), with timestamps.txt and data/.\n"
      "A recording's bag chunks are merged in time order. Point clouds keep every field; images\n"
      "are stored as recorded (Bayer undebayered); IMU as vbr-devkit's CSV; NavSatFix as\n"
      "navsat.csv; pose and odometry messages as poses.tum. Other topics are listed. Written\n"
      "all or nothing: RECORDING appears only when complete. An Ouster capture (pcap) with its\n"
      "--metadata JSON, and raw Ouster packets in bags, become ouster_points/ (a scan a frame,\n"
      "the ROS driver's point fields) and ouster_imu/.");
  cmd->add_option("bags", o->bags,
                  "the recording's .bag files (chunks in any order), or one Ouster capture (.pcap)")
      ->required();
  cmd->add_option("--metadata", o->metadata,
                  "the Ouster sensor's metadata JSON: for a capture, or for bags of raw packets "
                  "without the driver's metadata topic");
  cmd->add_option("--out", o->out, "the recording folder to write (new or empty)")->required();
  cmd->add_option("--topics", o->topics, "only these topics (default: every convertible one)")
      ->delimiter(',');
  cmd->add_option("--topic", o->folders,
                  "TOPIC=FOLDER: the folder of a topic (e.g. /gps/fix=gnss); repeatable");
  cmd->add_option("--stamps", o->stamps,
                  "header: each message's header stamp; record: the bag's record time (what "
                  "vbr-devkit writes)")
      ->check(CLI::IsMember({"header", "record"}))
      ->capture_default_str();
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::cli
