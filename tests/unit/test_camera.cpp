// Camera calibration against real images (OpenCV's stereo samples) and OpenCV's own solver on the
// same corners, and against simulator truth for both lens models.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "camera_bound.h"
#include "camera_truth.h"
#include "fixtures.h"
#include "rigcal/camera/calibrate.h"
#include "rigcal/camera/lens.h"
#include "rigcal/camera/rectify.h"
#include "rigcal/camera/report.h"
#include "rigcal/camera/uncertainty.h"
#include "rigcal/core/error.h"
#include "rigcal/core/stats.h"
#include "rigcal/io/target_pdf.h"
#include "rigcal/io/target_yaml.h"
#include "rigcal/rig/import.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/sim/session.h"

namespace rigcal::camera {
namespace {

std::vector<CameraInput> opencv_sample_detections(const std::string& dir, const Target& target) {
  std::vector<CameraInput> cams(2);
  cams[0].name = "left";
  cams[1].name = "right";
  for (int i : {1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 14}) {
    for (int c = 0; c < 2; ++c) {
      const cv::Mat img = cv::imread(fmt::format("{}/{}{:02d}.jpg", dir, c ? "right" : "left", i),
                                     cv::IMREAD_GRAYSCALE);
      cams[c].width = img.cols;
      cams[c].height = img.rows;
      cams[c].frames.push_back(detect(img, target));
    }
  }
  return cams;
}

// Acceptance 1 and 2 of the camera issue (doc/performance.md records the figures).
TEST(CameraReal, OpenCvStereoSamplesMeetTheBarAndMatchOpenCvOnTheSameCorners) {
  RIGCAL_REQUIRE_FIXTURE(dir, "stereo/opencv_samples");
  const Target target =
      io::read_target_file(RIGCAL_SOURCE_DIR "/targets/checkerboard_9x6_25mm.yaml");
  const std::vector<CameraInput> cams = opencv_sample_detections(dir, target);
  for (const CameraInput& c : cams) {
    for (const Detection& d : c.frames) ASSERT_TRUE(d.found);
  }
  const CalibrationResult r = calibrate(target, cams);
  RecordProperty("rms_2d_px", std::to_string(r.rms_2d_px));
  RecordProperty("baseline_mm", std::to_string(1000 * r.T_cam_cam0[1].t.norm()));
  EXPECT_LE(r.rms_2d_px, 0.20);
  EXPECT_NEAR(1000 * r.T_cam_cam0[1].t.norm(), 83.2, 0.4);
  EXPECT_LE(r.n_outliers, 20u);  // outlier rejection must not hide a bad fit

  // The same corners and model without outlier rejection, against cv::stereoCalibrate
  // (k1 k2 p1 p2, k3 fixed at 0), whose RMS is the same 2-D per-corner figure.
  CalibrationOptions all;
  all.max_rejection_rounds = 0;
  const CalibrationResult ours = calibrate(target, cams, all);
  std::vector<std::vector<cv::Point3f>> obj;
  std::vector<std::vector<cv::Point2f>> left, right;
  const std::vector<Eigen::Vector3d> points = object_points(target);
  for (size_t f = 0; f < cams[0].frames.size(); ++f) {
    obj.emplace_back(), left.emplace_back(), right.emplace_back();
    for (size_t i = 0; i < points.size(); ++i) {
      obj.back().emplace_back(points[i].x(), points[i].y(), 0.0f);
      left.back().emplace_back(cams[0].frames[f].pixels[i].x(), cams[0].frames[f].pixels[i].y());
      right.back().emplace_back(cams[1].frames[f].pixels[i].x(), cams[1].frames[f].pixels[i].y());
    }
  }
  cv::Mat K1 = cv::Mat::eye(3, 3, CV_64F), D1, K2 = cv::Mat::eye(3, 3, CV_64F), D2, R, T, E, F;
  std::vector<cv::Mat> rv, tv;
  const cv::Size size(cams[0].width, cams[0].height);
  cv::calibrateCamera(obj, left, size, K1, D1, rv, tv, cv::CALIB_FIX_K3);
  cv::calibrateCamera(obj, right, size, K2, D2, rv, tv, cv::CALIB_FIX_K3);
  const double opencv_rms = cv::stereoCalibrate(
      obj, left, right, K1, D1, K2, D2, size, R, T, E, F,
      cv::CALIB_USE_INTRINSIC_GUESS | cv::CALIB_FIX_K3,
      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, 1e-12));
  std::printf(
      "RMS on the same 1404 corners, k1 k2 p1 p2: rigcal %.5f px, OpenCV stereoCalibrate %.5f px; "
      "rigcal with outlier rejection %.5f px (%zu corners dropped)\n",
      ours.rms_2d_px, opencv_rms, r.rms_2d_px, r.n_outliers);
  RecordProperty("opencv_rms_2d_px", std::to_string(opencv_rms));
  EXPECT_LE(ours.rms_2d_px, 1.01 * opencv_rms);
}

// The real fisheye of the ACFR fixture: 12 images, 1920 x 1208, a 7 x 5 chessboard of 95 mm
// squares, the equidistant model (OpenCV's fisheye, the model of the authors' camera_info) against
// the intrinsics the authors published. In every view the board was held in one band below the
// image's centre, so the images measure the lens there and nowhere else: the fit is as good as on
// the OpenCV set, the reported projection uncertainty is small in the band and large outside it,
// and where the board was the published lens and rigcal's agree within the uncertainty.
TEST(CameraReal, AcfrFisheyeIsDeterminedWhereTheBoardWasAndNotBeyond) {
  RIGCAL_REQUIRE_FIXTURE(dir, "lidar_camera/acfr");
  const Target target = io::parse_target_yaml(
      "target_type: checkerboard\ntargetCols: 7\ntargetRows: 5\nrowSpacingMeters: 0.095\n"
      "colSpacingMeters: 0.095\n",
      "acfr.yaml");
  std::vector<std::string> files;
  for (int i = 1; i <= 11; ++i)
    files.push_back(fmt::format("{}/2022-11-09_00-54-42/images/pose{}.png", dir, i));
  files.push_back(dir + "/2022-11-09_01-12-11/images/pose5.png");  // a twelfth placement
  std::vector<CameraInput> cams(1);
  cams[0].name = "cam";
  for (const std::string& f : files) {
    const cv::Mat img = cv::imread(f, cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(img.empty()) << f;
    cams[0].width = img.cols, cams[0].height = img.rows;
    cams[0].frames.push_back(detect(img, target));
    EXPECT_TRUE(cams[0].frames.back().found) << f;
  }
  CalibrationOptions options;
  options.model = rig::DistortionModel::equidistant;
  const CalibrationResult r = calibrate(target, cams, options);
  const rig::CameraModel& ours = r.cameras[0].model;
  const rig::CameraModel published =
      rig::read_calibration_file(dir + "/cfg/camera_info.yaml").sensors.at(0).camera;
  const std::vector<double>& sd = r.cameras[0].stddev;
  std::printf(
      "ACFR fisheye, 12 views: RMS %.4f px (2-D), %zu outliers; fx %.2f +- %.2f (published %.3f), "
      "fy %.2f +- %.2f (%.3f), cx %.2f +- %.2f (%.3f), cy %.2f +- %.2f (%.3f); k %.4f %.4f %.4f "
      "%.4f (published %.6f %.6f %.6f %.6f)\n",
      r.rms_2d_px, r.n_outliers, ours.fx, sd[0], published.fx, ours.fy, sd[1], published.fy,
      ours.cx, sd[2], published.cx, ours.cy, sd[3], published.cy, ours.distortion_coeffs[0],
      ours.distortion_coeffs[1], ours.distortion_coeffs[2], ours.distortion_coeffs[3],
      published.distortion_coeffs[0], published.distortion_coeffs[1],
      published.distortion_coeffs[2], published.distortion_coeffs[3]);
  EXPECT_LE(r.rms_2d_px, 0.20);

  // The reported projection uncertainty (mrcal's definition, 3 m away) in the cells that hold
  // corners and in the rest, and the two lenses' difference at every corner: the ray through the
  // observed pixel by the published lens, projected by rigcal's.
  // As mrcal compares two lenses (projection-diff at infinity), the camera's rotation that best
  // maps one lens's rays onto the other's over the corners is taken out first (Kabsch): a shift
  // of the principal point is partly a turn of the camera, which the board poses absorb.
  const UncertaintyMap map = projection_uncertainty(r, 0, 3.0);
  std::vector<Eigen::Vector3d> rays_published, rays_ours;
  for (const CornerResidual& c : r.residuals) {
    if (c.outlier) continue;
    const Eigen::Vector2d a = unproject(published, c.observed), b = unproject(ours, c.observed);
    rays_published.push_back(Eigen::Vector3d(a.x(), a.y(), 1.0).normalized());
    rays_ours.push_back(Eigen::Vector3d(b.x(), b.y(), 1.0).normalized());
  }
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < rays_ours.size(); ++i) H += rays_ours[i] * rays_published[i].transpose();
  const Eigen::Matrix3d R_ours_published = nearest_rotation(H);  // Kabsch: the SVD projection
  std::printf("rotation taken out: %.4f deg\n",
              Eigen::AngleAxisd(R_ours_published).angle() * 180.0 / M_PI);
  std::vector<char> seen(map.sigma_px.size(), 0);
  std::vector<double> differences, sigma_there;
  size_t k_ray = 0;
  for (const CornerResidual& c : r.residuals) {
    if (c.outlier) continue;
    const std::optional<Eigen::Vector2d> q =
        project(ours, R_ours_published * rays_published[k_ray++]);
    ASSERT_TRUE(q);
    differences.push_back((*q - c.observed).norm());
    const int col = static_cast<int>(c.observed.x() / map.cell_px);
    const int row = static_cast<int>(c.observed.y() / map.cell_px);
    const size_t cell = static_cast<size_t>(row) * map.cols + col;
    seen[cell] = 1;
    sigma_there.push_back(map.sigma_px[cell]);
  }
  double outside = 0;
  size_t n_seen = 0;
  for (size_t k = 0; k < seen.size(); ++k) {
    if (seen[k])
      ++n_seen;
    else
      outside = std::max(outside, map.sigma_px[k]);
  }
  std::printf(
      "corners in %zu of %zu cells of %.0f px; projection 1-sigma there: rms %.3f px, max %.3f; "
      "elsewhere up to %.1f px; published vs rigcal at the corners: rms %.3f px, max %.3f\n",
      n_seen, seen.size(), map.cell_px, rms(sigma_there),
      *std::max_element(sigma_there.begin(), sigma_there.end()), outside, rms(differences),
      *std::max_element(differences.begin(), differences.end()));
  EXPECT_LT(n_seen * 5, seen.size()) << "the board covered a band, not the image";
  EXPECT_LT(rms(sigma_there), 1.0);
  EXPECT_GT(outside, 20 * rms(sigma_there)) << "the lens is extrapolated away from the band";
  // Two calibrations of one lens agree, where both measured it, to within a pixel (over the
  // whole image they differ by tens of pixels: `rigcal diff` on the two files).
  EXPECT_LT(rms(differences), 1.0);
}

// Rectified with the true lenses and extrinsic, a point's rows agree in both cameras (to the
// lens's inversion); with the right camera's extrinsic wrong by a turn of 0.2 deg about its x
// axis, they differ by about f * 0.2 deg, as a person would read off the figure.
TEST(StereoRectification, RowsAgreeWithTheTruthAndNotWithATurnedCamera) {
  const rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  const rig::CameraModel &left = rig::sensor(rig, "cam_l").camera,
                         &right = rig::sensor(rig, "cam_r").camera;
  const SE3 T_r_l = rig::T_a_b(rig, "cam_r", "cam_l");
  SE3 T_r_l_wrong = T_r_l;
  T_r_l_wrong.R = rotation_from_vector(Eigen::Vector3d(0.2 * M_PI / 180, 0, 0)) * T_r_l.R;
  Detection in_l, in_r;
  for (int i = 0; i < 60; ++i) {
    // Points 2-6 m ahead, spread over both images.
    const Eigen::Vector3d p_l(-1.0 + 0.04 * i, -0.6 + 0.02 * (i % 7) * 9, 2.0 + 0.07 * i);
    const std::optional<Eigen::Vector2d> ql = project(left, p_l), qr = project(right, T_r_l * p_l);
    if (!ql || !qr) continue;
    in_l.point_ids.push_back(i), in_l.pixels.push_back(*ql);
    in_r.point_ids.push_back(i), in_r.pixels.push_back(*qr);
  }
  ASSERT_GT(in_l.pixels.size(), 40u);
  const Rectification truth = rectify(left, right, T_r_l);
  for (double d : row_differences(truth, left, right, in_l, in_r)) EXPECT_LT(std::abs(d), 1e-6);
  const Rectification wrong = rectify(left, right, T_r_l_wrong);
  const std::vector<double> rows = row_differences(wrong, left, right, in_l, in_r);
  const double expected = wrong.f_px * std::tan(0.2 * M_PI / 180);
  EXPECT_NEAR(rms(rows), expected, 0.1 * expected);
}

// The quick look's label of point 0 is drawn outside the corners: no red pixel (the label, its
// line, point 0's circle) within 6 px of another corner.
TEST(CameraReport, PointZerosLabelCoversNoCorner) {
  Detection d;
  d.found = true;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 9; ++c) {
      d.point_ids.push_back(r * 9 + c);
      d.pixels.emplace_back(300 + 25 * c + 3 * r, 150 + 24 * r - 2 * c);
    }
  const cv::Mat png = corners_png(cv::Mat(480, 640, CV_8UC1, cv::Scalar(128)), d);
  int red = 0;
  for (int y = 0; y < png.rows; ++y) {
    for (int x = 0; x < png.cols; ++x) {
      const cv::Vec3b bgr = png.at<cv::Vec3b>(y, x);
      if (!(bgr[2] > 180 && bgr[1] < 90 && bgr[0] < 90)) continue;
      ++red;
      for (size_t i = 1; i < d.pixels.size(); ++i)
        EXPECT_GT((d.pixels[i] - Eigen::Vector2d(x, y)).norm(), 6.0) << x << " " << y;
    }
  }
  EXPECT_GT(red, 50);  // the label is there
}

