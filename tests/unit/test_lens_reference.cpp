// rigcal's lens models against OpenCV's own implementations, over the whole field of view: the
// simulator renders through camera::project, the calibrator fits it, so the simulated truth bars
// would not notice a wrong formula. Here cv::projectPoints (radtan) and cv::fisheye::projectPoints
// (equidistant) are the reference for the projection, and the rays of OpenCV's pixels (and
// cv::undistortPoints, cv::fisheye::undistortPoints) for the unprojection.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/calib3d.hpp>
#include <random>
#include <vector>

#include "rigcal/camera/lens.h"

namespace rigcal::camera {
namespace {

struct LensCase {
  const char* name;
  rig::CameraModel camera;
  double max_angle_deg;  // from the optical axis, within the lens's field of view
};

rig::CameraModel model(rig::DistortionModel m, double fx, double fy, double cx, double cy,
                       std::vector<double> k, int width, int height) {
  rig::CameraModel c;
  c.fx = fx, c.fy = fy, c.cx = cx, c.cy = cy;
  c.distortion_model = m;
  c.distortion_coeffs = std::move(k);
  c.width = width, c.height = height;
  return c;
}

std::vector<LensCase> cases() {
  using rig::DistortionModel;
  return {
      // The sample rig's cam_l (k1 k2 p1 p2), and a radtan with k3 and strong tangential terms.
      {"radtan, sample cam_l",
       model(DistortionModel::radtan, 1085.3, 1084.7, 701.2, 349.6,
             {-0.0921, 0.0874, 0.00031, -0.00027}, 1388, 700),
       45.0},
      {"radtan with k3",
       model(DistortionModel::radtan, 535.9, 530.2, 342.3, 235.6,
             {-0.2664, -0.0386, 0.00178, -0.00028, 0.2384}, 640, 480),
       35.0},
      // The equidistant set the camera tests simulate, and a strong fisheye to 85 degrees.
      {"equidistant, the camera tests' set",
       model(DistortionModel::equidistant, 1085.3, 1084.7, 701.2, 349.6,
             {0.02, -0.015, 0.004, -0.001}, 1388, 700),
       60.0},
      {"equidistant, wide fisheye",
       model(DistortionModel::equidistant, 610.2, 609.8, 962.4, 601.7,
             {-0.0512, 0.0123, -0.0041, 0.00068}, 1920, 1208),
       85.0},
  };
}

cv::Mat K_of(const rig::CameraModel& c) {
  return (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
}

// Points in front of the camera at angles up to `max_angle_deg` from the axis, every azimuth,
// depths 0.3-30 m; the axis itself and the field's edge included.
std::vector<cv::Point3d> points(double max_angle_deg) {
  std::vector<cv::Point3d> p;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> depth(0.3, 30.0);
  const double max_angle = max_angle_deg * M_PI / 180.0;
  for (int i = 0; i <= 40; ++i) {
    const double theta = max_angle * i / 40.0;
    for (int j = 0; j < 36; ++j) {
      const double phi = 2 * M_PI * (j + 0.5 * (i % 2)) / 36.0;
      const double d = depth(rng);
      p.emplace_back(d * std::sin(theta) * std::cos(phi), d * std::sin(theta) * std::sin(phi),
                     d * std::cos(theta));
    }
  }
  return p;
}

double ray_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

TEST(LensReference, ProjectionAndUnprojectionMatchOpenCv) {
  for (const LensCase& lc : cases()) {
    SCOPED_TRACE(lc.name);
    const rig::CameraModel& c = lc.camera;
    const bool fisheye = c.distortion_model == rig::DistortionModel::equidistant;
    const std::vector<cv::Point3d> pts = points(lc.max_angle_deg);
    const cv::Mat K = K_of(c), D(c.distortion_coeffs, true);
    std::vector<cv::Point2d> cv_px;
    const cv::Vec3d zero(0, 0, 0);
    if (fisheye)
      cv::fisheye::projectPoints(pts, cv_px, zero, zero, K, D);
    else
      cv::projectPoints(pts, zero, zero, K, D, cv_px);
    ASSERT_EQ(cv_px.size(), pts.size());

    // OpenCV's normalized coordinates of its own pixels, iterated to convergence.
    std::vector<cv::Point2d> cv_xn;
    const cv::TermCriteria tight(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, 1e-15);
    if (fisheye)
      cv::fisheye::undistortPoints(cv_px, cv_xn, K, D, cv::noArray(), cv::noArray(), tight);
    else
      cv::undistortPoints(cv_px, cv_xn, K, D, cv::noArray(), cv::noArray(), tight);

    double max_px = 0, max_ray = 0, max_cv_ray = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
      const Eigen::Vector3d p(pts[i].x, pts[i].y, pts[i].z);
      const std::optional<Eigen::Vector2d> px = project(c, p);
      ASSERT_TRUE(px) << i;
      const Eigen::Vector2d ref(cv_px[i].x, cv_px[i].y);
      max_px = std::max(max_px, (*px - ref).norm());
      EXPECT_LT((*px - ref).norm(), 1e-8) << "point " << i << " at "
                                          << ray_angle(p, Eigen::Vector3d::UnitZ()) * 180 / M_PI
                                          << " deg: rigcal " << px->transpose() << ", OpenCV "
                                          << ref.transpose();
      // The ray through OpenCV's pixel is the point's own direction.
      const Eigen::Vector2d xn = unproject(c, ref);
      const double e = ray_angle(Eigen::Vector3d(xn.x(), xn.y(), 1.0), p);
      max_ray = std::max(max_ray, e);
      EXPECT_LT(e, 1e-9) << "point " << i << ": ray off by " << e << " rad";
      // And agrees with OpenCV's unprojection of the same pixel.
      const double e_cv = ray_angle(Eigen::Vector3d(xn.x(), xn.y(), 1.0),
                                    Eigen::Vector3d(cv_xn[i].x, cv_xn[i].y, 1.0));
      max_cv_ray = std::max(max_cv_ray, e_cv);
      EXPECT_LT(e_cv, 1e-7) << "point " << i;
    }
    std::printf(
        "%s, %zu points to %.0f deg: |rigcal - OpenCV| projection max %.2e px; unprojection: ray "
        "vs the point max %.2e rad, vs OpenCV's max %.2e rad\n",
        lc.name, pts.size(), lc.max_angle_deg, max_px, max_ray, max_cv_ray);
  }
}

}  // namespace
}  // namespace rigcal::camera
