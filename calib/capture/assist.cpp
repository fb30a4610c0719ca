#include "rigcal/capture/assist.h"

#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "rigcal/camera/calibrate.h"
#include "rigcal/camera/detect.h"
#include "rigcal/camera/uncertainty.h"
#include "rigcal/core/error.h"
#include "rigcal/core/stats.h"
#include "rigcal/io/files.h"

namespace rigcal::capture {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kDeg = 180.0 / M_PI;

struct CameraState {
  CameraCoverage coverage;
  cv::Mat pending;  // the frame offered, not looked at yet
  bool has_pending = false;
  Clock::time_point last_taken{};
  cv::Mat last_gray;
  std::vector<camera::Detection> views;
  std::vector<int> hits;  // corners a grid cell
  cv::Size size;
  size_t solved_views = 0;
};

// The mean displacement (share of the width) of the points two detections share; 1 when they
// share fewer than half.
double motion(const camera::Detection& a, const camera::Detection& b, int width) {
  std::map<int, Eigen::Vector2d> at;
  for (size_t i = 0; i < a.point_ids.size(); ++i) at[a.point_ids[i]] = a.pixels[i];
  double sum = 0;
  size_t n = 0;
  for (size_t i = 0; i < b.point_ids.size(); ++i)
    if (auto it = at.find(b.point_ids[i]); it != at.end()) {
      sum += (it->second - b.pixels[i]).norm();
      ++n;
    }
  if (2 * n < std::max(a.point_ids.size(), b.point_ids.size())) return 1;
  return sum / static_cast<double>(n) / width;
}

const char* kZones[3][3] = {{"top-left", "top", "top-right"},
                            {"left", "centre", "right"},
                            {"bottom-left", "bottom", "bottom-right"}};

}  // namespace

struct Assistant::Impl {
  AssistOptions options;
  std::vector<CameraState> cameras;
  mutable std::mutex mutex;
  std::condition_variable wake;
  bool stop = false;
  std::thread worker;

  void run();
  void look(size_t index, const cv::Mat& frame);
  void solve(CameraState& c);
  void write_png();
};

Assistant::Assistant(AssistOptions options, std::vector<std::string> folders)
    : impl_(std::make_unique<Impl>()) {
  impl_->options = std::move(options);
  for (const std::string& f : folders) {
    CameraState c;
    c.coverage.folder = f;
    impl_->cameras.push_back(std::move(c));
  }
  impl_->worker = std::thread([this] { impl_->run(); });
}

Assistant::~Assistant() {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->stop = true;
  }
  impl_->wake.notify_all();
  impl_->worker.join();
}

void Assistant::offer(size_t index, const cv::Mat& frame) {
  {
    std::lock_guard lock(impl_->mutex);
    CameraState& c = impl_->cameras.at(index);
    const auto now = Clock::now();
    if (c.has_pending || now - c.last_taken < std::chrono::duration<double>(impl_->options.every_s))
      return;
    c.pending = frame;  // shared: the writer only reads it too
    c.has_pending = true;
    c.last_taken = now;
  }
  impl_->wake.notify_one();
}

std::vector<CameraCoverage> Assistant::coverage() const {
  std::lock_guard lock(impl_->mutex);
  std::vector<CameraCoverage> out;
  for (const CameraState& c : impl_->cameras) out.push_back(c.coverage);
  return out;
}

void Assistant::Impl::run() {
  while (true) {
    size_t index = 0;
    cv::Mat frame;
    {
      std::unique_lock lock(mutex);
      wake.wait(lock, [&] {
        if (stop) return true;
        for (const CameraState& c : cameras)
          if (c.has_pending) return true;
        return false;
      });
      if (stop) return;
      for (size_t i = 0; i < cameras.size(); ++i)
        if (cameras[i].has_pending) {
          index = i;
          frame = cameras[i].pending;
          break;
        }
    }
    try {
      look(index, frame);
    } catch (const std::exception& e) {
      std::lock_guard lock(mutex);
      cameras[index].coverage.missing = {fmt::format("assistance stopped: {}", e.what())};
    }
    std::lock_guard lock(mutex);
    cameras[index].pending.release();
    cameras[index].has_pending = false;
  }
}