struct SimCase {
  rig::DistortionModel model;
  std::vector<double> left_coeffs, right_coeffs;
  std::string target_file;  // empty: the simulator's default, the A3 checkerboard
};

// The projection error, as mrcal defines it, of the pixel q at distance d: the true point
// p_c = d * ray(q) (true lens) fixed in the true board frames, found again by the estimate as
// the mean over the frames of T^_cam0_board_f p_board_f, then T^_c_0 and the estimated lens.
// Compared with the mrcal-style map's 1-sigma of that cell: |e| / sigma_worst.
std::vector<double> projection_z(const CalibrationResult& r, const sim::StereoPart& part,
                                 const rig::Rig& rig, int camera, double distance, bool print) {
  const rig::CameraModel& truth = rig::sensor(rig, camera ? "cam_r" : "cam_l").camera;
  const SE3 T_c0_true = rig::T_a_b(rig, camera ? "cam_r" : "cam_l", "cam_l");
  const UncertaintyMap map = projection_uncertainty(r, camera, distance);
  std::vector<double> z;
  for (const auto& [fr, fc] : std::vector<std::pair<double, double>>{
           {0.5, 0.5}, {0.25, 0.25}, {0.25, 0.75}, {0.75, 0.25}, {0.75, 0.75}}) {
    const int row = static_cast<int>(fr * map.rows), col = static_cast<int>(fc * map.cols);
    const Eigen::Vector2d q((col + 0.5) * map.cell_px, (row + 0.5) * map.cell_px);
    const Eigen::Vector2d xn = unproject(truth, q);
    const Eigen::Vector3d p_0 =
        T_c0_true.inverse() * (distance * Eigen::Vector3d(xn.x(), xn.y(), 1.0).normalized());
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    int n = 0;
    for (size_t f = 0; f < r.board_covariance_index.size(); ++f) {
      if (r.board_covariance_index[f] < 0) continue;
      mean += *r.T_cam0_board[f] * (part.T_left_board[f].inverse() * p_0);
      ++n;
    }
    const Eigen::Vector2d q_est =
        *project(r.cameras[camera].model, r.T_cam_cam0[camera] * (mean / n));
    const double sigma = map.sigma_px[row * map.cols + col];
    z.push_back((q_est - q).norm() / sigma);
    if (print) {
      std::printf(
          "  camera %d pixel (%.0f, %.0f): projection error %.4f px (%+.4f, %+.4f), mrcal-style "
          "1-sigma %.4f px\n",
          camera, q.x(), q.y(), (q_est - q).norm(), (q_est - q).x(), (q_est - q).y(), sigma);
    }
  }
  return z;
}

