#include "rigcal/camera/report.h"

#include <fmt/format.h>

#include <algorithm>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/core/version.h"
#include "rigcal/report/rotation.h"

namespace rigcal::camera {
namespace {

// The saddle fit is named: a cache of the other refinement does not match, and its images are
// detected again.
std::string target_header(const Target& t, bool saddle_fit) {
  return fmt::format("# rigcal corners of target {} ({} {} x {}){}", t.name,
                     t.type == TargetType::checkerboard ? "checkerboard" : "aprilgrid", t.cols,
                     t.rows, saddle_fit ? ", saddle fit" : "");
}

cv::Mat colour(const cv::Mat& values_0_1) {
  cv::Mat u8, out;
  values_0_1.convertTo(u8, CV_8U, 255.0);
  cv::applyColorMap(u8, out, cv::COLORMAP_VIRIDIS);
  return out;
}

}  // namespace

std::string corners_vnl(const Target& target, const std::vector<std::string>& images,
                        const std::vector<Detection>& detections, bool saddle_fit) {
  const size_t n = object_points(target).size();
  std::string out = target_header(target, saddle_fit) + "\n# filename x y level\n";
  for (size_t i = 0; i < images.size(); ++i) {
    const Detection& d = detections[i];
    if (!d.found) {
      out += images[i] + " - - -\n";
      continue;
    }
    std::vector<const Eigen::Vector2d*> at(n, nullptr);
    for (size_t k = 0; k < d.point_ids.size(); ++k) at[d.point_ids[k]] = &d.pixels[k];
    for (size_t p = 0; p < n; ++p) {
      out += at[p] ? fmt::format("{} {} {} 0\n", images[i], format_double(at[p]->x()),
                                 format_double(at[p]->y()))
                   : images[i] + " - - -\n";
    }
  }
  return out;
}

std::map<std::string, Detection> parse_corners_vnl(std::string_view text, const Target& target,
                                                   bool saddle_fit) {
  std::map<std::string, Detection> out;
  if (text.substr(0, text.find('\n')) != target_header(target, saddle_fit)) return out;
  const size_t n = object_points(target).size();
  std::map<std::string, std::vector<std::string_view>> lines;
  std::vector<std::string> order;
  size_t pos = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    if (line.empty() || line[0] == '#') continue;
    const std::vector<std::string_view> f = split_fields(line);
    if (f.size() != 4) return {};
    const std::string name(f[0]);
    if (!lines.count(name)) order.push_back(name);
    lines[name].push_back(line);
  }
  for (const std::string& name : order) {
    Detection d;
    const auto& ls = lines[name];
    if (ls.size() == n) {
      for (size_t p = 0; p < n; ++p) {
        const std::vector<std::string_view> f = split_fields(ls[p]);
        if (f[1] == "-") continue;
        d.point_ids.push_back(static_cast<int>(p));
        try {
          d.pixels.emplace_back(parse_double(f[1], "x"), parse_double(f[2], "y"));
        } catch (const Error&) {
          return {};  // a damaged cache is no cache: the images are detected again
        }
      }
      d.found = !d.pixels.empty();
    }
    out[name] = d;
  }
  return out;
}

