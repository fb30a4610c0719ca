#include "rigcal/capture/record.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <ctime>
#include <deque>
#include <fstream>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "rigcal/core/error.h"
#include "rigcal/core/version.h"
#include "rigcal/io/files.h"
#include "rigcal/io/image_sets.h"

namespace rigcal::capture {
namespace {

using Clock = std::chrono::steady_clock;

std::string number_text(double x) { return fmt::format("{}", x); }

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

bool is_colour_mosaic(const std::string& pixel_format) {
  return pixel_format.rfind("Bayer", 0) == 0 || pixel_format.rfind("RGB", 0) == 0 ||
         pixel_format.rfind("BGR", 0) == 0;
}

// The frames a camera's receiver hands its writer.
struct FrameQueue {
  std::mutex mutex;
  std::condition_variable ready;
  std::deque<Frame> frames;
  bool closed = false;
  size_t max_size = 0;

  void push(Frame f) {
    {
      std::lock_guard lock(mutex);
      frames.push_back(std::move(f));
      max_size = std::max(max_size, frames.size());
    }
    ready.notify_one();
  }
  void close() {
    {
      std::lock_guard lock(mutex);
      closed = true;
    }
    ready.notify_all();
  }
  // False once closed and empty.
  bool pop(Frame& f) {
    std::unique_lock lock(mutex);
    ready.wait(lock, [&] { return closed || !frames.empty(); });
    if (frames.empty()) return false;
    f = std::move(frames.front());
    frames.pop_front();
    return true;
  }
};

// Everything a camera's two threads share with the recorder.
struct Recorder {
  Camera* camera = nullptr;
  CameraRecord record;
  bool gige = false;
  FrameQueue queue;
  std::atomic<size_t> received{0};  // frames and damaged buffers
  std::atomic<size_t> written{0};
  std::atomic<uint64_t> missing{0};
  std::mutex record_mutex;          // record's lists, between the receiver and the report
  std::optional<uint64_t> last_id;  // the receiver's
  size_t queued = 0;                // the receiver's: frames handed to the writer
};

// The ids between the last one seen and `id` (GigE Vision ids are 16 bits and skip 0).
void account_id(Recorder& r, uint64_t id) {
  if (r.last_id) {
    const uint64_t modulus = r.gige ? 65535 : 0;
    uint64_t step = 0;
    if (modulus) {
      const uint64_t prev = (*r.last_id - 1) % modulus, now = (id + modulus - 1) % modulus;
      step = (now + modulus - prev) % modulus;
    } else {
      step = id > *r.last_id ? id - *r.last_id : 0;
    }
    if (step > 1) {
      std::lock_guard lock(r.record_mutex);
      const uint64_t first = r.gige ? (*r.last_id % 65535) + 1 : *r.last_id + 1;
      r.record.gaps.push_back({static_cast<long>(r.queued) - 1, first, step - 1});
      r.missing += step - 1;
    }
  }
  r.last_id = id;
}

void receive(Recorder& r, const std::atomic<bool>& stop, std::atomic<bool>& failed) {
  const double cpu0 = thread_cpu_seconds();
  auto handle = [&](StreamEvent e) {
    if (e.kind == StreamEvent::Kind::timeout) return false;
    ++r.received;
    if (e.kind == StreamEvent::Kind::incomplete) {
      account_id(r, e.frame_id);
      std::lock_guard lock(r.record_mutex);
      ++r.record.incomplete;
      if (r.record.incomplete_statuses.size() < 100)
        r.record.incomplete_statuses.push_back(fmt::format("{}: {}", e.frame_id, e.status));
      return true;
    }
    account_id(r, e.frame.frame_id);
    ++r.queued;
    r.queue.push(std::move(e.frame));
    return true;
  };
  while (!stop) {
    handle(r.camera->next(0.1));
    if (r.camera->lost()) {
      std::lock_guard lock(r.record_mutex);
      r.record.error = fmt::format("{} ({}) was lost mid-stream after {} frames", r.record.folder,
                                   describe(r.record.info), r.received.load());
      failed = true;
      break;
    }
  }
  // What arrived before the stop is kept: the buffers already filled, then the acquisition ends.
  while (handle(r.camera->next(0.0))) {
  }
  r.camera->stop();
  r.queue.close();
  r.record.receive_cpu_s = thread_cpu_seconds() - cpu0;
}

void write_frames(Recorder& r, const std::filesystem::path& folder, io::CaptureStamps source,
                  std::atomic<bool>& failed) {
  const double cpu0 = thread_cpu_seconds();
  const std::filesystem::path data = folder / "data";
  std::ofstream stamps(folder / "timestamps.txt", std::ios::app);
  std::ofstream frames(folder / "frames.csv", std::ios::app);
  frames << "# file, the camera's frame id, the camera's stamp (ns), the host's stamp (ns)\n";
  frames.flush();
  Frame f;
  while (r.queue.pop(f)) {
    const size_t index = r.written.load();
    const std::string name = fmt::format("{:010d}", index);
    const std::filesystem::path part = data / (name + ".part.png"), final = data / (name + ".png");
    bool ok = false;
    try {
      ok = cv::imwrite(part.string(), f.image, {cv::IMWRITE_PNG_COMPRESSION, 1});
      if (ok) std::filesystem::rename(part, final);
    } catch (const std::exception&) {
      ok = false;
    }
    const Time t = source == io::CaptureStamps::host ? f.host_stamp : f.device_stamp;
    if (ok) {
      stamps << to_iso8601(t) << '\n';
      frames << name << ".png," << f.frame_id << ',' << f.device_stamp.ns << ',' << f.host_stamp.ns
             << '\n';
      stamps.flush();
      frames.flush();
      ok = stamps.good() && frames.good();
    }
    if (!ok) {
      std::error_code ec;
      std::filesystem::remove(part, ec);
      std::lock_guard lock(r.record_mutex);
      if (r.record.error.empty())
        r.record.error = fmt::format(
            "{}: could not write {} (disk full or not writable); the "
            "{} frames before it are kept",
            r.record.folder, final.string(), index);
      failed = true;
      break;
    }
    {
      std::lock_guard lock(r.record_mutex);
      r.record.stamps.push_back(t);
      r.record.host_stamps.push_back(f.host_stamp);
    }
    ++r.written;
  }
  // After a failed write the receiver may still hand frames: drain them (they cannot be kept).
  while (r.queue.pop(f)) {
  }
  r.record.write_cpu_s = thread_cpu_seconds() - cpu0;
}

double median_interval_s(const std::vector<Time>& stamps) {
  std::vector<double> d;
  for (size_t i = 1; i < stamps.size(); ++i) d.push_back((stamps[i] - stamps[i - 1]).seconds());
  if (d.empty()) return 0;
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

}  // namespace

std::string bayer_pattern(const std::string& pixel_format) {
  if (pixel_format.rfind("Bayer", 0) != 0 || pixel_format.size() < 7) return "";
  const std::string first = pixel_format.substr(5, 2);
  if (first == "RG") return "rggb";
  if (first == "BG") return "bggr";
  if (first == "GR") return "grbg";
  if (first == "GB") return "gbrg";
  return "";
}

std::vector<FeatureResult> configure(Camera& camera, const io::CaptureCameraConfig& c) {
  std::vector<FeatureResult> out;
  auto set = [&](std::vector<std::string> names, const std::string& value, bool required,
                 const std::string& why) {
    out.push_back(camera.set(names, value, required, why));
    return out.back().status == FeatureResult::Status::set ||
           out.back().status == FeatureResult::Status::adjusted;
  };
  if (c.region) {
    const auto& [x, y, w, h] = *c.region;
    const std::string why = fmt::format("region: [{}, {}, {}, {}]", x, y, w, h);
    if (camera.has("OffsetX")) set({"OffsetX"}, "0", false, why);
    if (camera.has("OffsetY")) set({"OffsetY"}, "0", false, why);
    set({"Width"}, std::to_string(w), true, why);
    set({"Height"}, std::to_string(h), true, why);
    set({"OffsetX"}, std::to_string(x), x != 0, why);
    set({"OffsetY"}, std::to_string(y), y != 0, why);
  }
  set({"PixelFormat"}, c.pixel_format, c.pixel_format_given,
      c.pixel_format_given ? "pixel_format: " + c.pixel_format
                           : "pixel_format (default: raw Bayer, as VBR records)");
  const std::string trigger_why =
      c.trigger_given ? "trigger: " + c.trigger : "trigger (default: Software)";
  const bool free_running = c.trigger == "off";
  // The rate first: on some cameras (and Aravis' simulator) setting it turns the triggers off.
  if (free_running) {
    if (camera.has("AcquisitionFrameRateEnable"))
      set({"AcquisitionFrameRateEnable"}, "true", false, "frame_rate_hz");
    set({"AcquisitionFrameRate", "AcquisitionFrameRateAbs"}, number_text(c.frame_rate_hz),
        c.frame_rate_given, fmt::format("frame_rate_hz: {}", number_text(c.frame_rate_hz)));
  }
  if (camera.has("TriggerSelector")) set({"TriggerSelector"}, "FrameStart", false, trigger_why);
  set({"TriggerMode"}, free_running ? "Off" : "On", c.trigger_given || !free_running, trigger_why);
  if (!free_running) {
    set({"TriggerSource"}, c.trigger, true, trigger_why);
    if (c.trigger != "Software")
      set({"TriggerActivation"}, c.trigger_activation.value_or("RisingEdge"),
          c.trigger_activation.has_value(),
          "trigger_activation: " + c.trigger_activation.value_or("RisingEdge (default)"));
  }
  if (c.exposure_us) {
    const std::string why = fmt::format("exposure_us: {}", number_text(*c.exposure_us));
    if (camera.has("ExposureAuto")) set({"ExposureAuto"}, "Off", false, why);
    set({"ExposureTime", "ExposureTimeAbs"}, number_text(*c.exposure_us), true, why);
  } else {
    const std::string why = c.exposure_given ? "exposure_us: auto" : "exposure_us: auto (default)";
    if (set({"ExposureAuto"}, "Continuous", c.exposure_given, why))
      set({"ExposureAutoMax", "AutoExposureTimeAbsMax", "ExposureAutoUpperLimit",
           "AutoExposureTimeUpperLimit"},
          number_text(c.exposure_auto_max_us), c.exposure_auto_max_given,
          fmt::format("exposure_auto_max_us: {}{}", number_text(c.exposure_auto_max_us),
                      c.exposure_auto_max_given ? "" : " (default)"));
  }
  if (c.gain) {
    const std::string why = "gain: " + *c.gain;
    if (*c.gain == "auto") {
      set({"GainAuto"}, "Continuous", true, why);
    } else {
      if (camera.has("GainAuto")) set({"GainAuto"}, "Off", false, why);
      set({"Gain", "GainRaw"}, *c.gain, true, why);
    }
  }
  const std::string format = camera.get("PixelFormat").value_or(c.pixel_format);
  if (c.balance_white_given || is_colour_mosaic(format))
    set({"BalanceWhiteAuto"}, c.balance_white == "auto" ? "Continuous" : "Off",
        c.balance_white_given,
        "balance_white: " + c.balance_white + (c.balance_white_given ? "" : " (default)"));
  for (const auto& [name, value] : c.features) set({name}, value, true, "features: " + name);

  std::string failures;
  for (const FeatureResult& r : out) {
    if (!r.required ||
        (r.status != FeatureResult::Status::absent && r.status != FeatureResult::Status::refused))
      continue;
    std::string detail;
    if (r.status == FeatureResult::Status::refused) {
      std::vector<std::string> parts;
      if (!r.camera_says.empty()) parts.push_back("Aravis: " + r.camera_says);
      if (!r.accepted.empty() && r.accepted != r.asked)
        parts.push_back("it reads back '" + r.accepted + "'");
      detail = fmt::format(" '{}'{}", r.asked,
                           parts.empty() ? "" : fmt::format(" ({})", fmt::join(parts, "; ")));
    }
    failures += fmt::format("; feature {} {}{}, asked by {}", r.feature, to_string(r.status),
                            detail, r.why);
  }
  if (!failures.empty())
    throw Error(fmt::format("{} ({}): {}", c.folder, describe(camera.info()), failures.substr(2)));
  return out;
}

CaptureRun record(const RecordOptions& o) {
  namespace fs = std::filesystem;
  CaptureRun run;
  run.out = o.out;
  run.config = o.config;
  if (o.config.cameras.empty()) throw Error("capture: no camera to record");
  if (fs::exists(o.out) && !(fs::is_directory(o.out) && fs::is_empty(o.out)))
    throw Error(
        fmt::format("{}: exists and is not an empty folder (a recording is never "
                    "written over)",
                    o.out.string()));
  double software_rate = 0;
  for (const io::CaptureCameraConfig& c : o.config.cameras)
    if (c.trigger == "Software") {
      if (software_rate > 0 && c.frame_rate_hz != software_rate)
        throw Error(
            fmt::format("capture: the software-triggered cameras need one frame_rate_hz "
                        "(they are triggered together), got {} and {}",
                        software_rate, c.frame_rate_hz));
      software_rate = c.frame_rate_hz;
    }

  // Open and configure all before anything is written.
  std::vector<std::unique_ptr<Camera>> cameras;
  std::vector<std::unique_ptr<Recorder>> recorders;
  for (const io::CaptureCameraConfig& c : o.config.cameras) {
    cameras.push_back(std::make_unique<Camera>(c.id));
    auto r = std::make_unique<Recorder>();
    r->camera = cameras.back().get();
    r->record.folder = c.folder;
    r->record.info = cameras.back()->info();
    r->record.features = configure(*cameras.back(), c);
    r->record.pixel_format = cameras.back()->get("PixelFormat").value_or("");
    r->record.trigger = c.trigger;
    r->gige = r->record.info.protocol == "GigEVision";
    if (o.on_configured) o.on_configured(c, *cameras.back());
    recorders.push_back(std::move(r));
  }
  io::FolderLock lock(o.out);
  for (const auto& r : recorders) fs::create_directories(o.out / r->record.folder / "data");

  std::atomic<bool> stop{false}, failed{false};
  for (auto& c : cameras) c->start(o.config.buffers);
  const auto start = Clock::now();
  std::vector<std::thread> threads;
  for (auto& r : recorders) {
    threads.emplace_back([&r, &stop, &failed] { receive(*r, stop, failed); });
    threads.emplace_back(
        [&r, &o, &failed] { write_frames(*r, o.out / r->record.folder, o.config.stamps, failed); });
  }
  // Software triggers: every software-triggered camera at once, at the configured rate.
  std::thread trigger;
  std::atomic<size_t> triggers{0};
  if (software_rate > 0)
    trigger = std::thread([&] {
      const auto period = std::chrono::duration<double>(1.0 / software_rate);
      // A camera may not stream at once when its acquisition starts: Aravis' simulator starts
      // up to half a second later and makes one frame of the triggers sent before. The first
      // trigger half a second after the start.
      auto next = Clock::now() + std::chrono::milliseconds(500);
      std::this_thread::sleep_until(next);
      while (!stop && (!o.frames || triggers < *o.frames)) {
        for (auto& r : recorders)
          if (r->record.trigger == "Software") r->camera->software_trigger();
        ++triggers;
        next += std::chrono::duration_cast<Clock::duration>(period);
        std::this_thread::sleep_until(next);
      }
    });

  auto last_progress = start;
  size_t settled_at_count = 0;
  auto settled_since = start;
  while (true) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const auto now = Clock::now();
    const double elapsed = std::chrono::duration<double>(now - start).count();
    if (failed) {
      run.stopped_by = "error";
      break;
    }
    if (o.interrupt && *o.interrupt) {
      run.stopped_by = "interrupt";
      break;
    }
    if (o.duration_s && elapsed >= *o.duration_s) {
      run.stopped_by = "duration";
      break;
    }
    if (o.frames) {
      bool all = true;
      size_t total = 0;
      for (auto& r : recorders) {
        all = all && r->received >= *o.frames;
        total += r->received;
      }
      if (all) {
        run.stopped_by = "frames";
        break;
      }
      // Every software trigger sent and nothing more arriving for a second: the frames the
      // cameras dropped will not come.
      if (software_rate > 0 && triggers >= *o.frames) {
        if (total != settled_at_count) {
          settled_at_count = total;
          settled_since = now;
        } else if (now - settled_since > std::chrono::seconds(1)) {
          run.stopped_by = "frames";
          break;
        }
      }
    }
    if (o.progress && now - last_progress >= std::chrono::seconds(1)) {
      last_progress = now;
      RecordProgress p;
      p.seconds = elapsed;
      for (auto& r : recorders) {
        p.written.push_back(r->written);
        p.missing.push_back(r->missing);
      }
      o.progress(p);
    }
  }
  stop = true;
  if (trigger.joinable()) trigger.join();
  for (std::thread& t : threads) t.join();
  run.seconds = std::chrono::duration<double>(Clock::now() - start).count();