// The reported uncertainty against the Cramér–Rao bound computed here (camera_bound.h: OpenCV's
// projection, central differences, the true parameters, the corner noise measured against
// truth), and the errors against both. Fills `out`'s figures; with `strict`, asserts:
// - the bound well-posed (condition of the scaled normal matrix below 1e8; measured 2.1e6-4.1e6
//   on the A3 board over 20 seeds and both models, 7.2e5 with the AprilGrid);
// - the reported 1-sigma of every parameter within [kSigmaOverBoundMin, kSigmaOverBoundMax]
//   times the bound's (camera_truth.h);
// - the solver's error equal to the bound's first-order least-squares error for the same corners
//   within 0.1 reported sigma (measured: within 0.01): the solver reaches the optimum, so that
//   what remains between its errors and the bound is the corners' noise, not the solver;
// - per group, the errors' squared Mahalanobis distance under the reported covariance of the group
//   below chi-square's 0.999 quantile with n = the group's size degrees of freedom. For an
//   efficient estimator whose covariance is the reported one, that distance is chi-square(n)
//   distributed, so one seed fails by chance once in a thousand per group. The full covariance
//   block and not the pooled error / sigma: the parameters of a group are correlated (the largest
//   |rho| is printed), and the sum of squared correlated z's is not chi-square(n) (its tail is
//   heavier: with rho = 1 its 0.999 quantile is n * 10.8, against 18.5 for n = 4).
void compare_with_the_bound(const CalibrationResult& r, const rig::Rig& rig,
                            const sim::StereoPart& part, const Target& target, const SE3& T_true,
                            const Eigen::Vector3d& rot_err_deg, uint64_t seed, bool print,
                            bool strict, TruthZ& out) {
  const auto start = std::chrono::steady_clock::now();
  const std::vector<rig::CameraModel> truth = {rig::sensor(rig, "cam_l").camera,
                                               rig::sensor(rig, "cam_r").camera};
  const CramerRaoBound bound = cramer_rao_bound(truth, {SE3(), T_true}, part.T_left_board,
                                                object_points(target), r.residuals);
  // The reported values in the bound's layout: intrinsics, then the rotation (deg; the solver's
  // covariance is in Ceres' quaternion tangent, half the angle) and the translation, taken from
  // the solver's covariance at its per-camera indices.
  const int NK = static_cast<int>(r.cameras[0].stddev.size());
  const int K = 2 * NK + 6;
  ASSERT_EQ(bound.sigma.size(), K);
  Eigen::VectorXd error(K), unit = Eigen::VectorXd::Ones(K);
  std::vector<std::string> group(K);
  std::vector<int> at(K);  // where each parameter is in the solver's covariance
  for (int c = 0; c < 2; ++c) {
    const std::vector<double> k_true = intrinsics_vector(truth[c]),
                              k_est = intrinsics_vector(r.cameras[c].model);
    ASSERT_EQ(static_cast<int>(k_est.size()), NK);
    for (int i = 0; i < NK; ++i) {
      error[c * NK + i] = k_est[i] - k_true[i];
      group[c * NK + i] = kParameterGroups[i < 2 ? 0 : i < 4 ? 1 : 2];
      at[c * NK + i] = r.intrinsics_covariance_index[c] + i;
    }
  }
  for (int i = 0; i < 3; ++i) {
    error[2 * NK + i] = rot_err_deg[i];
    error[2 * NK + 3 + i] = r.T_cam_cam0[1].t[i] - T_true.t[i];
    unit[2 * NK + i] = 360.0 / M_PI;
    group[2 * NK + i] = kParameterGroups[3];
    group[2 * NK + 3 + i] = kParameterGroups[4];
    at[2 * NK + i] = r.pose_covariance_index[1] + i;
    at[2 * NK + 3 + i] = r.pose_covariance_index[1] + 3 + i;
  }
  Eigen::MatrixXd reported(K, K);
  for (int i = 0; i < K; ++i)
    for (int j = 0; j < K; ++j) reported(i, j) = unit[i] * r.covariance(at[i], at[j]) * unit[j];
  out.noise_truth_px = bound.noise_sigma_px;
  out.noise_reported_px = r.noise_sigma_px;
  out.bound_condition = bound.condition;
  out.view_mean_z_rms = bound.view_mean_z_rms;
  out.neighbour_correlation = bound.neighbour_correlation;
  out.figures.clear();
  for (int k = 0; k < K; ++k) {
    out.figures.push_back({bound.names[k], group[k], error[k], std::sqrt(reported(k, k)),
                           bound.sigma[k], bound.lsq_error[k]});
  }
  out.groups.clear();
  std::map<std::string, double> max_rho;  // the largest |correlation| in a group, printed
  for (const char* g : kParameterGroups) {
    std::vector<int> idx;
    for (int k = 0; k < K; ++k)
      if (group[k] == g) idx.push_back(k);
    const int n = static_cast<int>(idx.size());
    Eigen::VectorXd e(n);
    Eigen::MatrixXd C(n, n), B(n, n);
    for (int i = 0; i < n; ++i) {
      e[i] = error[idx[i]];
      for (int j = 0; j < n; ++j) {
        C(i, j) = reported(idx[i], idx[j]);
        B(i, j) = bound.covariance(idx[i], idx[j]);
      }
    }
    out.groups.push_back({g, n, e.dot(C.ldlt().solve(e)), e.dot(B.ldlt().solve(e))});
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < i; ++j)
        max_rho[g] = std::max(max_rho[g], std::abs(C(i, j)) / std::sqrt(C(i, i) * C(j, j)));
  }
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (print) {
    std::printf(
        "seed %lu, the bound (%zu inlier corners, %zu frames, %zu parameters, condition %.2e, "
        "%.0f ms): corner noise against truth %.4f px per coordinate (mean %+.4f %+.4f), the "
        "solver's from the residuals %.4f px; independent corners? per-view mean error %.2f "
        "sigma rms (1 if so), neighbours' correlation %+.3f (0)\n",
        seed, bound.n_corners, bound.n_frames, bound.n_parameters, bound.condition, ms,
        bound.noise_sigma_px, bound.noise_mean_px.x(), bound.noise_mean_px.y(), r.noise_sigma_px,
        bound.view_mean_z_rms, bound.neighbour_correlation);
    std::printf("  %-26s %11s %11s %11s %7s %7s %11s\n", "parameter", "error", "reported", "bound",
                "rep/bnd", "err/rep", "lsq error");
    for (const TruthZ::Parameter& p : out.figures) {
      std::printf("  %-26s %+11.3e %11.3e %11.3e %7.3f %+7.2f %+11.3e\n", p.name.c_str(), p.error,
                  p.sigma, p.bound, p.sigma / p.bound, p.error / p.sigma, p.lsq_error);
    }
    for (const TruthZ::Group& g : out.groups) {
      std::printf(
          "  %-18s squared Mahalanobis distance %6.2f under the reported covariance (%d dof: "
          "P(chi2 >= it) = %.3f), %6.2f under the bound's; largest |correlation| %.2f\n",
          g.group.c_str(), g.mahalanobis2, g.n, chi2_upper_tail(g.mahalanobis2, g.n),
          g.mahalanobis2_bound, max_rho[g.group]);
    }
  }
  if (!strict) return;
  // A well-posed bound: the normal matrix (columns scaled) far from singular.
  EXPECT_LT(bound.condition, 1e8);
  for (const TruthZ::Parameter& p : out.figures) {
    EXPECT_LE(p.sigma, kSigmaOverBoundMax * p.bound) << p.name;
    EXPECT_GE(p.sigma, kSigmaOverBoundMin * p.bound) << p.name;
    EXPECT_LE(std::abs(p.error - p.lsq_error), 0.1 * p.sigma) << p.name;
  }
  for (const TruthZ::Group& g : out.groups)
    EXPECT_GE(chi2_upper_tail(g.mahalanobis2, g.n), 0.001) << g.group << ": " << g.mahalanobis2;
}