void Assistant::Impl::look(size_t index, const cv::Mat& frame) {
  CameraState& c = cameras[index];  // the worker's own, but for coverage and pending (locked)
  const cv::Mat gray = io::to_gray(frame, options.bayer, c.coverage.folder).clone();
  const camera::Detection d = camera::detect(gray, options.target);
  bool kept = false;
  {
    std::lock_guard lock(mutex);
    ++c.coverage.looked_at;
    c.last_gray = gray;
    if (c.size.empty()) {
      c.size = gray.size();
      c.hits.assign(options.grid_cols * options.grid_rows, 0);
    }
    if (d.found &&
        (c.views.empty() || motion(c.views.back(), d, c.size.width) > options.min_motion)) {
      c.views.push_back(d);
      kept = true;
      for (const Eigen::Vector2d& p : d.pixels) {
        const int col = std::clamp(static_cast<int>(p.x() * options.grid_cols / c.size.width), 0,
                                   options.grid_cols - 1);
        const int row = std::clamp(static_cast<int>(p.y() * options.grid_rows / c.size.height), 0,
                                   options.grid_rows - 1);
        ++c.hits[row * options.grid_cols + col];
      }
      c.coverage.views = c.views.size();
      size_t covered = 0;
      for (int h : c.hits) covered += h > 0;
      c.coverage.covered = static_cast<double>(covered) / static_cast<double>(c.hits.size());
      c.coverage.empty_zones.clear();
      for (int zr = 0; zr < 3; ++zr)
        for (int zc = 0; zc < 3; ++zc) {
          size_t cells = 0, hit = 0;
          for (int r = 0; r < options.grid_rows; ++r)
            for (int q = 0; q < options.grid_cols; ++q)
              if (r * 3 / options.grid_rows == zr && q * 3 / options.grid_cols == zc) {
                ++cells;
                hit += c.hits[r * options.grid_cols + q] > 0;
              }
          if (2 * hit < cells) c.coverage.empty_zones.push_back(kZones[zr][zc]);
        }
    }
  }
  if (kept && c.views.size() >= 4 && (c.solved_views == 0 || c.views.size() >= c.solved_views + 2))
    solve(c);
  if (kept && !options.png.empty()) write_png();
}

void Assistant::Impl::solve(CameraState& c) {
  camera::CameraInput input{c.coverage.folder, c.size.width, c.size.height, c.views};
  camera::CalibrationResult result;
  try {
    result = camera::calibrate(options.target, {input});
  } catch (const Error&) {
    return;  // too few usable views yet
  }
  c.solved_views = c.views.size();
  const camera::CameraResult& r = result.cameras.at(0);
  CameraCoverage s;
  s.solved = true;
  s.focal_px = r.model.fx;
  s.focal_rel_sigma = std::max(r.stddev.at(0) / r.model.fx, r.stddev.at(1) / r.model.fy);
  s.principal_sigma_px = std::max(r.stddev.at(2), r.stddev.at(3));
  // The boards' tilts about the image's axes and their distances (their centres).
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  const auto points = camera::object_points(options.target);
  for (const auto& p : points) centre += p;
  centre /= static_cast<double>(points.size());
  std::vector<double> tilt_x, tilt_y, distance;
  for (const auto& T : result.T_cam0_board) {
    if (!T) continue;
    Eigen::Vector3d n = T->R.col(2);
    if (n.z() > 0) n = -n;  // towards the camera
    tilt_x.push_back(kDeg * std::atan2(n.y(), -n.z()));
    tilt_y.push_back(kDeg * std::atan2(n.x(), -n.z()));
    distance.push_back((*T * centre).norm());
  }
  if (distance.empty()) return;
  s.tilt_x_min_deg = *std::min_element(tilt_x.begin(), tilt_x.end());
  s.tilt_x_max_deg = *std::max_element(tilt_x.begin(), tilt_x.end());
  s.tilt_y_min_deg = *std::min_element(tilt_y.begin(), tilt_y.end());
  s.tilt_y_max_deg = *std::max_element(tilt_y.begin(), tilt_y.end());
  s.distance_min_m = *std::min_element(distance.begin(), distance.end());
  s.distance_max_m = *std::max_element(distance.begin(), distance.end());
  const camera::UncertaintyMap u = camera::projection_uncertainty(result, 0, median(distance));
  const auto worst = std::max_element(u.sigma_px.begin(), u.sigma_px.end());
  if (worst != u.sigma_px.end()) {
    const long i = worst - u.sigma_px.begin();
    s.worst_projection_sigma_px = *worst;
    s.worst_at = {(static_cast<double>(i % u.cols) + 0.5) * u.cell_px,
                  (static_cast<double>(i / u.cols) + 0.5) * u.cell_px};
  }
  std::lock_guard lock(mutex);
  CameraCoverage& k = c.coverage;
  s.folder = k.folder;
  s.looked_at = k.looked_at;
  s.views = k.views;
  s.covered = k.covered;
  s.empty_zones = k.empty_zones;
  std::vector<std::string>& m = s.missing;
  if (!s.empty_zones.empty())
    m.push_back(fmt::format("corners in the {} of the image", fmt::join(s.empty_zones, ", ")));
  auto tilt_words = [&](double lo, double hi, const char* axis) {
    if (lo > -options.tilt_goal_deg || hi < options.tilt_goal_deg)
      m.push_back(fmt::format("views turned {} by {:.0f} deg both ways (so far {:+.0f} to {:+.0f})",
                              axis, options.tilt_goal_deg, lo, hi));
  };
  tilt_words(s.tilt_x_min_deg, s.tilt_x_max_deg, "about the image's horizontal axis");
  tilt_words(s.tilt_y_min_deg, s.tilt_y_max_deg, "about its vertical axis");
  if (s.focal_rel_sigma > options.focal_goal)
    m.push_back(fmt::format("a focal length better known (sigma {:.1e} of it, goal {:.1e})",
                            s.focal_rel_sigma, options.focal_goal));
  if (s.principal_sigma_px > options.principal_goal_px)
    m.push_back(fmt::format("a principal point better known (sigma {:.2f} px, goal {:.2f})",
                            s.principal_sigma_px, options.principal_goal_px));
  if (!m.empty())
    m.push_back(
        fmt::format("the projection is least certain near ({:.0f}, {:.0f}) px: {:.2f} px "
                    "at {:.1f} m",
                    s.worst_at.x, s.worst_at.y, s.worst_projection_sigma_px, median(distance)));
  k = s;
}

