// rigcal capture: records a calibration session's cameras through Aravis (doc/capture.md).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <atomic>
#include <csignal>
#include <memory>

#include "cli.h"
#include "rigcal/capture/record.h"
#include "rigcal/core/error.h"
#include "rigcal/io/capture_config.h"
#include "rigcal/io/target_yaml.h"

namespace rigcal::cli {
namespace capture_command {

struct Options {
  bool list = false, fake = false;
  std::string config, left, right, out, target, bayer;
  size_t frames = 0;
  double duration_s = 0;
};

std::atomic<bool> interrupted{false};
extern "C" void on_interrupt(int) {
  interrupted = true;
  std::signal(SIGINT, SIG_DFL);  // a second Ctrl-C ends the process at once
}

void list(bool fake) {
  const auto cameras = capture::list_cameras(true, fake);
  if (cameras.empty())
    fmt::print("no camera found (GigE Vision on every interface, USB3 Vision)\n");
  for (const auto& c : cameras)
    fmt::print("{}\n  vendor {}, model {}, serial {}, address {}, {}\n  pixel formats: {}\n", c.id,
               c.vendor, c.model, c.serial, c.address, c.protocol,
               c.pixel_formats.empty() ? "(not read: the camera could not be opened)"
                                       : fmt::format("{}", fmt::join(c.pixel_formats, " ")));
}

void run(const Options& o) {
  if (o.list) return list(o.fake);
  if (o.out.empty()) throw Error("capture: --out is needed (the recording folder to write)");
  io::CaptureConfig config;
  if (!o.config.empty()) {
    if (!o.left.empty() || !o.right.empty())
      throw Error("capture: give the cameras in --config or by --left/--right, not both");
    config = io::read_capture_config(o.config);
  } else {
    if (o.left.empty() && o.right.empty())
      throw Error("capture: no camera: give --config FILE, or --left ID (and --right ID)");
    for (const auto& [folder, id] : {std::pair{"camera_left", o.left}, {"camera_right", o.right}})
      if (!id.empty()) {
        io::CaptureCameraConfig c;
        c.folder = folder;
        c.id = id;
        config.cameras.push_back(c);
      }
  }
  if (o.fake) capture::list_cameras(false, true);  // Aravis' in-process fake camera, "Fake_1"

  capture::RecordOptions options;
  options.config = config;
  options.out = o.out;
  if (o.frames > 0) options.frames = o.frames;
  if (o.duration_s > 0) options.duration_s = o.duration_s;
  options.interrupt = &interrupted;
  options.progress = [&](const capture::RecordProgress& p) {
    std::string line = fmt::format("\r{:.0f} s:", p.seconds);
    for (size_t i = 0; i < p.written.size(); ++i)
      line += fmt::format(" {} {} frames{}", config.cameras[i].folder, p.written[i],
                          p.missing[i] ? fmt::format(" ({} missing)", p.missing[i]) : "");
    fmt::print(stderr, "{}   ", line);
  };
  if (!o.target.empty()) {
    capture::AssistOptions assist;
    assist.target = io::read_target_file(o.target);
    assist.bayer = io::bayer_from_string(o.bayer);
    options.assist = assist;
    auto last = std::make_shared<std::vector<std::string>>();
    options.on_coverage = [last](const std::vector<capture::CameraCoverage>& coverage) {
      const auto lines = capture::Assistant::lines(coverage);
      if (lines == *last) return;
      *last = lines;
      for (const std::string& line : lines) fmt::print(stderr, "\n{}", line);
      fmt::print(stderr, "\n");
    };
  }
  std::signal(SIGINT, on_interrupt);
  const capture::CaptureRun result = capture::record(options);
  std::signal(SIGINT, SIG_DFL);
  fmt::print(stderr, "\n");

  for (const capture::CameraRecord& c : result.cameras) {
    fmt::print("{}: {} ({} {}, {}), {}, trigger {}\n", c.folder, c.info.id, c.info.vendor,
               c.info.model, c.info.address, c.pixel_format, c.trigger);
    for (const capture::FeatureResult& f : c.features)
      fmt::print(
          "  {:<26} {:<9} {}{}  ({})\n", f.feature, capture::to_string(f.status),
          f.accepted.empty() ? f.asked : f.accepted,
          f.status == capture::FeatureResult::Status::adjusted ? " (asked " + f.asked + ")" : "",
          f.why);
    fmt::print("  {} frames written, {} missing (gaps in the frame ids: {}), {} incomplete{}\n",
               c.written, c.missing, c.gaps.size(), c.incomplete,
               c.triggers_sent ? fmt::format(", {} software triggers", c.triggers_sent) : "");
  }
  if (result.cameras.size() == 2) {
    fmt::print("pairs by trigger: {} (stamps within {:.2f} ms of each other)\n", result.pairs,
               1e3 * result.max_pair_difference_s);
    if (result.pairs == 0)
      fmt::print(
          "note: no frame of one camera has a frame of the other within half a frame "
          "interval: with stamps: camera, the cameras' clocks must be synchronised (PTP)\n");
    else if (result.max_pair_difference_s > 0.005)
      fmt::print(
          "note: rigcal calibrate pairs the cameras' images within 5 ms: pairs further "
          "apart are left out (host stamps differ by the frames' transfer; cameras' own "
          "clocks agree only when synchronised, PTP)\n");
  }
  fmt::print("stopped by {} after {:.1f} s; wrote {} (the session layout) and {}/capture.json\n",
             result.stopped_by, result.seconds, o.out, o.out);
  const std::string bayer =
      result.cameras.empty() ? "" : capture::bayer_pattern(result.cameras[0].pixel_format);
  for (const std::string& line : capture::Assistant::lines(result.coverage))
    fmt::print("{}\n", line);
  if (!result.coverage.empty()) fmt::print("the views' coverage: {}/coverage.png\n", o.out);
  if (!bayer.empty())
    fmt::print("raw {} mosaics: calibrate with `rigcal calibrate --session {} --bayer {} ...`\n",
               result.cameras[0].pixel_format, o.out, bayer);
  if (!result.error.empty())
    throw Error(fmt::format("{}; what was recorded is kept in {}", result.error, o.out));
}

}  // namespace capture_command

void add_capture(CLI::App& app) {
  using namespace capture_command;
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "capture",
      "Records the rig's cameras through Aravis (GigE Vision, USB3 Vision) in the session layout\n"
      "(doc/capture.md): each camera's GenICam features set and read back (a feature the config\n"
      "asks for that the camera lacks or refuses stops it, named), a thread a camera, frames\n"
      "written as PNG (raw Bayer kept raw) with timestamps.txt and frames.csv, missing frames\n"
      "counted and listed in capture.json, the cameras paired by trigger. Ctrl-C stops cleanly:\n"
      "every frame received is on disk with its stamp.");
  cmd->add_flag("--list", o->list, "list the cameras Aravis sees, with their pixel formats");
  cmd->add_option("--config", o->config, "the capture config (YAML, doc/capture.md)");
  cmd->add_option("--left", o->left,
                  "without --config: the left camera's Aravis id, serial or address (defaults: "
                  "BayerRG8, software trigger at 10 Hz, auto exposure up to 20 ms)");
  cmd->add_option("--right", o->right, "without --config: the right camera");
  cmd->add_option("--out", o->out, "the recording folder to write (new or empty)");
  cmd->add_option("--frames", o->frames, "stop once every camera has this many frames")
      ->check(whole_count("a number of frames"));
  cmd->add_option("--duration", o->duration_s, "stop after this many seconds")
      ->check(seconds_within(0.001));
  cmd->add_option("--target", o->target,
                  "calibration assistance with this board (target YAML): the detector on a "
                  "decimated stream says which parts of the image, tilts and distances are "
                  "missing for the camera step's bars, refreshes OUT/coverage.png")
      ->check(CLI::ExistingFile);
  cmd->add_option("--bayer", o->bayer,
                  "the raw mosaic for the assistance's detector (default: from the pixel format)");
  cmd->add_flag("--fake", o->fake, "also see Aravis' in-process fake camera, Fake_1 (for trying)");
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::cli