// Simulated truth: the default 40 views of the A3 board at the default noise, 1388 x 700.
// Returns, per checked quantity, the error in units of the reported 1-sigma.
TruthZ check_against_truth(const SimCase& sc, uint64_t seed, bool print, bool strict = true) {
  rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  rig::sensor(rig, "cam_l").camera.distortion_model = sc.model;
  rig::sensor(rig, "cam_r").camera.distortion_model = sc.model;
  rig::sensor(rig, "cam_l").camera.distortion_coeffs = sc.left_coeffs;
  rig::sensor(rig, "cam_r").camera.distortion_coeffs = sc.right_coeffs;
  sim::SimConfig cfg;
  cfg.seed = seed;
  if (!sc.target_file.empty()) cfg.target = io::read_target_file(sc.target_file);
  const sim::StereoPart part = sim::simulate_stereo(rig, cfg);
  const std::vector<CameraInput> cams = detect_stereo(part, cfg.target);
  CalibrationOptions opt;
  opt.model = sc.model;
  const CalibrationResult r = calibrate(cfg.target, cams, opt);
  const SE3 T_true = rig::T_a_b(rig, "cam_r", "cam_l");
  TruthZ out;
  for (int c = 0; c < 2; ++c) {
    const rig::CameraModel& truth = rig::sensor(rig, c ? "cam_r" : "cam_l").camera;
    const rig::CameraModel& est = r.cameras[c].model;
    const double f_rel = std::max(std::abs(est.fx / truth.fx - 1), std::abs(est.fy / truth.fy - 1));
    const double pp = std::max(std::abs(est.cx - truth.cx), std::abs(est.cy - truth.cy));
    out.focal_rel = std::max(out.focal_rel, f_rel);
    out.principal_point_px = std::max(out.principal_point_px, pp);
    out.principal_point_sigma_px.push_back(r.cameras[c].stddev[2]);
    out.principal_point_sigma_px.push_back(r.cameras[c].stddev[3]);
    if (print) {
      std::printf(
          "seed %lu camera %d: focal rel. error %.2e, principal point %.3f px (1-sigma reported "
          "%.3f, %.3f)\n",
          seed, c, f_rel, pp, r.cameras[c].stddev[2], r.cameras[c].stddev[3]);
    }
    if (strict) {
      EXPECT_LE(f_rel, 2e-4) << "camera " << c;
    }
    // The issue's bar of 0.3 px is below what 40 views of the A3 board determine (reported
    // 1-sigma ~0.2-0.3 px, doc/cameras.md): asserted is that the reported uncertainty covers it.
    if (strict) {
      EXPECT_LE(std::abs(est.cx - truth.cx), 3 * r.cameras[c].stddev[2]) << "camera " << c;
      EXPECT_LE(std::abs(est.cy - truth.cy), 3 * r.cameras[c].stddev[3]) << "camera " << c;
    }
  }
  const double baseline_err = std::abs(r.T_cam_cam0[1].t.norm() - T_true.t.norm());
  const Eigen::Vector3d rot_err =
      rotation_vector(r.T_cam_cam0[1].R * T_true.R.transpose()) * 180 / M_PI;
  if (print) {
    std::printf(
        "seed %lu: baseline error %.3f mm, stereo rotation error %.4f deg (1-sigma reported: %.4f "
        "%.4f %.4f), RMS %.3f px\n",
        seed, 1000 * baseline_err, rot_err.norm(), r.rotation_stddev_deg[1].x(),
        r.rotation_stddev_deg[1].y(), r.rotation_stddev_deg[1].z(), r.rms_2d_px);
  }
  if (strict) {
    EXPECT_LE(baseline_err, 2e-4);
  }
  // The issue's bar of 0.01 deg is not met with this board: the reported 1-sigma is ~0.015 deg
  // about y, and the errors agree with it (doc/cameras.md). What is asserted: the reported
  // uncertainty covers the error.
  if (strict) {
    EXPECT_LE(std::abs(rot_err.x()), 3 * r.rotation_stddev_deg[1].x() + 1e-4);
    EXPECT_LE(std::abs(rot_err.y()), 3 * r.rotation_stddev_deg[1].y() + 1e-4);
  }
  // Errors in sigmas: fx, fy, cx, cy of both cameras, and the three rotation axes.
  std::vector<double> z;
  for (int c = 0; c < 2; ++c) {
    const rig::CameraModel& truth = rig::sensor(rig, c ? "cam_r" : "cam_l").camera;
    const std::vector<double> k_true = intrinsics_vector(truth),
                              k_est = intrinsics_vector(r.cameras[c].model);
    for (int i = 0; i < 4; ++i)
      z.push_back(std::abs(k_est[i] - k_true[i]) / r.cameras[c].stddev[i]);
  }
  for (int i = 0; i < 3; ++i) z.push_back(std::abs(rot_err[i]) / r.rotation_stddev_deg[1][i]);
  compare_with_the_bound(r, rig, part, cfg.target, T_true, rot_err, seed, print, strict, out);
  // Projection uncertainty as mrcal defines it, at the median board distance.
  std::vector<double> distances;
  for (const auto& T : r.T_cam0_board) {
    if (T) distances.push_back(T->t.norm());
  }
  const double d = median(distances);
  std::vector<double> zp;
  for (int c = 0; c < 2; ++c) {
    for (double x : projection_z(r, part, rig, c, d, print)) zp.push_back(x);
  }
  if (strict) {
    // One seed is one draw of a mostly common error (the ten pixels move together): a gross
    // check here (a wrong Jacobian or a factor of 2 shows as 5 sigma and more); the statistical
    // check over 20 seeds is tests/long (CameraSimLong). Seed 1 gives at most 1.5 sigma on the
    // A3 board with radtan, 3.4 with equidistant, 3.7 with the AprilGrid (doc/cameras.md).
    for (double x : zp) EXPECT_LE(x, 5.0);
  }
  out.parameters = z;
  out.projection = zp;
  out.baseline_m = baseline_err;
  out.rotation_deg = rot_err.norm();
  out.rotation_sigma_deg = r.rotation_stddev_deg[1];
  return out;
}

