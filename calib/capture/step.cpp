#include "rigcal/capture/step.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "rigcal/core/error.h"
#include "rigcal/io/target_yaml.h"

namespace rigcal::capture {

RecordOptions record_options(const CaptureRequest& r, const std::atomic<bool>* interrupt) {
  if (r.out.empty()) throw Error("capture: --out is needed (the recording folder to write)");
  RecordOptions o;
  if (!r.config.empty()) {
    if (!r.left.empty() || !r.right.empty())
      throw Error("capture: give the cameras in --config or by --left/--right, not both");
    o.config = io::read_capture_config(r.config);
  } else {
    if (r.left.empty() && r.right.empty())
      throw Error("capture: no camera: give --config FILE, or --left ID (and --right ID)");
    for (const auto& [folder, id] : {std::pair{"camera_left", r.left}, {"camera_right", r.right}})
      if (!id.empty()) {
        io::CaptureCameraConfig c;
        c.folder = folder;
        c.id = id;
        o.config.cameras.push_back(c);
      }
  }
  if (r.fake) enable_fake_interface();
  o.out = r.out;
  if (r.frames && *r.frames > 0) o.frames = r.frames;  // 0: no limit, as --frames 0 says
  o.duration_s = r.duration_s;
  o.interrupt = interrupt;
  if (!r.target.empty()) {
    AssistOptions assist;
    assist.target = io::read_target_file(r.target);
    assist.bayer = io::bayer_from_string(r.bayer);
    o.assist = assist;
  }
  return o;
}

std::vector<std::string> camera_list_lines(bool include_fake) {
  const auto cameras = list_cameras(true, include_fake);
  if (cameras.empty()) return {"no camera found (GigE Vision on every interface, USB3 Vision)"};
  std::vector<std::string> out;
  for (const CameraInfo& c : cameras) {
    out.push_back(c.id);
    out.push_back(fmt::format("  vendor {}, model {}, serial {}, address {}, {}", c.vendor, c.model,
                              c.serial, c.address, c.protocol));
    out.push_back("  pixel formats: " +
                  (c.pixel_formats.empty()
                       ? std::string("(not read: the camera could not be opened)")
                       : fmt::format("{}", fmt::join(c.pixel_formats, " "))));
  }
  return out;
}

std::string progress_line(const RecordProgress& p, const io::CaptureConfig& config) {
  std::string line = fmt::format("{:.0f} s:", p.seconds);
  for (size_t i = 0; i < p.written.size() && i < config.cameras.size(); ++i)
    line += fmt::format(" {} {} frames{}", config.cameras[i].folder, p.written[i],
                        p.missing[i] ? fmt::format(" ({} missing)", p.missing[i]) : "");
  return line;
}

std::vector<std::string> summary_lines(const CaptureRun& run) {
  std::vector<std::string> out;
  for (const CameraRecord& c : run.cameras) {
    out.push_back(fmt::format("{}: {} ({} {}, {}), {}, trigger {}", c.folder, c.info.id,
                              c.info.vendor, c.info.model, c.info.address, c.pixel_format,
                              c.trigger));
    for (const FeatureResult& f : c.features)
      out.push_back(fmt::format(
          "  {:<26} {:<9} {}{}  ({})", f.feature, to_string(f.status),
          f.accepted.empty() ? f.asked : f.accepted,
          f.status == FeatureResult::Status::adjusted ? " (asked " + f.asked + ")" : "", f.why));
    out.push_back(
        fmt::format("  {} frames written, {} missing (gaps in the frame ids: {}), {} incomplete{}",
                    c.written, c.missing, c.gaps.size(), c.incomplete,
                    c.triggers_sent ? fmt::format(", {} software triggers", c.triggers_sent) : ""));
  }
  if (run.cameras.size() == 2) {
    out.push_back(fmt::format("pairs by trigger: {} (stamps within {:.2f} ms of each other)",
                              run.pairs, 1e3 * run.max_pair_difference_s));
    if (run.pairs == 0)
      out.push_back(
          "note: no frame of one camera has a frame of the other within half a frame "
          "interval: with stamps: camera, the cameras' clocks must be synchronised (PTP)");
    else if (run.max_pair_difference_s > 0.005)
      out.push_back(
          "note: rigcal calibrate pairs the cameras' images within 5 ms: pairs further "
          "apart are left out (host stamps differ by the frames' transfer; cameras' own "
          "clocks agree only when synchronised, PTP)");
  }
  const std::string out_dir = run.out.string();
  out.push_back(
      fmt::format("stopped by {} after {:.1f} s; wrote {} (the session layout) and {}/capture.json",
                  run.stopped_by, run.seconds, out_dir, out_dir));
  for (const std::string& line : Assistant::lines(run.coverage)) out.push_back(line);
  if (!run.coverage.empty())
    out.push_back(fmt::format("the views' coverage: {}/coverage.png", out_dir));
  const std::string bayer = run.cameras.empty() ? "" : bayer_pattern(run.cameras[0].pixel_format);
  if (!bayer.empty())
    out.push_back(
        fmt::format("raw {} mosaics: calibrate with `rigcal calibrate --session {} --bayer {} ...`",
                    run.cameras[0].pixel_format, out_dir, bayer));
  return out;
}

}  // namespace rigcal::capture