nlohmann::json cameras_json(const CalibrationResult& r, const CameraReportInput& in) {
  nlohmann::json j;
  j["tool_version"] = version_string();
  j["inputs"] = in.inputs;
  j["rms_2d_px"] = r.rms_2d_px;
  j["rms_per_coordinate_px"] = r.rms_coord_px;
  j["noise_sigma_px"] = r.noise_sigma_px;
  j["n_residuals"] = r.n_residuals;
  j["n_parameters"] = r.n_parameters;
  j["n_outliers"] = r.n_outliers;
  if (r.board_warp_m) {
    j["board_warp_m"] = {r.board_warp_m->x(), r.board_warp_m->y()};
    j["board_warp_stddev_m"] = {r.board_warp_stddev_m->x(), r.board_warp_stddev_m->y()};
  }
  j["definitions"] = {
      {"rms_2d_px", "sqrt(mean over inlier corners of |projected - observed|^2): OpenCV's RMS"},
      {"rms_per_coordinate_px",
       "sqrt(mean over inlier x and y residuals^2) = rms_2d / sqrt(2): mrcal's"},
      {"noise_sigma_px",
       "sqrt(sum of squared residuals / (residuals - parameters)), per coordinate; scales the "
       "covariance"},
      {"stddev", "1-sigma of each parameter from the covariance"},
      {"board_warp_m",
       "with --board-warp: the board's bend along its x and y axes, each a parabola zero at the "
       "first and last corner and this high (m, along the board's z) at the middle: mrcal's "
       "calobject_warp"},
      {"projection_uncertainty",
       "worst-direction 1-sigma of a pixel's projection at uncertainty_distance_m, as mrcal "
       "defines it: the point fixed in the boards' frames, every parameter (intrinsics, camera "
       "and board poses) perturbed by the covariance, the camera re-finding it as the mean over "
       "the frames; intrinsics_only_*: a point fixed in the camera frame through perturbed "
       "intrinsics (no board poses), for comparison"}};
  for (size_t c = 0; c < r.cameras.size(); ++c) {
    const CameraResult& cr = r.cameras[c];
    nlohmann::json cj;
    cj["name"] = in.camera_names[c];
    cj["model"] = {{"camera_model", "pinhole"},
                   {"distortion_model", rig::to_string(cr.model.distortion_model)},
                   {"intrinsics", {cr.model.fx, cr.model.fy, cr.model.cx, cr.model.cy}},
                   {"distortion_coeffs", cr.model.distortion_coeffs},
                   {"resolution", {cr.model.width, cr.model.height}}};
    cj["stddev"] = {
        {"intrinsics", std::vector<double>(cr.stddev.begin(), cr.stddev.begin() + 4)},
        {"distortion_coeffs", std::vector<double>(cr.stddev.begin() + 4, cr.stddev.end())}};
    cj["n_views"] = cr.n_views;
    cj["n_corners"] = cr.n_corners;
    nlohmann::json views = nlohmann::json::array();
    for (size_t f = 0; f < cr.view_rms.size(); ++f) {
      if (std::isnan(cr.view_rms[f])) continue;
      views.push_back({{"frame", f}, {"image", in.images[c][f]}, {"rms_2d_px", cr.view_rms[f]}});
    }
    cj["views"] = views;
    if (c < in.uncertainty.size()) {
      const UncertaintyMap& u = in.uncertainty[c];
      cj["projection_uncertainty"] = {{"distance_m", in.uncertainty_distance_m},
                                      {"mean_px", u.mean_px},
                                      {"max_px", u.max_px},
                                      {"centre_px", u.centre_px}};
      // The map itself, for the report's figure: cells of cell_px from the image's corner, rows
      // first, each sigma to 4 digits.
      nlohmann::json sigma = nlohmann::json::array();
      for (const double s : u.sigma_px) sigma.push_back(std::stod(fmt::format("{:.4g}", s)));
      cj["projection_uncertainty"]["grid"] = {
          {"cols", u.cols}, {"rows", u.rows}, {"cell_px", u.cell_px}, {"sigma_px", sigma}};
      if (c < in.uncertainty_intrinsics_only.size()) {
        const UncertaintyMap& ui = in.uncertainty_intrinsics_only[c];
        cj["projection_uncertainty"]["intrinsics_only_mean_px"] = ui.mean_px;
        cj["projection_uncertainty"]["intrinsics_only_max_px"] = ui.max_px;
        cj["projection_uncertainty"]["intrinsics_only_centre_px"] = ui.centre_px;
      }
    }
    if (c > 0) {
      const SE3 T_c0 = r.T_cam_cam0[c];
      const Eigen::Vector3d rpy = roll_pitch_yaw(T_c0.R) * 180.0 / M_PI;
      cj["T_cam_cam0"] = {{"from", in.camera_names[0]},
                          {"translation_m", {T_c0.t.x(), T_c0.t.y(), T_c0.t.z()}},
                          {"axis_angle", report::axis_angle_json(T_c0.R)},
                          {"rotation_rpy_deg", {rpy.x(), rpy.y(), rpy.z()}},
                          {"baseline_m", T_c0.t.norm()},
                          {"translation_stddev_m",
                           {r.translation_stddev_m[c].x(), r.translation_stddev_m[c].y(),
                            r.translation_stddev_m[c].z()}},
                          {"rotation_stddev_deg",
                           {r.rotation_stddev_deg[c].x(), r.rotation_stddev_deg[c].y(),
                            r.rotation_stddev_deg[c].z()}}};
    }
    j["cameras"].push_back(cj);
  }
  // The worst inlier corners and every outlier.
  std::vector<const CornerResidual*> sorted;
  for (const CornerResidual& cr : r.residuals) sorted.push_back(&cr);
  std::sort(sorted.begin(), sorted.end(),
            [](auto* a, auto* b) { return a->residual.norm() > b->residual.norm(); });
  auto corner = [&](const CornerResidual& cr) {
    return nlohmann::json{{"camera", in.camera_names[cr.camera]},
                          {"image", in.images[cr.camera][cr.frame]},
                          {"point", cr.point},
                          {"observed_px", {cr.observed.x(), cr.observed.y()}},
                          {"residual_px", {cr.residual.x(), cr.residual.y()}}};
  };
  j["worst_corners"] = nlohmann::json::array();
  j["outliers"] = nlohmann::json::array();
  for (const auto* cr : sorted) {
    if (cr->outlier)
      j["outliers"].push_back(corner(*cr));
    else if (j["worst_corners"].size() < 10)
      j["worst_corners"].push_back(corner(*cr));
  }
  j["notes"] = r.notes;
  return j;
}