const SimCase kRadtan{rig::DistortionModel::radtan,
                      {-0.0921, 0.0874, 0.00031, -0.00027},
                      {-0.0897, 0.0832, -0.00019, 0.00042},
                      ""};
const SimCase kEquidistant{rig::DistortionModel::equidistant,
                           {0.02, -0.015, 0.004, -0.001},
                           {0.018, -0.012, 0.003, -0.0008},
                           ""};

}  // namespace

std::vector<CameraInput> detect_stereo(const sim::StereoPart& part, const Target& target) {
  std::vector<CameraInput> cams(2);
  cams[0].name = "cam_l";
  cams[1].name = "cam_r";
  for (size_t k = 0; k < part.left.size(); ++k) {
    cams[0].frames.push_back(detect(part.left[k], target));
    cams[1].frames.push_back(detect(part.right[k], target));
  }
  for (CameraInput& c : cams) c.width = 1388, c.height = 700;
  return cams;
}

// For tests/long: the same check for any seed.
TruthZ check_against_truth_for_long_test(rig::DistortionModel model, uint64_t seed) {
  return check_against_truth(model == rig::DistortionModel::radtan ? kRadtan : kEquidistant, seed,
                             /*print=*/true, /*strict=*/false);
}

TruthZ check_aprilgrid_for_long_test(uint64_t seed) {
  SimCase sc = kRadtan;
  sc.target_file = RIGCAL_SOURCE_DIR "/targets/aprilgrid_6x6_88mm.yaml";
  return check_against_truth(sc, seed, /*print=*/false, /*strict=*/false);
}