  for (auto& r : recorders) {
    r->record.written = r->written;
    r->record.missing = r->missing;
    r->record.max_queue = r->queue.max_size;
    if (r->record.trigger == "Software") r->record.triggers_sent = triggers;
    if (!r->record.error.empty() && run.error.empty()) run.error = r->record.error;
    run.cameras.push_back(std::move(r->record));
  }
  if (run.cameras.size() == 2) {
    const auto& a = run.cameras[0].stamps;
    const auto& b = run.cameras[1].stamps;
    const double interval = std::max(median_interval_s(a), median_interval_s(b));
    const Time tolerance = Time::from_seconds(interval > 0 ? interval / 2 : 0.005);
    const auto pairs = io::pair_by_stamp(a, b, tolerance);
    for (size_t i = 0; i < pairs.size(); ++i)
      if (pairs[i]) {
        ++run.pairs;
        run.max_pair_difference_s =
            std::max(run.max_pair_difference_s, std::abs((a[i] - b[*pairs[i]]).seconds()));
      }
  }
  const nlohmann::json report = capture_report(run);
  io::write_file_atomic(o.out / "capture.json", report.dump(1) + "\n");
  return run;
}

nlohmann::json capture_report(const CaptureRun& run) {
  using nlohmann::json;
  json cameras = json::array();
  for (const CameraRecord& c : run.cameras) {
    json features = json::array();
    for (const FeatureResult& f : c.features)
      features.push_back({{"feature", f.feature},
                          {"asked", f.asked},
                          {"accepted", f.accepted},
                          {"status", std::string(to_string(f.status))},
                          {"required", f.required},
                          {"why", f.why}});
    json gaps = json::array();
    for (const FrameGap& g : c.gaps)
      gaps.push_back({{"after_file", g.after_file}, {"first_id", g.first_id}, {"count", g.count}});
    const double span = c.stamps.size() > 1 ? (c.stamps.back() - c.stamps.front()).seconds() : 0;
    cameras.push_back(
        {{"folder", c.folder},
         {"id", c.info.id},
         {"vendor", c.info.vendor},
         {"model", c.info.model},
         {"serial", c.info.serial},
         {"address", c.info.address},
         {"protocol", c.info.protocol},
         {"pixel_format", c.pixel_format},
         {"bayer", bayer_pattern(c.pixel_format)},
         {"trigger", c.trigger},
         {"features", features},
         {"frames_written", c.written},
         {"frames_incomplete", c.incomplete},
         {"incomplete", c.incomplete_statuses},
         {"frames_missing", c.missing},
         {"gaps", gaps},
         {"software_triggers_sent", c.triggers_sent},
         {"first_stamp", c.stamps.empty() ? "" : to_iso8601(c.stamps.front())},
         {"last_stamp", c.stamps.empty() ? "" : to_iso8601(c.stamps.back())},
         {"frames_per_second", span > 0 ? static_cast<double>(c.stamps.size() - 1) / span : 0.0},
         {"receive_cpu_s", c.receive_cpu_s},
         {"write_cpu_s", c.write_cpu_s},
         {"cpu_percent_of_a_core",
          run.seconds > 0 ? 100 * (c.receive_cpu_s + c.write_cpu_s) / run.seconds : 0.0},
         {"max_frames_waiting", c.max_queue},
         {"error", c.error}});
  }
  return {{"tool", "rigcal capture"},
          {"version", version_string()},
          {"stamps", std::string(io::to_string(run.config.stamps))},
          {"stamps_explained",
           run.config.stamps == io::CaptureStamps::host
               ? "the host's clock (UTC) when Aravis received the frame"
               : "the camera's own clock as it reports it (ns; its epoch is the camera's: PTP "
                 "time on synchronised cameras, else time since power on)"},
          {"seconds", run.seconds},
          {"stopped_by", run.stopped_by},
          {"error", run.error},
          {"cameras", cameras},
          {"pairs", run.pairs},
          {"max_pair_stamp_difference_s", run.max_pair_difference_s}};
}

}  // namespace rigcal::capture
