#include "rigcal/camera/detect.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <map>
#include <opencv2/aruco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "rigcal/camera/saddle.h"
#include "rigcal/core/stats.h"

namespace rigcal::camera {
namespace {

// cornerSubPix half-window from the local feature size: 0.25 of a square, 2..11 px. Measured
// (doc/cameras.md): larger windows win on sharp renders (0.4: 0.051 px vs truth), smaller ones on
// real blurred JPEGs (0.4: 0.44 px RMS on the OpenCV stereo samples; 0.25: 0.21 px).
int subpix_half_window(double feature_px) {
  return std::clamp(static_cast<int>(0.25 * feature_px), 2, 11);
}

// Each corner located by the saddle fit (saddle.h) in a disc of `radius_px`, at most
// kSaddleDiscMaxPx, where the fit converges within a pixel of cornerSubPix's estimate; elsewhere
// cornerSubPix's is kept. Discs under 2.5 px (too few pixels for seven parameters) are not
// tried. The cap, measured on the simulator's default session (seed 1, 40 stereo views of the A3
// board; doc/cameras.md): corner noise 0.029 / 0.024 / 0.020 / 0.015 px with discs of 3 / 4 / 5
// / up to 10 px, against 0.050 px for cornerSubPix alone; on a board bent by (4, -2) mm the
// edges' curvature then biases the left camera's cy by 1.9 / 2.4 / 3.0 / 5.5 of its reported
// sigma. Four keeps every parameter within 3 sigma there.
constexpr double kSaddleDiscMaxPx = 4.0;

void fit_saddles(const cv::Mat& gray, std::vector<Eigen::Vector2d>& corners, double radius_px) {
  if (radius_px < 2.5) return;
  for (Eigen::Vector2d& c : corners) {
    const SaddleFit f = fit_saddle(gray, c, std::min(radius_px, kSaddleDiscMaxPx));
    if (f.ok) c = f.corner;
  }
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
  // The squares are the saddle's quadrants: the disc stays a blur's width inside them.
  if (o.fit_saddles) fit_saddles(gray, px, 0.5 * d.square_px - 1.5);
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

// The Kalibr point ids of tag `id`'s corners in aruco's order (the printed tag's top left, top
// right, bottom right, bottom left): (2c, 2r + 1), (2c + 1, 2r + 1), (2c + 1, 2r), (2c, 2r).
std::array<int, 4> tag_point_ids(const Target& t, int id) {
  const int c = id % t.cols, r = id / t.cols, w = 2 * t.cols;
  return {(2 * r + 1) * w + 2 * c, (2 * r + 1) * w + 2 * c + 1, 2 * r * w + 2 * c + 1,
          2 * r * w + 2 * c};
}

using TagCorners = std::array<cv::Point2f, 4>;

// Tag `id`'s four corners on the board (x, y), in tag_point_ids' order.
TagCorners tag_board_corners(const Target& t, const std::vector<Eigen::Vector3d>& object, int id) {
  const std::array<int, 4> ids = tag_point_ids(t, id);
  TagCorners board;
  for (int k = 0; k < 4; ++k)
    board[k] =
        cv::Point2f(static_cast<float>(object[ids[k]].x()), static_cast<float>(object[ids[k]].y()));
  return board;
}

// Whether the image shows tag `id` as printed through these corners: the tag's 10 x 10 cells
// (its 2-bit border and 6 x 6 data bits) and the ring of cells around it (the white gap, the
// corner squares), 144 cells, each read as the mean of four samples about its centre through the
// homography of the four corners, split into black and white at the midpoint of the means of
// the cells printed black and of those printed white. At most `max_misread` cells may read
// otherwise: tag36h11's codes differ in at least 11 of the 36 bits, so another tag, a tag put
// one place off, or anything else that is not this tag, fails. Ring cells off the printed
// board (a grid without margin) are not read.
bool reads_as_printed(const cv::Mat& gray, const Target& t, const Pattern& pattern,
                      const std::vector<Eigen::Vector3d>& object, int id, const TagCorners& px,
                      int max_misread) {
  const TagCorners corners = tag_board_corners(t, object, id);
  const std::vector<cv::Point2f> board(corners.begin(), corners.end()), image(px.begin(), px.end());
  const cv::Matx33d H = cv::getPerspectiveTransform(board, image);
  const Outline o = outline(t);
  const Eigen::Vector3d& origin = object[tag_point_ids(t, id)[3]];  // the tag's corner (2c, 2r)
  const double x0 = origin.x(), y0 = origin.y(), cell = t.tag_size / 10.0;
  std::vector<std::pair<double, bool>> cells;  // (intensity, printed white)
  for (int j = -1; j <= 10; ++j) {
    for (int i = -1; i <= 10; ++i) {
      const double bx = x0 + (i + 0.5) * cell, by = y0 + (j + 0.5) * cell;
      if (bx < o.x_min || bx > o.x_max || by < o.y_min || by > o.y_max) continue;
      double sum = 0.0;
      for (int q = 0; q < 4; ++q) {
        const double sx = bx + (q % 2 ? 0.2 : -0.2) * cell, sy = by + (q / 2 ? 0.2 : -0.2) * cell;
        const cv::Vec3d h = H * cv::Vec3d(sx, sy, 1.0);
        const double u = h[0] / h[2], v = h[1] / h[2];
        if (!(u >= 0 && v >= 0 && u < gray.cols - 1 && v < gray.rows - 1)) return false;
        sum += bilinear(gray, u, v);
      }
      cells.emplace_back(0.25 * sum, pattern.albedo(bx, by) > 0.5);
    }
  }
  double white = 0.0, black = 0.0;
  int n_white = 0, n_black = 0;
  for (const auto& [value, is_white] : cells) {
    (is_white ? white : black) += value;
    (is_white ? n_white : n_black) += 1;
  }
  if (n_white == 0 || n_black == 0) return false;
  white /= n_white;
  black /= n_black;
  if (white - black < 10.0) return false;  // no contrast: nothing can be read
  const double mid = 0.5 * (white + black);
  int misread = 0;
  for (const auto& [value, is_white] : cells) misread += (value > mid) != is_white;
  return misread <= max_misread;
}

void refine_corners(const cv::Mat& gray, std::vector<cv::Point2f>& corners, double tag_px) {
  const int w = std::clamp(static_cast<int>(0.12 * tag_px), 2, 11);
  cv::cornerSubPix(gray, corners, cv::Size(w, w), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4));
}

// The shortest side: the window of a foreshortened tag's corners must stay inside its border
// across the tag's short direction too.
double shortest_side_px(const TagCorners& px) {
  double s = INFINITY;
  for (int k = 0; k < 4; ++k)
    s = std::min(s, static_cast<double>(cv::norm(px[k] - px[(k + 1) % 4])));
  return s;
}

double side_px(const TagCorners& px) {
  return 0.25 * (cv::norm(px[0] - px[1]) + cv::norm(px[1] - px[2]) + cv::norm(px[2] - px[3]) +
                 cv::norm(px[3] - px[0]));
}

// Tags aruco did not decode, found from the grid: each missing tag's corners predicted by the
// homography of the decoded tags nearest to it on the board (up to four, at most 2.9 tag pitches
// away: local, so that lens distortion stays small across them), refined as saddle points like
// the decoded tags' corners, and kept only if the image reads as that tag through them
// (reads_as_printed). Repeated while tags are added, so that the grid grows from what aruco read
// into the tags next to it.
int complete_grid(const cv::Mat& gray, const Target& t, const Pattern& pattern,
                  const std::vector<Eigen::Vector3d>& object, std::map<int, TagCorners>& tags) {
  const double pitch = t.tag_size * (1.0 + t.tag_spacing);
  auto centre = [&](int id) {
    return Eigen::Vector2d((id % t.cols) * pitch, (id / t.cols) * pitch);
  };
  int added = 0;
  for (bool grew = true; grew;) {
    grew = false;
    for (int id = 0; id < t.cols * t.rows; ++id) {
      if (tags.count(id)) continue;
      std::vector<std::pair<double, int>> near;
      for (const auto& [other, px] : tags) {
        const double d = (centre(other) - centre(id)).norm() / pitch;
        if (d <= 2.9) near.emplace_back(d, other);
      }
      // Two tags or more, or one next to this one (its four corners fix the homography
      // exactly; extrapolated one tag over, the error stays a fraction of a cell).
      if (near.empty() || (near.size() < 2 && near[0].first > 1.5)) continue;
      std::sort(near.begin(), near.end());
      near.resize(std::min<size_t>(near.size(), 4));
      std::vector<cv::Point2f> board, image;
      for (const auto& [d, other] : near) {
        const TagCorners on_board = tag_board_corners(t, object, other);
        board.insert(board.end(), on_board.begin(), on_board.end());
        image.insert(image.end(), tags[other].begin(), tags[other].end());
      }
      const cv::Mat H = cv::findHomography(board, image, 0);
      if (H.empty()) continue;
      const TagCorners on_board = tag_board_corners(t, object, id);
      std::vector<cv::Point2f> predicted;
      cv::perspectiveTransform(std::vector<cv::Point2f>(on_board.begin(), on_board.end()),
                               predicted, H);
      TagCorners px;
      std::copy(predicted.begin(), predicted.end(), px.begin());
      const double side = side_px(px);
      const double margin = 0.12 * side + 2.0;
      bool inside = side >= 10.0;  // below: too few pixels a bit to read
      for (const cv::Point2f& p : predicted)
        inside = inside && p.x >= margin && p.y >= margin && p.x < gray.cols - margin &&
                 p.y < gray.rows - margin;
      if (!inside) continue;
      std::vector<cv::Point2f> refined = predicted;
      refine_corners(gray, refined, shortest_side_px(px));
      bool near_prediction = true;
      for (int k = 0; k < 4; ++k)
        near_prediction = near_prediction && cv::norm(refined[k] - predicted[k]) < 0.2 * side;
      if (!near_prediction) continue;
      std::copy(refined.begin(), refined.end(), px.begin());
      if (!reads_as_printed(gray, t, pattern, object, id, px, 3)) continue;
      tags[id] = px;
      ++added;
      grew = true;
    }
  }
  return added;
}

// One pass of OpenCV's aruco over an image `scale` times the size of the one detected in: the
// grid's tags it decoded, and the quads it found but could not read, in the detected image's
// pixels.
struct ArucoPass {
  std::map<int, TagCorners> tags;
  std::vector<TagCorners> unread;
  int wrong = 0;  // ids outside the grid
};

ArucoPass aruco_pass(const cv::Mat& image, const Target& t, double scale) {
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
  std::vector<std::vector<cv::Point2f>> found, rejected;
  cv::aruco::detectMarkers(image, dict, found, ids, params, rejected);
  ArucoPass pass;
  auto corners = [&](const std::vector<cv::Point2f>& quad) {
    TagCorners px;
    for (int k = 0; k < 4; ++k) px[k] = quad[k] * static_cast<float>(1.0 / scale);
    return px;
  };
  for (size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] < 0 || ids[i] >= t.cols * t.rows)
      ++pass.wrong;
    else if (!pass.tags.count(ids[i]))  // aruco reports some tags twice; the first is kept
      pass.tags[ids[i]] = corners(found[i]);
  }
  for (const std::vector<cv::Point2f>& quad : rejected) pass.unread.push_back(corners(quad));
  return pass;
}