cv::Mat corners_png(const cv::Mat& gray, const Detection& d) {
  cv::Mat out;
  cv::cvtColor(gray, out, cv::COLOR_GRAY2BGR);
  for (size_t i = 0; i < d.pixels.size(); ++i) {
    const cv::Point p(static_cast<int>(d.pixels[i].x()), static_cast<int>(d.pixels[i].y()));
    cv::circle(out, p, 4, i == 0 ? cv::Scalar(0, 0, 255) : cv::Scalar(0, 200, 0), 1, cv::LINE_AA);
  }
  if (d.pixels.empty()) return out;
  // The label of point 0 outside the corners (beyond the farthest from their centroid, in point
  // 0's direction), joined to it by a line: it covers no corner.
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : d.pixels) centre += p;
  centre /= static_cast<double>(d.pixels.size());
  double radius = 0;
  for (const Eigen::Vector2d& p : d.pixels) radius = std::max(radius, (p - centre).norm());
  Eigen::Vector2d dir = d.pixels[0] - centre;
  dir = dir.norm() > 1e-9 ? dir.normalized() : Eigen::Vector2d(-1, -1).normalized();
  const double scale = std::max(0.5, out.cols / 1400.0);
  const int thickness = std::max(1, static_cast<int>(std::lround(scale)));
  int baseline = 0;
  const cv::Size text =
      cv::getTextSize("point 0", cv::FONT_HERSHEY_SIMPLEX, scale, thickness, &baseline);
  const Eigen::Vector2d end = centre + dir * (radius + 12 * scale);
  // The text's box grows away from the corners: to the left of `end` when pointing left, above
  // it when pointing up.
  double x = dir.x() < 0 ? end.x() - text.width : end.x();
  double y = dir.y() < 0 ? end.y() : end.y() + text.height;
  x = std::clamp(x, 0.0, std::max(0.0, double(out.cols - text.width)));
  y = std::clamp(y, double(text.height), double(out.rows - baseline));
  const cv::Scalar red(0, 0, 255);
  cv::line(out, cv::Point2d(d.pixels[0].x(), d.pixels[0].y()), cv::Point2d(end.x(), end.y()), red,
           1, cv::LINE_AA);
  cv::putText(out, "point 0", cv::Point2d(x, y), cv::FONT_HERSHEY_SIMPLEX, scale, red, thickness,
              cv::LINE_AA);
  return out;
}

