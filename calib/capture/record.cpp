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
#include "rigcal/core/stats.h"
#include "rigcal/core/text.h"
#include "rigcal/core/version.h"
#include "rigcal/io/files.h"
#include "rigcal/io/image_sets.h"

namespace rigcal::capture {
namespace {

using Clock = std::chrono::steady_clock;

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

size_t bytes_of(const Frame& f) { return f.image.total() * f.image.elemSize(); }

// The frames a camera's receiver hands its writer, and their bytes, bounded by `limit_bytes`.
struct FrameQueue {
  std::mutex mutex;
  std::condition_variable ready;
  std::deque<Frame> frames;
  bool closed = false;
  size_t limit_bytes = 0;
  size_t max_size = 0;
  size_t bytes = 0, max_bytes = 0;

  // The frame is queued whatever happens (it was received: it is written); false when the
  // frames waiting now hold more than the limit.
  bool push(Frame f) {
    bool within = true;
    {
      std::lock_guard lock(mutex);
      bytes += bytes_of(f);
      frames.push_back(std::move(f));
      max_size = std::max(max_size, frames.size());
      max_bytes = std::max(max_bytes, bytes);
      within = bytes <= limit_bytes;
    }
    ready.notify_one();
    return within;
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
    bytes -= bytes_of(f);
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
  std::mutex record_mutex;  // record's lists, between the receiver and the report
  std::atomic<size_t> trigger_failures{0};
  Assistant* assistant = nullptr;
  size_t index = 0;
  std::optional<uint64_t> last_id;  // the receiver's
  size_t queued = 0;                // the receiver's: frames handed to the writer
};

void account_id(Recorder& r, uint64_t id) {
  if (r.last_id) {
    const IdStep step = id_step(*r.last_id, id, r.gige);
    std::lock_guard lock(r.record_mutex);
    if (step.missing > 0) {
      r.record.gaps.push_back({static_cast<long>(r.queued) - 1, step.first_missing, step.missing});
      r.missing += step.missing;
    } else if (step.backwards) {
      r.record.id_restarts.push_back(fmt::format("{} after {}", id, *r.last_id));
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
    if (r.assistant) r.assistant->offer(r.index, e.frame.image);
    ++r.queued;
    if (!r.queue.push(std::move(e.frame))) {
      // The disk does not keep up: memory would grow until the system kills the recording.
      // Stopped here, everything received is still written.
      std::lock_guard lock(r.record_mutex);
      if (r.record.error.empty())
        r.record.error = fmt::format(
            "{}: the frames waiting to be written passed max_waiting_mb ({} MB) after {} frames, "
            "{} of them written: writing PNGs falls behind the camera (a slower disk or CPU than "
            "the frame rate needs); every frame received is written. Record to a faster disk, at "
            "a lower rate, or raise max_waiting_mb in the capture config",
            r.record.folder, r.queue.limit_bytes >> 20, r.queued, r.written.load());
      failed = true;
    }
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
  // What arrived before the stop is kept: the acquisition ends, then the buffers filled and those
  // still in transfer (until none for a quarter of a second, a second at most: a camera that
  // ignores the stop, as Aravis' fake interface's, would stream on) are taken.
  r.camera->stop_acquisition();
  const auto drain_end = Clock::now() + std::chrono::seconds(1);
  while (Clock::now() < drain_end && handle(r.camera->next(0.25))) {
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
    // Written under a name the session reader does not take (*.png), renamed once whole.
    const std::filesystem::path part = data / (name + ".tmp"), final = data / (name + ".png");
    bool ok = false;
    try {
      std::vector<uint8_t> png;
      ok = cv::imencode(".png", f.image, png, {cv::IMWRITE_PNG_COMPRESSION, 1});
      if (ok) {
        std::ofstream out(part, std::ios::binary);
        out.write(reinterpret_cast<const char*>(png.data()),
                  static_cast<std::streamsize>(png.size()));
        out.close();
        ok = out.good();
      }
      if (ok) std::filesystem::rename(part, final);
    } catch (const std::exception&) {
      ok = false;
    }
    const Time t = source == io::CaptureStamps::host ? f.host_stamp : f.device_stamp;
    if (ok && !r.record.stamps.empty() && t <= r.record.stamps.back()) {
      std::lock_guard lock(r.record_mutex);
      if (r.record.error.empty())
        r.record.error = fmt::format(
            "{}: the stamp of {} ({}) is not after the previous one: the {} clock went back "
            "(the host's clock stepped, or the camera restarted its own); the frames are kept, "
            "but the session reader refuses stamps that do not increase",
            r.record.folder, final.filename().string(), to_iso8601(t), io::to_string(source));
      failed = true;
    }
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
      std::filesystem::remove(final, ec);  // a file without its stamp would break the folder
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
  return d.empty() ? 0 : median(d);
}

// Mono or raw Bayer, 8 bits or unpacked in 16 (what camera.cpp writes as it comes).
bool recordable_pixel_format(const std::string& f) {
  std::string bits;
  if (f.rfind("Mono", 0) == 0)
    bits = f.substr(4);
  else if (f.rfind("Bayer", 0) == 0 && f.size() > 7)
    bits = f.substr(7);
  else
    return false;
  return bits == "8" || bits == "10" || bits == "12" || bits == "14" || bits == "16";
}

}  // namespace

IdStep id_step(uint64_t previous, uint64_t id, bool gige16) {
  IdStep s;
  if (gige16) {
    // 1..65535, 0 never used: positions 0..65534 on a circle. A step back of under half the
    // circle is the camera restarting its count, not 65,000 frames lost.
    constexpr uint64_t n = 65535;
    const uint64_t a = (previous + n - 1) % n, b = (id + n - 1) % n;
    const uint64_t forward = (b + n - a) % n;
    if (forward == 0 || forward > n / 2) {
      s.backwards = true;
      return s;
    }
    s.missing = forward - 1;
    s.first_missing = previous % n + 1;
  } else {
    if (id <= previous) {
      s.backwards = true;
      return s;
    }
    s.missing = id - previous - 1;
    s.first_missing = previous + 1;
  }
  return s;
}

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
    set({"AcquisitionFrameRate", "AcquisitionFrameRateAbs"}, format_double(c.frame_rate_hz),
        c.frame_rate_given, fmt::format("frame_rate_hz: {}", format_double(c.frame_rate_hz)));
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
    const std::string why = fmt::format("exposure_us: {}", format_double(*c.exposure_us));
    if (camera.has("ExposureAuto")) set({"ExposureAuto"}, "Off", false, why);
    set({"ExposureTime", "ExposureTimeAbs"}, format_double(*c.exposure_us), true, why);
  } else {
    const std::string why = c.exposure_given ? "exposure_us: auto" : "exposure_us: auto (default)";
    if (set({"ExposureAuto"}, "Continuous", c.exposure_given, why))
      set({"ExposureAutoMax", "AutoExposureTimeAbsMax", "ExposureAutoUpperLimit",
           "AutoExposureTimeUpperLimit"},
          format_double(c.exposure_auto_max_us), c.exposure_auto_max_given,
          fmt::format("exposure_auto_max_us: {}{}", format_double(c.exposure_auto_max_us),
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
  if (!recordable_pixel_format(format))
    throw Error(fmt::format(
        "{} ({}): pixel format {} is not recorded (packed, colour or YUV): give pixel_format one "
        "of Mono8/10/12/14/16 or Bayer..8/10/12/14/16 the camera has ({})",
        c.folder, describe(camera.info()), format, fmt::join(camera.info().pixel_formats, " ")));
  // Colour formats were refused above: a raw mosaic is the colour camera here.
  if (c.balance_white_given || !bayer_pattern(format).empty())
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
    r->queue.limit_bytes = static_cast<size_t>(o.config.max_waiting_mb) << 20;
    if (o.on_configured) o.on_configured(c, *cameras.back());
    recorders.push_back(std::move(r));
  }
  io::FolderLock lock(o.out);
  for (const auto& r : recorders) fs::create_directories(o.out / r->record.folder / "data");
  std::unique_ptr<Assistant> assistant;
  if (o.assist) {
    AssistOptions a = *o.assist;
    if (a.png.empty()) a.png = o.out / "coverage.png";
    if (a.bayer == io::Bayer::none) {
      const std::string pattern = bayer_pattern(recorders.front()->record.pixel_format);
      if (!pattern.empty()) a.bayer = io::bayer_from_string(pattern);
    }
    std::vector<std::string> folders;
    for (const auto& r : recorders) folders.push_back(r->record.folder);
    assistant = std::make_unique<Assistant>(a, folders);
    for (size_t i = 0; i < recorders.size(); ++i) {
      recorders[i]->assistant = assistant.get();
      recorders[i]->index = i;
    }
  }

  std::atomic<bool> stop{false}, failed{false};
  try {
    for (auto& c : cameras) c->start(o.config.buffers);
  } catch (...) {
    for (auto& c : cameras) c->stop();
    // Nothing was recorded: the folders made for it go, so the same command can run again.
    std::error_code ec;
    for (const auto& r : recorders) fs::remove_all(o.out / r->record.folder, ec);
    throw;
  }
  const auto start = Clock::now();
  std::vector<std::thread> threads;
  for (auto& r : recorders) {
    // A thread that throws (out of memory) ends its camera's recording with the reason.
    auto guarded = [&r, &failed](auto body) {
      return [&r, &failed, body] {
        try {
          body();
        } catch (const std::exception& e) {
          std::lock_guard lock(r->record_mutex);
          if (r->record.error.empty())
            r->record.error = fmt::format("{}: recording stopped: {}", r->record.folder, e.what());
          failed = true;
          r->queue.close();
        }
      };
    };
    threads.emplace_back(guarded([&r, &stop, &failed] { receive(*r, stop, failed); }));
    threads.emplace_back(guarded([&r, &o, &failed] {
      write_frames(*r, o.out / r->record.folder, o.config.stamps, failed);
    }));
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
      auto sleep_until = [&](Clock::time_point t) {
        while (!stop && Clock::now() < t)
          std::this_thread::sleep_for(
              std::min<Clock::duration>(t - Clock::now(), std::chrono::milliseconds(10)));
      };
      sleep_until(next);
      while (!stop && (!o.frames || triggers < *o.frames)) {
        for (auto& r : recorders)
          if (r->record.trigger == "Software" && !r->camera->software_trigger())
            ++r->trigger_failures;
        ++triggers;
        next += std::chrono::duration_cast<Clock::duration>(period);
        sleep_until(next);
      }
    });

  auto last_progress = start;
  size_t settled_at_count = 0;
  auto settled_since = start;
  // Whatever the loop throws (a progress callback's broken terminal), the threads stop and join
  // first and what was received is written.
  std::exception_ptr thrown;
  try {
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
          all = all && r->written >= *o.frames;
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
      if (now - last_progress >= std::chrono::seconds(1)) {
        last_progress = now;
        if (assistant && o.on_coverage) o.on_coverage(assistant->coverage());
        RecordProgress p;
        p.seconds = elapsed;
        for (auto& r : recorders) {
          p.written.push_back(r->written);
          p.missing.push_back(r->missing);
        }
        if (o.progress) o.progress(p);
      }
    }
  } catch (...) {
    thrown = std::current_exception();
    run.stopped_by = "error";
  }
  stop = true;
  if (trigger.joinable()) trigger.join();
  for (std::thread& t : threads) t.join();
  run.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (assistant) run.coverage = assistant->coverage();
  assistant.reset();
  if (thrown) std::rethrow_exception(thrown);

  for (auto& r : recorders) {
    r->record.written = r->written;
    r->record.missing = r->missing;
    r->record.max_queue = r->queue.max_size;
    r->record.max_waiting_mb = static_cast<double>(r->queue.max_bytes) / (1 << 20);
    if (r->record.trigger == "Software") {
      r->record.triggers_sent = triggers - r->trigger_failures;
      r->record.trigger_failures = r->trigger_failures;
    }
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
         {"max_waiting_mb", c.max_waiting_mb},
         {"error", c.error}});
  }
  json coverage = json::array();
  for (const CameraCoverage& c : run.coverage)
    coverage.push_back({{"folder", c.folder},
                        {"frames_looked_at", c.looked_at},
                        {"views", c.views},
                        {"image_covered", c.covered},
                        {"empty_zones", c.empty_zones},
                        {"solved", c.solved},
                        {"focal_px", c.focal_px},
                        {"focal_relative_sigma", c.focal_rel_sigma},
                        {"principal_point_sigma_px", c.principal_sigma_px},
                        {"tilt_about_x_deg", {c.tilt_x_min_deg, c.tilt_x_max_deg}},
                        {"tilt_about_y_deg", {c.tilt_y_min_deg, c.tilt_y_max_deg}},
                        {"distance_m", {c.distance_min_m, c.distance_max_m}},
                        {"worst_projection_sigma_px", c.worst_projection_sigma_px},
                        {"worst_projection_at_px", {c.worst_at.x, c.worst_at.y}},
                        {"missing", c.missing}});
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
          {"max_pair_stamp_difference_s", run.max_pair_difference_s},
          {"assistance", coverage}};
}

}  // namespace rigcal::capture
