#include "rigcal/lidar/step.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "rigcal/core/error.h"
#include "rigcal/io/bag_scans.h"
#include "rigcal/io/image_sets.h"
#include "rigcal/io/ouster_metadata.h"
#include "rigcal/io/ouster_pcap.h"
#include "rigcal/io/point_cloud_io.h"
#include "rigcal/io/session.h"
#include "rigcal/report/svg_plot.h"

namespace rigcal::lidar {

namespace fs = std::filesystem;

namespace {

bool is_scan_topic(const fs::path& folder) {
  return fs::is_directory(folder / "data") && fs::exists(folder / "timestamps.txt");
}

// A KITTI odometry sequence: velodyne/ (its .bin scans) and times.txt.
bool is_kitti_sequence(const fs::path& folder) {
  return fs::is_directory(folder / "velodyne") && fs::is_regular_file(folder / "times.txt");
}

std::string scan_extension(const fs::path& folder, const std::string& files) {
  for (const fs::directory_entry& e : fs::directory_iterator(folder / files)) {
    if (e.path().extension() == ".bin") return ".bin";
    if (e.path().extension() == ".pcd") return ".pcd";
  }
  throw Error(fmt::format("{}: no .bin or .pcd scans in {}/", folder.string(), files));
}

io::StampedFolder stamped_scans(const fs::path& folder) {
  if (is_kitti_sequence(folder))
    return io::read_stamped_folder(folder, scan_extension(folder, "velodyne"), "velodyne",
                                   "times.txt");
  return io::read_stamped_folder(folder, scan_extension(folder, "data"));
}

}  // namespace

fs::path scans_folder(const fs::path& given, const report::Progress& progress) {
  if (fs::is_regular_file(given) && io::is_pcap_capture(given)) return given;  // read as it is
  if (fs::is_directory(given) && is_scan_topic(given) && !fs::exists(given / "ouster_points"))
    return given;
  if (is_kitti_sequence(given)) return given;
  if (is_scan_topic(given / "ouster_points")) return given / "ouster_points";
  // A bag, or a folder of bags, with a PointCloud2 topic: read as it streams. Bags of Ouster
  // packets only are converted with the session (below).
  if (const std::vector<fs::path> bags = io::ros1_bags_at(given);
      !bags.empty() && !io::scan_topic(bags).empty())
    return given;
  const io::Session s = io::read_session(given, progress);
  for (const fs::path& recording : {s.motion, s.lidar_camera}) {
    if (!recording.empty() && is_scan_topic(recording / "ouster_points"))
      return recording / "ouster_points";
  }
  throw Error(fmt::format(
      "{}: no scans (a folder with data/ and timestamps.txt, a recording with ouster_points/, "
      "a session whose motion or lidar_camera recording has one, or a KITTI sequence with "
      "velodyne/ and times.txt)",
      given.string()));
}

namespace {

// Keeps the step; stops the run when the odometry is lost.
void keep(OdometryRun& run, Step step, const std::string& source) {
  run.steps.push_back(std::move(step));
  size_t lost = 0;
  for (auto s = run.steps.rbegin(); s != run.steps.rend(); ++s, ++lost)
    if (s->skipped.rfind("no overlap", 0) != 0) break;
  if (lost >= kMaxScansLost) {
    throw Error(fmt::format(
        "{}: the odometry is lost: {} scans in a row share no surface with the map (the first "
        "stamped {} s, the last registered {}); a gap in the recording, or a blocked sensor",
        source, lost, to_seconds_text(run.steps[run.steps.size() - lost].stamp),
        run.steps.size() > lost
            ? to_seconds_text(run.steps[run.steps.size() - lost - 1].stamp) + " s"
            : "none"));
  }
}

}  // namespace

struct ScanStream::Impl {
  fs::path scans;
  std::unique_ptr<io::OusterPcapReader> capture;  // or the bags:
  std::unique_ptr<io::BagScanStream> bag;
  std::string bag_topic;  // or the folder:
  io::StampedFolder folder;
  size_t without_times = 0;
};

ScanStream::ScanStream(const fs::path& scans) : impl_(std::make_unique<Impl>()) {
  impl_->scans = scans;
  if (fs::is_regular_file(scans) && io::is_pcap_capture(scans)) {
    const fs::path json = fs::path(scans).replace_extension(".json");
    if (!fs::exists(json)) {
      throw Error(
          fmt::format("{}: the capture's metadata {} is not beside it (or convert first: "
                      "rigcal convert {} --metadata M.json --out RECORDING)",
                      scans.string(), json.filename().string(), scans.string()));
    }
    impl_->capture = std::make_unique<io::OusterPcapReader>(scans, io::read_ouster_metadata(json));
  } else if (const std::vector<fs::path> bags = io::ros1_bags_at(scans); !bags.empty()) {
    impl_->bag_topic = io::scan_topic(bags);
    if (impl_->bag_topic.empty()) {
      throw Error(
          fmt::format("{}: no sensor_msgs/PointCloud2 topic in the bags (Ouster packets: "
                      "rigcal convert them first)",
                      scans.string()));
    }
    impl_->bag = std::make_unique<io::BagScanStream>(bags, impl_->bag_topic);
  } else {
    impl_->folder = stamped_scans(scans);
  }
}

ScanStream::~ScanStream() = default;

std::optional<Scan> ScanStream::next() {
  if (impl_->capture) {
    std::optional<Scan> scan = impl_->capture->next_scan();
    read_ += scan.has_value();
    return scan;
  }
  if (impl_->bag) {
    std::optional<Scan> scan = impl_->bag->next();
    if (scan && scan->points.empty())
      throw Error(fmt::format("{}: no points", impl_->bag->source()));
    if (scan) impl_->without_times += !scan->point_times, ++read_;
    return scan;
  }
  if (read_ >= impl_->folder.files.size()) return std::nullopt;
  const std::string& file = impl_->folder.files[read_];
  Scan scan = io::read_scan(file);
  if (scan.points.empty()) throw Error(fmt::format("{}: no points", file));
  scan.stamp = impl_->folder.stamps[read_];
  impl_->without_times += !scan.point_times;
  ++read_;
  return scan;
}

size_t ScanStream::skip_before(Time stamp) {
  if (impl_->capture || impl_->bag) return 0;
  const size_t from = read_;
  while (read_ < impl_->folder.stamps.size() && impl_->folder.stamps[read_] < stamp) ++read_;
  return read_ - from;
}

size_t ScanStream::total() const {
  if (impl_->bag) return impl_->bag->total();
  return impl_->capture ? 0 : impl_->folder.files.size();
}

std::string ScanStream::source() const {
  if (impl_->bag) return impl_->bag->source();
  if (impl_->capture || read_ == 0) return impl_->scans.string();
  return impl_->folder.files[read_ - 1];
}

std::vector<std::string> ScanStream::notes() const {
  std::vector<std::string> out;
  if (impl_->capture) {
    const io::OusterCaptureCounters& c = impl_->capture->counters();
    out.push_back(
        fmt::format("capture read as it streams: {} frames complete, {} incomplete; "
                    "{} packets skipped{}{}",
                    c.frames_complete, c.frames_incomplete, c.skipped_total(),
                    c.note.empty() ? "" : "; ", c.note));
  }
  if (impl_->bag)
    out.push_back(fmt::format("bags read as they stream: topic {}", impl_->bag_topic));
  if (!impl_->capture && impl_->without_times > 0) {
    out.push_back(fmt::format(
        "{} of {} scans have no per-point times (KITTI points, PCD): they are used as measured, "
        "not deskewed",
        impl_->without_times, read_));
  }
  return out;
}

OdometryRun run_odometry(const fs::path& scans, const OdometryConfig& config,
                         const report::Progress& progress) {
  const auto started = std::chrono::steady_clock::now();
  OdometryRun run;
  run.scans = scans;
  run.config = config;
  Odometry odometry = start_odometry(config);
  ScanStream stream(scans);
  while (std::optional<Scan> scan = stream.next()) {
    keep(run, register_scan(odometry, *scan), stream.source());
    report::tell(progress, "odometry: scans read", stream.read(), stream.total());
  }
  for (const std::string& n : stream.notes()) run.notes.push_back(n);
  size_t skipped = 0;
  for (const Step& s : run.steps) skipped += !s.skipped.empty();
  if (skipped > 0) {
    run.notes.push_back(
        fmt::format("{} of {} scans skipped, without a pose (the report's rows say why)", skipped,
                    run.steps.size()));
  }
  run.T_odom_lidar = odometry.T_odom_lidar;
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return run;
}

std::vector<io::StepCovariance> step_covariances(const OdometryRun& run) {
  std::vector<io::StepCovariance> out;
  const Step* previous = nullptr;
  for (const Step& s : run.steps) {
    if (!s.skipped.empty()) continue;
    if (previous) out.push_back({previous->stamp, s.stamp, s.covariance_prev_cur});
    previous = &s;
  }
  return out;
}

nlohmann::json odometry_report(const OdometryRun& run) {
  const OdometryConfig& c = run.config;
  nlohmann::json j;
  j["step"] = "odometry";
  j["scans"] = run.scans.string();
  j["config"] = {{"voxel_size_m", c.voxel_size_m},
                 {"min_range_m", c.min_range_m},
                 {"max_range_m", c.max_range_m},
                 {"max_points_per_voxel", c.max_points_per_voxel},
                 {"initial_threshold_m", c.initial_threshold_m},
                 {"deskew", c.deskew},
                 {"deskew_passes", c.deskew_passes},
                 {"plane_neighbours", c.registration.plane_neighbours},
                 {"max_flatness", c.registration.max_flatness},
                 {"max_point_share", c.registration.max_point_share},
                 {"degenerate_ratio", c.degenerate_ratio},
                 {"degenerate_sigma_m", c.degenerate_sigma_m}};
  size_t degenerate = 0, widened = 0, not_converged = 0, skipped = 0;
  double step_seconds = 0, max_seconds = 0;
  nlohmann::json rows = nlohmann::json::array();
  bool first = true;
  for (const Step& s : run.steps) {
    step_seconds += s.seconds, max_seconds = std::max(max_seconds, s.seconds);
    if (!s.skipped.empty()) {
      ++skipped;
      rows.push_back({{"t", s.stamp.seconds()},
                      {"points_in", s.points_in},
                      {"correspondences", s.correspondences},
                      {"skipped", s.skipped},
                      {"seconds", s.seconds}});
      continue;
    }
    if (first) {  // the first registered scan starts the map: no motion
      first = false;
      continue;
    }
    degenerate += s.degeneracy.degenerate;
    widened += s.degeneracy.translation_widened;
    not_converged += !s.converged;
    const Degeneracy& d = s.degeneracy;
    rows.push_back(
        {{"t", s.stamp.seconds()},
         {"points_in", s.points_in},
         {"points_used", s.points_used},
         {"correspondences", s.correspondences},
         {"inlier_ratio", s.points_used ? double(s.correspondences) / s.points_used : 0},
         {"residual_rms_m", s.residual_rms_m},
         {"noise_sigma_m", s.noise_sigma_m},
         {"threshold_m", s.threshold_m},
         {"iterations", s.iterations},
         {"converged", s.converged},
         {"deskewed", s.deskewed},
         {"translation_sigma_max_m", d.translation_sigma_max_m},
         {"rotation_sigma_max_deg", d.rotation_sigma_max_deg},
         {"weakest_translation",
          {d.weakest_translation.x(), d.weakest_translation.y(), d.weakest_translation.z()}},
         {"translation_ratio", d.translation_ratio},
         {"translation_variance_ratio", d.translation_variance_ratio},
         {"rotation_ratio", d.rotation_ratio},
         {"degenerate", d.degenerate},
         {"translation_widened", d.translation_widened},
         {"seconds", s.seconds}});
  }
  j["summary"] = {
      {"scans", run.steps.size()},
      {"path_length_m", path_length(run.T_odom_lidar)},
      {"degenerate_steps", degenerate},
      {"widened_steps", widened},
      {"not_converged_steps", not_converged},
      {"skipped_scans", skipped},
      {"seconds", run.seconds},
      {"registration_seconds_mean", run.steps.empty() ? 0.0 : step_seconds / run.steps.size()},
      {"registration_seconds_max", max_seconds}};
  j["notes"] = run.notes;
  j["steps"] = rows;
  return j;
}

std::string choose_preset(const std::string& given, const rig::Sensor* lidar,
                          std::vector<std::string>& notes) {
  if (!given.empty()) return given;
  const std::string preset = lidar ? preset_for_model(lidar->model) : "";
  if (!preset.empty()) return preset;
  if (lidar && !lidar->model.empty()) {
    notes.push_back(
        fmt::format("odometry: the LiDAR's model '{}' names no preset; os0-128's is used (give "
                    "--odometry-preset)",
                    lidar->model));
  }
  return "os0-128";
}

std::vector<std::pair<std::string, std::string>> odometry_figures(const nlohmann::json& report) {
  const nlohmann::json& rows = report.at("steps");
  double t0 = 0;
  for (const nlohmann::json& r : rows) {
    t0 = r.at("t").get<double>();
    break;
  }
  // One series a key of the registered steps' rows, scaled, against the time since the first.
  auto series = [&](const std::string& label, const char* key, double scale, bool log10) {
    report::PlotSeries s{label, {}, {}, {}};
    for (const nlohmann::json& r : rows) {
      if (r.contains("skipped") || !r.contains(key)) continue;
      const double v = r.at(key).get<double>() * scale;
      if (log10 && !(v > 0)) continue;
      s.x.push_back(r.at("t").get<double>() - t0);
      s.y.push_back(log10 ? std::log10(v) : v);
    }
    return s;
  };
  const std::string x_label = "time since the first scan (s)";
  std::vector<std::pair<std::string, std::string>> out;
  auto add = [&](const std::string& file, const std::string& title, const std::string& y_label,
                 std::vector<report::PlotSeries> s) {
    report::Plot p;
    p.title = title, p.x_label = x_label, p.y_label = y_label, p.series = std::move(s);
    out.emplace_back(file, report::render_svg(p));
  };
  add("residuals.svg", "Point-to-plane residuals of each step", "mm",
      {series("rms of the correspondences", "residual_rms_m", 1e3, false),
       series("noise level (weighted)", "noise_sigma_m", 1e3, false)});
  add("inliers.svg", "Registration points with a map plane within the threshold",
      "fraction of the points used", {series("inlier ratio", "inlier_ratio", 1, false)});
  report::PlotSeries threshold = series("degenerate below", "translation_ratio", 1, true);
  const double ratio = report.at("config").value("degenerate_ratio", 0.01);
  for (double& y : threshold.y) y = std::log10(ratio);
  add("degeneracy.svg", "Weakest over strongest direction (1: even, small: degenerate)",
      "log10 ratio",
      {series("translation, information", "translation_ratio", 1, true),
       series("translation, covariance", "translation_variance_ratio", 1, true),
       series("rotation, information", "rotation_ratio", 1, true), threshold});
  add("timing.svg", "Wall time of each step", "ms", {series("step", "seconds", 1e3, false)});
  return out;
}

}  // namespace rigcal::lidar