namespace {

TEST(CameraSim, RadtanMeetsTheTruthBar) { check_against_truth(kRadtan, 1, true); }

TEST(CameraSim, EquidistantMeetsTheTruthBar) { check_against_truth(kEquidistant, 1, true); }

// The same 40 views with the 6 x 6 AprilGrid (88 mm tags, 144 corners a view where the A3 board
// has 40). The issue's focal, principal-point and baseline bars hold here on seed 1 with room; the
// 0.01 deg stereo-rotation bar does not hold in general (seed 1 gives 0.0097 deg, at the edge): it
// is a rate, asserted over 20 seeds in tests/long (CameraSimLong.AprilGridBarsOver20Seeds, see
// doc/cameras.md: 14 of 20). Here the rotation is held to 0.02 deg, which all 20 meet (max
// 0.0160 deg).
TEST(CameraSim, AprilGridSeedOneAgainstTheIssuesBars) {
  SimCase sc = kRadtan;
  sc.target_file = RIGCAL_SOURCE_DIR "/targets/aprilgrid_6x6_88mm.yaml";
  const TruthZ t = check_against_truth(sc, 1, true);
  std::printf(
      "AprilGrid, radtan, seed 1: focal %.2e, principal point %.3f px, baseline %.3f mm, "
      "rotation %.4f deg\n",
      t.focal_rel, t.principal_point_px, 1e3 * t.baseline_m, t.rotation_deg);
  EXPECT_LE(t.focal_rel, 2e-4);
  EXPECT_LE(t.principal_point_px, 0.3);
  EXPECT_LE(t.baseline_m, 0.2e-3);
  EXPECT_LE(t.rotation_deg, 0.02);
}

TEST(CameraInputErrors, ClearMessages) {
  const Target target = sim::default_target();
  std::vector<CameraInput> cams(1);
  cams[0].name = "cam_l";
  cams[0].width = 100;
  cams[0].height = 100;
  cams[0].frames.resize(2);
  try {
    calibrate(target, cams);
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "camera cam_l: 0 usable views of the target; at least 3 are needed");
  }
  cams.push_back(cams[0]);
  cams[1].frames.resize(3);
  EXPECT_THROW(calibrate(target, cams), Error);
}

}  // namespace
}  // namespace rigcal::camera

