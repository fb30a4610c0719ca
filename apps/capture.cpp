// rigcal capture: records a calibration session's cameras through Aravis (doc/capture.md).
#include <fmt/format.h>

#include <atomic>
#include <csignal>
#include <memory>

#include "cli.h"
#include "rigcal/capture/step.h"
#include "rigcal/core/error.h"

namespace rigcal::cli {
namespace capture_command {

struct Options {
  capture::CaptureRequest request;
  bool list = false;
};

std::atomic<bool> interrupted{false};
extern "C" void on_interrupt(int) {
  interrupted = true;
  std::signal(SIGINT, SIG_DFL);  // a second Ctrl-C ends the process at once
}

void run(Options o) {
  if (o.list) {
    for (const std::string& line : capture::camera_list_lines(o.request.fake))
      fmt::print("{}\n", line);
    return;
  }
  capture::RecordOptions options = capture::record_options(o.request, &interrupted);
  options.progress = [&config = options.config](const capture::RecordProgress& p) {
    fmt::print(stderr, "\r{}   ", capture::progress_line(p, config));
  };
  auto last = std::make_shared<std::vector<std::string>>();
  options.on_coverage = [last](const std::vector<capture::CameraCoverage>& coverage) {
    const auto lines = capture::Assistant::lines(coverage);
    if (lines == *last) return;
    *last = lines;
    for (const std::string& line : lines) fmt::print(stderr, "\n{}", line);
    fmt::print(stderr, "\n");
  };
  std::signal(SIGINT, on_interrupt);
  const capture::CaptureRun result = capture::record(options);
  std::signal(SIGINT, SIG_DFL);
  fmt::print(stderr, "\n");
  for (const std::string& line : capture::summary_lines(result)) fmt::print("{}\n", line);
  if (!result.error.empty())
    throw Error(
        fmt::format("{}; what was recorded is kept in {}", result.error, o.request.out.string()));
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
  cmd->add_option("--config", o->request.config, "the capture config (YAML, doc/capture.md)");
  cmd->add_option("--left", o->request.left,
                  "without --config: the left camera's Aravis id, serial or address (defaults: "
                  "BayerRG8, software trigger at 10 Hz, auto exposure up to 20 ms)");
  cmd->add_option("--right", o->request.right, "without --config: the right camera");
  cmd->add_option("--out", o->request.out, "the recording folder to write (new or empty)");
  cmd->add_option("--frames", o->request.frames,
                  "stop once every camera has written this many frames")
      ->check(whole_count("a number of frames"));
  cmd->add_option("--duration", o->request.duration_s, "stop after this many seconds")
      ->check(seconds_within(0.001));
  cmd->add_option("--target", o->request.target,
                  "calibration assistance with this board (target YAML): the detector on a "
                  "decimated stream says which parts of the image, tilts and distances are "
                  "missing for the camera step's bars, refreshes OUT/coverage.png")
      ->check(CLI::ExistingFile);
  cmd->add_option("--bayer", o->request.bayer,
                  "the raw mosaic for the assistance's detector (default: from the pixel format)");
  cmd->add_flag("--fake", o->request.fake,
                "also see Aravis' in-process fake camera, Fake_1 (for trying)");
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::cli