void Assistant::Impl::write_png() {
  std::vector<cv::Mat> panels;
  {
    std::lock_guard lock(mutex);
    for (const CameraState& c : cameras) {
      if (c.last_gray.empty()) continue;
      const double scale = 700.0 / c.size.width;
      cv::Mat small, panel;
      cv::resize(c.last_gray, small, {}, scale, scale, cv::INTER_AREA);
      cv::cvtColor(small, panel, cv::COLOR_GRAY2BGR);
      cv::Mat tint = panel.clone();
      for (int r = 0; r < options.grid_rows; ++r)
        for (int q = 0; q < options.grid_cols; ++q) {
          const cv::Rect cell(q * panel.cols / options.grid_cols,
                              r * panel.rows / options.grid_rows, panel.cols / options.grid_cols,
                              panel.rows / options.grid_rows);
          cv::rectangle(
              tint, cell,
              c.hits[r * options.grid_cols + q] > 0 ? cv::Scalar(0, 160, 0) : cv::Scalar(0, 0, 200),
              cv::FILLED);
        }
      cv::addWeighted(panel, 0.75, tint, 0.25, 0, panel);
      for (const auto& v : c.views)
        for (const Eigen::Vector2d& p : v.pixels)
          cv::circle(panel, {int(p.x() * scale), int(p.y() * scale)}, 1, {0, 255, 255}, cv::FILLED);
      cv::putText(panel,
                  fmt::format("{}: {} views, {:.0f}% of the image", c.coverage.folder,
                              c.coverage.views, 100 * c.coverage.covered),
                  {8, 20}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {255, 255, 255}, 1, cv::LINE_AA);
      panels.push_back(panel);
    }
  }
  if (panels.empty()) return;
  cv::Mat all;
  cv::vconcat(panels, all);
  std::vector<uint8_t> png;
  cv::imencode(".png", all, png);
  io::write_file_atomic(options.png, std::string(png.begin(), png.end()));
}

std::vector<std::string> Assistant::lines(const std::vector<CameraCoverage>& coverage) {
  std::vector<std::string> out;
  for (const CameraCoverage& c : coverage) {
    std::string line = fmt::format("{}: {} views of {} looked at, {:.0f}% of the image", c.folder,
                                   c.views, c.looked_at, 100 * c.covered);
    if (c.solved)
      line += fmt::format("; focal sigma {:.1e}, principal point sigma {:.2f} px",
                          c.focal_rel_sigma, c.principal_sigma_px);
    if (c.views < 4)
      line += "; more views needed";
    else if (c.solved && c.missing.empty())
      line += "; enough: the camera step's bars hold at 3 sigma";
    else if (!c.missing.empty())
      line += fmt::format("; still missing: {}", fmt::join(c.missing, "; "));
    out.push_back(line);
  }
  return out;
}

}  // namespace rigcal::capture