namespace rigcal::camera {
namespace {

// `rigcal target print`: the PDF rendered back to pixels by poppler detects as the target, at the
// printed scale.
TEST(TargetPdf, RendersBackToTheTargetAtExactScale) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("rigcal_pdf_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (const char* name : {"a3_checkerboard_8x5_40mm", "aprilgrid_6x6_88mm"}) {
    SCOPED_TRACE(name);
    const Target t =
        io::read_target_file(std::string(RIGCAL_SOURCE_DIR "/targets/") + name + ".yaml");
    const std::string pdf = io::target_pdf(t);
    ASSERT_EQ(pdf.substr(0, 5), "%PDF-");
    std::ofstream((dir / "t.pdf").string(), std::ios::binary) << pdf;
    const int dpi = 72;
    ASSERT_EQ(std::system(fmt::format("pdftoppm -r {} -gray -png -singlefile {} {}", dpi,
                                      (dir / "t.pdf").string(), (dir / "t").string())
                              .c_str()),
              0)
        << "pdftoppm (poppler-utils) is needed";
    const cv::Mat img = cv::imread((dir / "t.png").string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(img.empty());
    const Detection d = detect(img, t);
    ASSERT_TRUE(d.found) << d.note;
    EXPECT_EQ(d.pixels.size(), object_points(t).size());  // every corner, every tag
    // Scale: the distance between points 0 and 1 is one square (checkerboard) or one tag side.
    const double expected_px =
        (t.type == TargetType::checkerboard ? t.square : t.tag_size) * dpi / 0.0254;
    size_t i0 = 0, i1 = 0;
    for (size_t k = 0; k < d.point_ids.size(); ++k) {
      if (d.point_ids[k] == 0) i0 = k;
      if (d.point_ids[k] == 1) i1 = k;
    }
    EXPECT_NEAR((d.pixels[i1] - d.pixels[i0]).norm(), expected_px, 0.01 * expected_px);
    // Point 0 of a checkerboard (rows down the page) is top left; of an AprilGrid, bottom left.
    if (t.type == TargetType::checkerboard) {
      EXPECT_LT(d.pixels[i0].y(), d.pixels.back().y());
    } else {
      EXPECT_GT(d.pixels[i0].y(), img.rows / 2);
    }
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace rigcal::camera

namespace rigcal::camera {
namespace {

// Acceptance 2, mrcal: mrcal-calibrate-cameras on rigcal's own corners.vnl, same model
// (LENSMODEL_OPENCV4 = k1 k2 p1 p2), without mrcal's board-warp parameters (rigcal has none).
// Both report the per-coordinate RMS; mrcal's includes its regularization.
TEST(CameraPeers, MrcalOnTheSameCorners) {
  RIGCAL_REQUIRE_FIXTURE(dir, "stereo/opencv_samples");
  if (std::system("command -v mrcal-calibrate-cameras > /dev/null") != 0) {
    GTEST_SKIP() << "mrcal-calibrate-cameras (Debian package mrcal) not installed";
  }
  const Target target =
      io::read_target_file(RIGCAL_SOURCE_DIR "/targets/checkerboard_9x6_25mm.yaml");
  const std::vector<CameraInput> cams = opencv_sample_detections(dir, target);
  const CalibrationResult ours = calibrate(target, cams);
  std::vector<std::string> names;
  std::vector<Detection> detections;
  const int ids[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 14};
  for (int c = 0; c < 2; ++c) {
    for (size_t f = 0; f < 13; ++f) {
      names.push_back(fmt::format("{}/{}{:02d}.jpg", dir, c ? "right" : "left", ids[f]));
      detections.push_back(cams[c].frames[f]);
    }
  }
  const std::filesystem::path work =
      std::filesystem::temp_directory_path() / ("rigcal_mrcal_" + std::to_string(::getpid()));
  std::filesystem::create_directories(work);
  std::ofstream((work / "corners.vnl").string()) << camera::corners_vnl(target, names, detections);
  const std::string cmd = fmt::format(
      "cd {} && mrcal-calibrate-cameras --corners-cache corners.vnl --lensmodel LENSMODEL_OPENCV4 "
      "--focal 535 "
      "--object-spacing 0.025 --object-width-n 9 --object-height-n 6 --imagersize 640 480 --outdir "
      ". "
      "--skip-calobject-warp-solve '{}/left*.jpg' '{}/right*.jpg' > mrcal.log 2>&1",
      work.string(), dir, dir);
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream log((work / "mrcal.log").string());
  std::string line;
  double mrcal_rms = -1;
  while (std::getline(log, line)) {
    if (line.rfind("## RMS error: ", 0) == 0) mrcal_rms = std::stod(line.substr(14));
  }
  ASSERT_GT(mrcal_rms, 0) << "no RMS in mrcal's output";
  std::printf(
      "per-coordinate RMS on the same corners, k1 k2 p1 p2, outliers rejected: rigcal %.5f px (%zu "
      "outliers), mrcal %.5f px\n",
      ours.rms_coord_px, ours.n_outliers, mrcal_rms);
  RecordProperty("mrcal_rms_per_coordinate_px", std::to_string(mrcal_rms));
  EXPECT_LE(ours.rms_coord_px, 1.01 * mrcal_rms);
  std::filesystem::remove_all(work);
}

}  // namespace
}  // namespace rigcal::camera

namespace rigcal::camera {
namespace {

TEST(CameraDetect, NoBoardIsAnAnswerAndAHalfTurnIsCaught) {
  // An image without a board: found = false (the probe keeps this well under a second; speed is
  // measured in doc/performance.md, not here).
  cv::Mat noise(700, 1388, CV_8UC1);
  cv::randu(noise, 60, 200);
  const Target board = sim::default_target();
  EXPECT_FALSE(detect(noise, board).found);
  EXPECT_FALSE(detect(cv::Mat(700, 1388, CV_8UC1, cv::Scalar(128)), board).found);
  // A board seen upside down: point 0 is still the same physical corner.
  const rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  sim::SimConfig cfg;
  cfg.boards.views = 3;
  const sim::StereoPart part = sim::simulate_stereo(rig, cfg);
  for (size_t k = 0; k < part.left.size(); ++k) {
    const Detection upright = detect(part.left[k], cfg.target);
    cv::Mat turned;
    cv::rotate(part.left[k], turned, cv::ROTATE_180);
    const Detection flipped = detect(turned, cfg.target);
    ASSERT_TRUE(upright.found && flipped.found);
    const Eigen::Vector2d p0_turned(1387 - flipped.pixels[0].x(), 699 - flipped.pixels[0].y());
    EXPECT_LT((p0_turned - upright.pixels[0]).norm(), 0.5) << "view " << k;
    EXPECT_LT((upright.pixels[0] - part.corners_left[k][0]).norm(), 0.5) << "view " << k;
  }
}

}  // namespace
}  // namespace rigcal::camera

namespace rigcal::camera {
namespace {

// AprilGrid detection on simulated grids: the rate and the corners against truth. Measured over
// 40 images (doc/cameras.md): 65 % of tags, median 0.058 px.
TEST(CameraDetect, AprilGridCornersMatchTruth) {
  const rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  sim::SimConfig cfg;
  cfg.target = io::read_target_file(RIGCAL_SOURCE_DIR "/targets/aprilgrid_6x6_88mm.yaml");
  cfg.boards.views = 5;
  const sim::StereoPart part = sim::simulate_stereo(rig, cfg);
  std::vector<double> errors;
  size_t tags = 0;
  for (size_t k = 0; k < part.left.size(); ++k) {
    const Detection d = detect(part.left[k], cfg.target);
    if (!d.found) continue;
    tags += d.pixels.size() / 4;
    for (size_t i = 0; i < d.pixels.size(); ++i)
      errors.push_back((d.pixels[i] - part.corners_left[k][d.point_ids[i]]).norm());
  }
  ASSERT_FALSE(errors.empty());
  std::sort(errors.begin(), errors.end());
  std::printf("AprilGrid: %zu of %zu tags, median corner error %.3f px\n", tags,
              part.left.size() * 36, median(errors));
  EXPECT_GE(tags, part.left.size() * 36 / 2);
  EXPECT_LT(median(errors), 0.1);
  EXPECT_LT(errors[errors.size() * 9 / 10], 0.3);
}

}  // namespace
}  // namespace rigcal::camera

namespace rigcal::camera {
namespace {

// Corners on a grid of the 1200 x 600 image, except where `skip` says.
CalibrationResult corners_where(const std::function<bool(double u, double v)>& skip) {
  CalibrationResult r;
  for (double u = 10; u < 1200; u += 40) {
    for (double v = 10; v < 600; v += 40) {
      if (skip(u, v)) continue;
      CornerResidual c;
      c.observed = {u, v};
      r.residuals.push_back(c);
    }
  }
  return r;
}

TEST(CameraReport, CoverageWarningsNameWhereTheImageHasNoCorners) {
  EXPECT_TRUE(
      coverage_warnings(corners_where([](double, double) { return false; }), 0, "cam_r", 1200, 600)
          .empty());
  const std::vector<std::string> half = coverage_warnings(
      corners_where([](double u, double) { return u > 560; }), 0, "cam_r", 1200, 600);
  ASSERT_EQ(half.size(), 1u);
  EXPECT_NE(half[0].find("cam_r: the right half of the image holds 0 of its"), std::string::npos)
      << half[0];
  // An outlier corner is no coverage; another camera's corners are not this one's.
  CalibrationResult r = corners_where([](double u, double v) { return u < 400 && v < 200; });
  CornerResidual stray;
  stray.observed = {50, 50};
  stray.outlier = true;
  r.residuals.push_back(stray);
  stray.outlier = false, stray.camera = 1;
  r.residuals.push_back(stray);
  const std::vector<std::string> ninth = coverage_warnings(r, 0, "cam_l", 1200, 600);
  ASSERT_EQ(ninth.size(), 1u);
  EXPECT_NE(ninth[0].find("cam_l: no corners in the top-left ninth"), std::string::npos)
      << ninth[0];
  // The corners and their residuals as the report's CSV.
  r.residuals[0].residual = {0.25, -0.5};
  const std::string csv = residuals_csv(r, {"cam_l", "cam_r"});
  EXPECT_EQ(csv.substr(0, csv.find('\n', csv.find('\n') + 1) + 1),
            "camera,view,point,u_px,v_px,residual_u_px,residual_v_px,outlier\n"
            "cam_l,0,0,10.000,210.000,0.25000,-0.50000,0\n");
  EXPECT_NE(csv.find("cam_r,0,0,50.000,50.000"), std::string::npos);
}

}  // namespace
}  // namespace rigcal::camera