cv::Mat residuals_png(const CalibrationResult& r, int camera, int width, int height,
                      double magnify) {
  cv::Mat out(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  for (const CornerResidual& cr : r.residuals) {
    if (cr.camera != camera) continue;
    const cv::Point a(static_cast<int>(cr.observed.x()), static_cast<int>(cr.observed.y()));
    const Eigen::Vector2d e = cr.observed + magnify * cr.residual;
    cv::arrowedLine(out, a, cv::Point(static_cast<int>(e.x()), static_cast<int>(e.y())),
                    cr.outlier ? cv::Scalar(0, 0, 255) : cv::Scalar(120, 60, 0), 1, cv::LINE_AA, 0,
                    0.2);
  }
  cv::putText(out, fmt::format("residuals x{} (red: outliers)", magnify), cv::Point(10, 25),
              cv::FONT_HERSHEY_SIMPLEX, 0.7, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  return out;
}

cv::Mat coverage_png(const CalibrationResult& r, int camera, int width, int height) {
  const int cell = 20;
  cv::Mat counts = cv::Mat::zeros((height + cell - 1) / cell, (width + cell - 1) / cell, CV_64F);
  for (const CornerResidual& cr : r.residuals) {
    if (cr.camera != camera || cr.outlier) continue;
    const int u = std::clamp(static_cast<int>(cr.observed.x()) / cell, 0, counts.cols - 1);
    const int v = std::clamp(static_cast<int>(cr.observed.y()) / cell, 0, counts.rows - 1);
    counts.at<double>(v, u) += 1;
  }
  double max = 1;
  cv::minMaxLoc(counts, nullptr, &max);
  cv::Mat scaled, big;
  cv::resize(counts / std::max(1.0, max), big, cv::Size(width, height), 0, 0, cv::INTER_NEAREST);
  scaled = colour(big);
  cv::putText(scaled, fmt::format("corners a 20 px cell, max {}", static_cast<int>(max)),
              cv::Point(10, 25), cv::FONT_HERSHEY_SIMPLEX, 0.7, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
  return scaled;
}

std::string residuals_csv(const CalibrationResult& r, const std::vector<std::string>& names) {
  std::string out = "camera,view,point,u_px,v_px,residual_u_px,residual_v_px,outlier\n";
  for (const CornerResidual& cr : r.residuals) {
    out += fmt::format("{},{},{},{:.3f},{:.3f},{:.5f},{:.5f},{}\n", names.at(cr.camera), cr.frame,
                       cr.point, cr.observed.x(), cr.observed.y(), cr.residual.x(), cr.residual.y(),
                       cr.outlier ? 1 : 0);
  }
  return out;
}

std::vector<std::string> coverage_warnings(const CalibrationResult& r, int camera,
                                           const std::string& name, int width, int height) {
  static const char* kCells[3][3] = {{"top-left", "top", "top-right"},
                                     {"left", "centre", "right"},
                                     {"bottom-left", "bottom", "bottom-right"}};
  int cells[3][3] = {};
  int total = 0;
  for (const CornerResidual& cr : r.residuals) {
    if (cr.camera != camera || cr.outlier) continue;
    const int u = std::clamp(static_cast<int>(3 * cr.observed.x() / width), 0, 2);
    const int v = std::clamp(static_cast<int>(3 * cr.observed.y() / height), 0, 2);
    ++cells[v][u], ++total;
  }
  if (total == 0) return {};
  std::vector<std::string> empty;
  for (int v = 0; v < 3; ++v)
    for (int u = 0; u < 3; ++u)
      if (cells[v][u] == 0) empty.push_back(kCells[v][u]);
  // Each half's share of the corners, by the corners' own positions.
  const struct {
    const char* name;
    bool (*in)(const Eigen::Vector2d&, int, int);
  } halves[] = {{"left", [](const Eigen::Vector2d& p, int w, int) { return p.x() < w / 2.0; }},
                {"right", [](const Eigen::Vector2d& p, int w, int) { return p.x() >= w / 2.0; }},
                {"top", [](const Eigen::Vector2d& p, int, int h) { return p.y() < h / 2.0; }},
                {"bottom", [](const Eigen::Vector2d& p, int, int h) { return p.y() >= h / 2.0; }}};
  std::vector<std::string> out;
  for (const auto& half : halves) {
    int n = 0;
    for (const CornerResidual& cr : r.residuals)
      n += cr.camera == camera && !cr.outlier && half.in(cr.observed, width, height);
    if (n * 10 >= total) continue;
    out.push_back(fmt::format(
        "{}: the {} half of the image holds {} of its {} corners ({:.0f} %): the lens there is "
        "extrapolated from the rest, not measured; record the board in that part of the image",
        name, half.name, n, total, 100.0 * n / total));
  }
  if (out.empty() && !empty.empty()) {
    out.push_back(fmt::format(
        "{}: no corners in the {} {} of the image (3 x 3 cells): the lens there is extrapolated, "
        "not measured; record the board there",
        name, fmt::join(empty, ", "), empty.size() == 1 ? "ninth" : "ninths"));
  }
  return out;
}

cv::Mat uncertainty_png(const UncertaintyMap& m, int width, int height) {
  cv::Mat grid(m.rows, m.cols, CV_64F);
  for (int r = 0; r < m.rows; ++r) {
    for (int c = 0; c < m.cols; ++c)
      grid.at<double>(r, c) = m.sigma_px[r * m.cols + c] / std::max(1e-12, m.max_px);
  }
  cv::Mat big;
  cv::resize(grid, big, cv::Size(width, height), 0, 0, cv::INTER_LINEAR);
  cv::Mat out = colour(big);
  cv::putText(
      out,
      fmt::format("projection 1-sigma, px: mean {:.3f}, max {:.3f} (yellow)", m.mean_px, m.max_px),
      cv::Point(10, 25), cv::FONT_HERSHEY_SIMPLEX, 0.7, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  return out;
}

}  // namespace rigcal::camera
