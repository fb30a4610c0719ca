#include "rigcal/camera/detect.h"

#include <fmt/format.h>

#include <algorithm>
#include <opencv2/aruco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "rigcal/core/stats.h"

namespace rigcal::camera {
namespace {

// cornerSubPix half-window from the local feature size: 0.25 of a square, 2..11 px. Measured
// (doc/cameras.md): larger windows win on sharp renders (0.4: 0.051 px vs truth), smaller ones on
// real blurred JPEGs (0.4: 0.44 px RMS on the OpenCV stereo samples; 0.25: 0.21 px).
int subpix_half_window(double feature_px) {
  return std::clamp(static_cast<int>(0.25 * feature_px), 2, 11);
}

// Mean intensity in a small disc, or -1 outside the image.
double sample(const cv::Mat& gray, const Eigen::Vector2d& p, int r) {
  const int u = static_cast<int>(std::lround(p.x())), v = static_cast<int>(std::lround(p.y()));
  if (u - r < 0 || v - r < 0 || u + r >= gray.cols || v + r >= gray.rows) return -1;
  return cv::mean(gray(cv::Rect(u - r, v - r, 2 * r + 1, 2 * r + 1)))[0];
}

Detection detect_checkerboard(const cv::Mat& gray, const Target& t, const DetectOptions& o) {
  Detection d;
  const cv::Size pattern(t.cols, t.rows);
  const double scale =
      std::min(1.0, static_cast<double>(o.probe_max_size) / std::max(gray.cols, gray.rows));
  cv::Mat probe;
  if (scale < 1.0)
    cv::resize(gray, probe, cv::Size(), scale, scale, cv::INTER_AREA);
  else
    probe = gray;
  std::vector<cv::Point2f> corners;
  double found_scale = scale;
  // Small images (no probe needed): the classic detector with its quick check first, ~10 ms a
  // 640 x 480 image where it succeeds against ~75 ms for SB (the 26 OpenCV samples: 0.36 s
  // against 1.96 s). Not on larger images: there it can take seconds on steep or far boards
  // that pass the quick check (100 rendered 1388 x 700 pairs: 38 s against 19 s).
  bool ok = false;
  if (scale == 1.0) {
    ok = cv::findChessboardCorners(
        gray, pattern, corners,
        cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK);
  }
  if (!ok) ok = cv::findChessboardCornersSB(probe, pattern, corners, cv::CALIB_CB_NORMALIZE_IMAGE);
  if (!ok && scale < 1.0) {
    // Small or steep boards are lost in the probe: try once at full resolution (0.1-0.2 s).
    ok = cv::findChessboardCornersSB(gray, pattern, corners, cv::CALIB_CB_NORMALIZE_IMAGE);
    found_scale = 1.0;
  }
  if (!ok && scale == 1.0) {
    // Small images: the classic detector is quick there and finds some boards SB misses.
    ok = cv::findChessboardCorners(gray, pattern, corners,
                                   cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE);
  }
  if (!ok) {
    d.note = "no checkerboard";
    return d;
  }
  for (cv::Point2f& c : corners) c *= static_cast<float>(1.0 / found_scale);
  // Square size in px, from neighbours along the rows.
  std::vector<double> sq;
  for (int j = 0; j < t.rows; ++j) {
    for (int i = 0; i + 1 < t.cols; ++i)
      sq.push_back(cv::norm(corners[j * t.cols + i + 1] - corners[j * t.cols + i]));
  }
  d.square_px = sq.empty() ? 0.0 : median(sq);  // empty: a target of one column
  const int w = subpix_half_window(d.square_px);
  cv::cornerSubPix(gray, corners, cv::Size(w, w), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4));
  std::vector<Eigen::Vector2d> px;
  for (const cv::Point2f& c : corners) px.emplace_back(c.x, c.y);
  // Point 0 must be the origin corner. OpenCV may start at either end (a half turn). The first
  // interior square, between corners 0, 1, cols and cols + 1, is black (doc/targets.md); for a
  // board with cols + rows odd, the square at the other end is white. Interior squares are always
  // in view, unlike the squares beyond the outer corners.
  const int n = t.cols * t.rows;
  auto square_centre = [&](int a, int b, int c, int e) {
    return 0.25 * (px[a] + px[b] + px[c] + px[e]);
  };
  const int r = std::max(1, static_cast<int>(0.15 * d.square_px));
  const double at_first = sample(gray, square_centre(0, 1, t.cols, t.cols + 1), r);
  const double at_last =
      sample(gray, square_centre(n - 1, n - 2, n - 1 - t.cols, n - 2 - t.cols), r);
  bool reverse = false;
  if ((t.cols + t.rows) % 2 == 1 && at_first >= 0 && at_last >= 0 &&
      std::abs(at_first - at_last) > 10) {
    reverse = at_first > at_last;  // the black one is the origin's
  } else {
    // A board symmetric under a half turn (cols + rows even): take the end nearer the image's
    // top-left, the same rule in every camera of a rig.
    reverse = px.back().x() + px.back().y() < px.front().x() + px.front().y();
    d.note = "corner order by image position (board symmetric under a half turn)";
  }
  if (reverse) std::reverse(px.begin(), px.end());
  d.pixels = px;
  d.point_ids.resize(n);
  for (int i = 0; i < n; ++i) d.point_ids[i] = i;
  d.found = true;
  return d;
}

Detection detect_aprilgrid(const cv::Mat& gray, const Target& t, const DetectOptions& o) {
  Detection d;
  static const cv::Ptr<cv::aruco::Dictionary> dict =
      cv::aruco::getPredefinedDictionary(cv::aruco::DICT_APRILTAG_36h11);
  cv::Ptr<cv::aruco::DetectorParameters> params = cv::aruco::DetectorParameters::create();
  params->markerBorderBits = 2;
  params->minMarkerDistanceRate = 0.01;  // Kalibr's neighbours are 0.3 tag sizes apart
  // Small tags fail in decoding (quads found, bits unread at ~3.5 px a bit): sampling each bit on
  // 8 x 8 pixels of the rectified tag, ignoring 0.25 of a bit at its edges, reads more of them.
  // On 40 simulated views of the 6 x 6 grid: 849 of 1440 tags against 800 with aruco's defaults
  // (adaptive-threshold windows 3..53 px add 18 more, at four times the detection time).
  params->perspectiveRemovePixelPerCell = 8;
  params->perspectiveRemoveIgnoredMarginPerCell = 0.25;
  std::vector<int> ids;
  std::vector<std::vector<cv::Point2f>> tags;
  cv::aruco::detectMarkers(gray, dict, tags, ids, params);
  const int n_tags = t.cols * t.rows;
  std::vector<cv::Point2f> corners;
  std::vector<double> sizes;
  int wrong = 0;
  for (size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] < 0 || ids[i] >= n_tags) {
      ++wrong;
      continue;
    }
    const int c = ids[i] % t.cols, r = ids[i] / t.cols;
    // aruco: top-left, top-right, bottom-right, bottom-left of the printed tag; Kalibr points:
    // (2c, 2r + 1), (2c + 1, 2r + 1), (2c + 1, 2r), (2c, 2r).
    const int m[4] = {2 * c, 2 * c + 1, 2 * c + 1, 2 * c};
    const int nn[4] = {2 * r + 1, 2 * r + 1, 2 * r, 2 * r};
    for (int k = 0; k < 4; ++k) {
      d.point_ids.push_back(nn[k] * 2 * t.cols + m[k]);
      corners.push_back(tags[i][k]);
    }
    sizes.push_back(0.25 * cv::arcLength(tags[i], true));
  }
  if (static_cast<int>(sizes.size()) < o.min_tags) {
    d.point_ids.clear();
    d.note = fmt::format("{} tags of the grid decoded (fewer than {})", sizes.size(), o.min_tags);
    return d;
  }
  // Tag corners meet the grid's corner squares: saddle points cornerSubPix refines. The window
  // (0.12 of the tag side) stays inside the tag's 2-bit border and the gap; measured on 40
  // simulated views: median 0.058 px from truth, 2.5 % of corners over 1 px (a jump to a
  // neighbouring saddle; the solver's outlier rejection drops them), where 0.2 sent 21 % over
  // 1 px. aruco's own corners are ~2 px off on these grids (the tag's outline touches the corner
  // squares), so refinement is needed.
  d.square_px = sizes.empty() ? 0.0 : median(sizes);  // empty: no tag with min_tags <= 0
  const int w = std::clamp(static_cast<int>(0.12 * d.square_px), 2, 11);
  cv::cornerSubPix(gray, corners, cv::Size(w, w), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4));
  for (const cv::Point2f& c : corners) d.pixels.emplace_back(c.x, c.y);
  if (wrong) d.note = fmt::format("{} tags with ids outside the grid ignored", wrong);
  d.found = true;
  return d;
}

}  // namespace

Detection detect(const cv::Mat& gray, const Target& target, const DetectOptions& options) {
  CV_Assert(gray.type() == CV_8UC1);
  return target.type == TargetType::checkerboard ? detect_checkerboard(gray, target, options)
                                                 : detect_aprilgrid(gray, target, options);
}

}  // namespace rigcal::camera
