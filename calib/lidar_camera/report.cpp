#include "rigcal/lidar_camera/report.h"

#include <fmt/format.h>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "rigcal/camera/lens.h"
#include "rigcal/core/se3.h"
#include "rigcal/core/version.h"
#include "rigcal/report/json.h"
#include "rigcal/report/png.h"
#include "rigcal/report/rotation.h"

namespace rigcal::lidar_camera {
cv::Mat overlay(const cv::Mat& image, const std::vector<Eigen::Vector3d>& scan,
                const std::vector<Eigen::Vector3d>& board_points, const SE3& T,
                const rig::CameraModel& camera) {
  cv::Mat out;
  if (image.channels() == 1) {
    cv::cvtColor(image, out, cv::COLOR_GRAY2BGR);
  } else {
    out = image.clone();
  }
  out = out * 0.6;  // dimmed, so the points stand out
  const int r = std::max(1, out.cols / 900);
  for (const Eigen::Vector3d& x : scan) {
    const Eigen::Vector3d p = T * x;
    if (p.z() < 0.2 || p.z() > 30.0) continue;
    const auto px = camera::project(camera, p);
    if (!px || px->x() < 0 || px->y() < 0 || px->x() >= out.cols || px->y() >= out.rows) continue;
    // Depth to hue: 0.5 m red ... 10 m blue (log scale).
    const double f = std::clamp(std::log(p.z() / 0.5) / std::log(20.0), 0.0, 1.0);
    cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(static_cast<int>(120 * f), 255, 255)), bgr;
    cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
    const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
    cv::circle(out, cv::Point(static_cast<int>(px->x()), static_cast<int>(px->y())), r,
               cv::Scalar(c[0], c[1], c[2]), cv::FILLED);
  }
  for (const Eigen::Vector3d& x : board_points) {
    const auto px = camera::project(camera, T * x);
    if (!px) continue;
    cv::circle(out, cv::Point(static_cast<int>(px->x()), static_cast<int>(px->y())), r + 1,
               cv::Scalar(255, 255, 255), 1);
  }
  return out;
}

std::vector<io::OutputFile> lidar_camera_report_files(const std::filesystem::path& dir,
                                                      const LidarCameraInputs& in,
                                                      const std::vector<PairInput>& pairs,
                                                      const Calibration& c,
                                                      const rig::CameraModel& camera,
                                                      const std::vector<cv::Mat>& images) {
  const Solution& s = c.solution;
  nlohmann::json j;
  j["tool_version"] = version_string();
  j["definition"] =
      "T_camera_lidar maps LiDAR points into the camera frame. Per board: the camera's plane "
      "(PnP on the corners through the lens) and the LiDAR's (fitted to the board's points) must "
      "agree after the extrinsic: normal angle (deg) and distance (m) residuals; point_rms_m: "
      "the LiDAR board points against the camera's plane";
  j["inputs"] = {{"target", in.target},
                 {"rig", in.rig},
                 {"camera", in.camera},
                 {"board_width_m", in.board_width_m},
                 {"board_height_m", in.board_height_m}};
  const SE3& T = s.T_camera_lidar;
  j["T_camera_lidar"] = {
      {"t_m", report::vector_json(T.t)},
      {"axis_angle", report::axis_angle_json(T.R)},
      {"roll_pitch_yaw_deg", report::vector_json(roll_pitch_yaw(T.R) * 180.0 / M_PI)},
      {"t_sigma_m", report::vector_json(s.translation_sigma_m)},
      {"rotation_sigma_deg", report::vector_json(s.rotation_sigma_deg)},
      {"matrix", {T.matrix().row(0), T.matrix().row(1), T.matrix().row(2)}}};
  std::vector<std::vector<double>> cov;
  for (int r = 0; r < 6; ++r)
    cov.push_back({s.covariance.row(r).data(), s.covariance.row(r).data() + 6});
  j["covariance"] = {{"definition",
                      "rotation (left tangent, rad) then translation (m); scaled by the "
                      "residuals' level when above 1"},
                     {"matrix", cov}};
  j["closed_form"] = {
      {"t_m", report::vector_json(s.closed_form.t)},
      {"roll_pitch_yaw_deg", report::vector_json(roll_pitch_yaw(s.closed_form.R) * 180 / M_PI)}};
  j["observability"] = {
      {"normal_singular_values", report::vector_json(s.observability.singular_values)},
      {"condition", s.observability.condition},
      {"weak_direction_camera", report::vector_json(s.observability.weak_direction)}};
  j["noise_scale"] = s.noise_scale;
  nlohmann::json pj = nlohmann::json::array();
  size_t used = 0;
  for (size_t k = 0; k < c.pairs.size(); ++k) {
    nlohmann::json p = {{"image", k < in.images.size() ? in.images[k] : ""},
                        {"scan", k < in.scans.size() ? in.scans[k] : ""},
                        {"used", c.pairs[k].used},
                        {"note", c.pairs[k].note}};
    if (pairs[k].camera) p["camera_reprojection_rms_px"] = pairs[k].camera->rms_px;
    if (c.pairs[k].used) {
      const PairResidual& r = s.residuals[used++];
      p["board_points"] = c.pairs[k].lidar.points.size();
      p["board_rectangle_m"] = {c.pairs[k].lidar.width_m, c.pairs[k].lidar.height_m};
      p["lidar_plane_rms_m"] = c.pairs[k].lidar.plane_rms_m;
      p["normal_angle_deg"] = r.normal_angle_deg;
      p["distance_m"] = r.distance_m;
      p["point_rms_m"] = r.point_rms_m;
      p["chi2"] = r.chi2;
      p["outlier"] = r.outlier;
    }
    pj.push_back(p);
  }
  j["pairs"] = pj;
  std::vector<io::OutputFile> files{{dir / "lidar_camera.json", report::json_text(j)}};
  for (size_t k = 0; k < pairs.size() && k < images.size(); ++k) {
    files.push_back({dir / fmt::format("pair_{:02d}.png", k + 1),
                     report::encode_png(
                         overlay(images[k], pairs[k].scan, c.pairs[k].lidar.points, T, camera))});
  }
  return files;
}

}  // namespace rigcal::lidar_camera
