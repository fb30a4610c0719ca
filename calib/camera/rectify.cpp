// The stereo pair rectified (rectify.h).
#include "rigcal/camera/rectify.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <map>
#include <opencv2/imgproc.hpp>

#include "rigcal/camera/lens.h"

namespace rigcal::camera {

Rectification rectify(const rig::CameraModel& left, const rig::CameraModel& right,
                      const SE3& T_r_l) {
  // In the left camera's frame: the baseline (left centre to right centre) and the two optical
  // axes' mean; the rectified frame has x along the baseline, y across it and that mean, z ahead.
  const Eigen::Vector3d c_r = -T_r_l.R.transpose() * T_r_l.t;
  Eigen::Vector3d x = c_r.normalized();
  if (x.x() < 0) x = -x;  // a right camera on the left: the images stay upright, rows still agree
  const Eigen::Vector3d ahead =
      Eigen::Vector3d::UnitZ() + T_r_l.R.transpose() * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d y = ahead.cross(x).normalized(), z = x.cross(y);
  Rectification r;
  r.R_rect_l.row(0) = x.transpose();
  r.R_rect_l.row(1) = y.transpose();
  r.R_rect_l.row(2) = z.transpose();
  r.R_rect_r = r.R_rect_l * T_r_l.R.transpose();
  r.f_px = std::min({left.fx, left.fy, right.fx, right.fy});
  r.width = left.width;
  r.height = left.height;
  r.cx_px = 0.5 * (left.width - 1);
  r.cy_px = 0.5 * (left.height - 1);
  return r;
}

Eigen::Vector2d rectified_pixel(const Rectification& rect, const rig::CameraModel& camera,
                                const Eigen::Matrix3d& R_rect_cam, const Eigen::Vector2d& pixel) {
  const Eigen::Vector2d xn = unproject(camera, pixel);
  const Eigen::Vector3d p = R_rect_cam * Eigen::Vector3d(xn.x(), xn.y(), 1.0);
  return {rect.f_px * p.x() / p.z() + rect.cx_px, rect.f_px * p.y() / p.z() + rect.cy_px};
}

std::vector<double> row_differences(const Rectification& rect, const rig::CameraModel& left,
                                    const rig::CameraModel& right, const Detection& in_left,
                                    const Detection& in_right) {
  std::map<int, Eigen::Vector2d> by_id;
  for (size_t i = 0; i < in_left.point_ids.size(); ++i)
    by_id[in_left.point_ids[i]] = in_left.pixels[i];
  std::vector<double> out;
  for (size_t i = 0; i < in_right.point_ids.size(); ++i) {
    const auto it = by_id.find(in_right.point_ids[i]);
    if (it == by_id.end()) continue;
    const double row_l = rectified_pixel(rect, left, rect.R_rect_l, it->second).y();
    const double row_r = rectified_pixel(rect, right, rect.R_rect_r, in_right.pixels[i]).y();
    out.push_back(row_r - row_l);
  }
  return out;
}

namespace {

// One camera's image resampled into the rectified pinhole (black where its lens sees nothing).
cv::Mat resample(const Rectification& rect, const rig::CameraModel& camera,
                 const Eigen::Matrix3d& R_rect_cam, const cv::Mat& gray) {
  cv::Mat map_x(rect.height, rect.width, CV_32FC1), map_y(rect.height, rect.width, CV_32FC1);
  const Eigen::Matrix3d R_cam_rect = R_rect_cam.transpose();
  for (int v = 0; v < rect.height; ++v) {
    for (int u = 0; u < rect.width; ++u) {
      const Eigen::Vector3d ray((u - rect.cx_px) / rect.f_px, (v - rect.cy_px) / rect.f_px, 1.0);
      const std::optional<Eigen::Vector2d> q = project(camera, R_cam_rect * ray);
      map_x.at<float>(v, u) = q ? static_cast<float>(q->x()) : -1.0f;
      map_y.at<float>(v, u) = q ? static_cast<float>(q->y()) : -1.0f;
    }
  }
  cv::Mat out;
  cv::remap(gray, out, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
  return out;
}

}  // namespace

cv::Mat rectified_pair_png(const Rectification& rect, const rig::CameraModel& left,
                           const rig::CameraModel& right, const cv::Mat& gray_left,
                           const cv::Mat& gray_right, const Detection& in_left,
                           const Detection& in_right, int line_every_px) {
  cv::Mat pair;
  cv::hconcat(resample(rect, left, rect.R_rect_l, gray_left),
              resample(rect, right, rect.R_rect_r, gray_right), pair);
  cv::Mat out;
  cv::cvtColor(pair, out, cv::COLOR_GRAY2BGR);
  for (int v = line_every_px / 2; v < rect.height; v += std::max(1, line_every_px))
    cv::line(out, {0, v}, {out.cols - 1, v}, cv::Scalar(0, 200, 0), 1, cv::LINE_AA);
  const auto circle = [&](const Detection& d, const rig::CameraModel& camera,
                          const Eigen::Matrix3d& R, int offset, const cv::Scalar& colour) {
    for (const Eigen::Vector2d& px : d.pixels) {
      const Eigen::Vector2d q = rectified_pixel(rect, camera, R, px);
      cv::circle(out, cv::Point2d(q.x() + offset, q.y()), 4, colour, 1, cv::LINE_AA);
    }
  };
  circle(in_left, left, rect.R_rect_l, 0, cv::Scalar(0, 0, 255));
  circle(in_right, right, rect.R_rect_r, rect.width, cv::Scalar(255, 80, 0));
  return out;
}

}  // namespace rigcal::camera