// Quads aruco found but could not decode, read as the grid's tags: corners refined, then each
// tag not yet found tried in each of the four turns with reads_as_printed (the grid has few
// tags, and which cells are black is known: a reading aruco's general decoder cannot make on
// blurred or small tags).
int read_quads(const cv::Mat& gray, const Target& t, const Pattern& pattern,
               const std::vector<Eigen::Vector3d>& object, const std::vector<TagCorners>& quads,
               std::map<int, TagCorners>& tags) {
  int added = 0;
  for (const TagCorners& quad : quads) {
    const double side = side_px(quad);
    if (side < 10.0) continue;
    std::vector<cv::Point2f> refined(quad.begin(), quad.end());
    refine_corners(gray, refined, shortest_side_px(quad));
    bool read = false;
    for (int id = 0; id < t.cols * t.rows && !read; ++id) {
      if (tags.count(id)) continue;
      for (int turn = 0; turn < 4 && !read; ++turn) {
        TagCorners px;
        for (int k = 0; k < 4; ++k) px[k] = refined[(k + turn) % 4];
        if (!reads_as_printed(gray, t, pattern, object, id, px, 3)) continue;
        tags[id] = px;
        read = true;
        ++added;
      }
    }
  }
  return added;
}

Detection detect_aprilgrid(const cv::Mat& gray, const Target& t, const DetectOptions& o) {
  const Pattern pattern(t);
  const std::vector<Eigen::Vector3d> object = object_points(t);
  const int n_tags = t.cols * t.rows;
  std::map<int, TagCorners> tags;
  int wrong = 0, aruco = 0, quads = 0, completed = 0;
  // Tag corners meet the grid's corner squares: saddle points cornerSubPix refines. The window
  // (0.12 of the tag side) stays inside the tag's 2-bit border and the gap; measured on 40
  // simulated views: median 0.058 px from truth, 2.5 % of corners over 1 px (a jump to a
  // neighbouring saddle; the solver's outlier rejection drops them), where 0.2 sent 21 % over
  // 1 px. aruco's own corners are ~2 px off on these grids (the tag's outline touches the corner
  // squares), so refinement is needed.
  auto take = [&](const ArucoPass& pass) {
    wrong += pass.wrong;
    for (const auto& [id, quad] : pass.tags) {
      if (tags.count(id)) continue;
      std::vector<cv::Point2f> corners(quad.begin(), quad.end());
      refine_corners(gray, corners, shortest_side_px(quad));
      std::copy(corners.begin(), corners.end(), tags[id].begin());
      ++aruco;
    }
    quads += read_quads(gray, t, pattern, object, pass.unread, tags);
    completed += complete_grid(gray, t, pattern, object, tags);
  };
  take(aruco_pass(gray, t, 1.0));
  if (static_cast<int>(tags.size()) < n_tags) {
    // Tags of under ~25 px (2.5 px a bit) are rarely decoded, and a grid whose every tag is that
    // small leaves nothing to grow from: aruco again at twice the size.
    cv::Mat twice;
    cv::resize(gray, twice, cv::Size(), 2.0, 2.0, cv::INTER_CUBIC);
    take(aruco_pass(twice, t, 2.0));
  }
  Detection d;
  if (static_cast<int>(tags.size()) < o.min_tags) {
    d.note = fmt::format("{} tags of the grid found (fewer than {})", tags.size(), o.min_tags);
    return d;
  }
  std::vector<double> sizes;
  for (const auto& [id, px] : tags) {
    const std::array<int, 4> point_ids = tag_point_ids(t, id);
    for (int k = 0; k < 4; ++k) {
      d.point_ids.push_back(point_ids[k]);
      d.pixels.emplace_back(px[k].x, px[k].y);
    }
    sizes.push_back(side_px(px));
  }
  d.square_px = sizes.empty() ? 0.0 : median(sizes);  // empty: no tag with min_tags <= 0
  d.note = fmt::format(
      "{} tags: {} decoded by aruco, {} read from quads aruco could not decode, {} "
      "found from their neighbours",
      tags.size(), aruco, quads, completed);
  if (wrong) d.note += fmt::format("; {} tags with ids outside the grid ignored", wrong);
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
