#include "rigcal/lidar_camera/board_lidar.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <climits>
#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>
#include <random>
#include <tuple>
#include <unordered_map>

namespace rigcal::lidar_camera {

Plane fit_plane(const std::vector<Eigen::Vector3d>& points) {
  const double N = static_cast<double>(points.size());
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) c += p;
  c /= N;
  Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) S += (p - c) * (p - c).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(S);  // ascending eigenvalues
  Plane plane;
  plane.n = es.eigenvectors().col(0);
  plane.d = plane.n.dot(c);
  if (plane.d < 0) plane.n = -plane.n, plane.d = -plane.d;
  const double var = std::max(es.eigenvalues()[0], 0.0) / std::max(1.0, N - 3.0);
  // The normal's tilt about the in-plane principal axes e1, e2 has variance var / lambda_k; the
  // offset along n at the centroid var / N, independent of the tilt.
  const Eigen::Matrix<double, 3, 2> B = tangent(plane.n);
  Eigen::Matrix3d info_inv = Eigen::Matrix3d::Zero();
  for (int k = 1; k < 3; ++k) {
    const Eigen::Vector3d e = es.eigenvectors().col(k);
    info_inv += e * e.transpose() * (var / std::max(es.eigenvalues()[k], 1e-12));
  }
  Eigen::Matrix3d Cx = Eigen::Matrix3d::Zero();
  Cx.block<2, 2>(0, 0) = B.transpose() * info_inv * B;
  Cx(2, 2) = var / N;
  Eigen::Matrix3d M = Eigen::Matrix3d::Identity();
  M.block<1, 2>(2, 0) = c.transpose() * B;
  plane.covariance = M * Cx * M.transpose();
  return plane;
}

namespace {

// The range a LiDAR point x (sensor at the origin) would need to lie on the plane n . x = d,
// minus its range: the plane's residual in the units of the noise.
double range_residual(const Eigen::Vector3d& n, double d, const Eigen::Vector3d& x) {
  const double cosine = n.dot(x) / x.norm();
  return (d - n.dot(x)) / (std::abs(cosine) > 0.05 ? cosine : 0.05);
}

}  // namespace

Plane fit_plane_along_rays(const std::vector<Eigen::Vector3d>& points, double* rms) {
  Plane plane = fit_plane(points);
  // Parameters: two tangent angles (n <- normalize(n + a u + b v)) and d.
  auto residuals = [&](const Eigen::Vector3d& n, double d) {
    Eigen::VectorXd r(points.size());
    for (size_t i = 0; i < points.size(); ++i) r[i] = range_residual(n, d, points[i]);
    return r;
  };
  // The residuals' Jacobian at `plane` (forward differences, in the tangent basis of its n).
  auto jacobian = [&](const Eigen::VectorXd& r) {
    const Eigen::Matrix<double, 3, 2> B = tangent(plane.n);
    Eigen::MatrixXd J(points.size(), 3);
    for (int c = 0; c < 3; ++c) {
      Eigen::Vector3d dp = Eigen::Vector3d::Zero();
      dp[c] = 1e-7;
      const Eigen::Vector3d n1 = (plane.n + B * dp.head<2>()).normalized();
      J.col(c) = (residuals(n1, plane.d + dp[2]) - r) / 1e-7;
    }
    return J;
  };
  for (int it = 0; it < 10; ++it) {
    const Eigen::Matrix<double, 3, 2> B = tangent(plane.n);
    const Eigen::VectorXd r = residuals(plane.n, plane.d);
    const Eigen::MatrixXd J = jacobian(r);
    const Eigen::Vector3d step = (J.transpose() * J).ldlt().solve(-J.transpose() * r);
    plane.n = (plane.n + B * step.head<2>()).normalized();
    plane.d += step[2];
    if (step.norm() < 1e-12) break;
  }
  if (plane.d < 0) plane.n = -plane.n, plane.d = -plane.d;
  const Eigen::VectorXd r = residuals(plane.n, plane.d);
  const double N = static_cast<double>(points.size());
  const double var = r.squaredNorm() / std::max(1.0, N - 3.0);
  if (rms) *rms = std::sqrt(r.squaredNorm() / N);
  // J at the solution, in the tangent basis of the final n (the covariance's convention).
  const Eigen::MatrixXd J = jacobian(r);
  plane.covariance = var * (J.transpose() * J).inverse();
  return plane;
}

namespace {

struct CellHash {
  size_t operator()(const Eigen::Vector3i& v) const {
    return (static_cast<size_t>(v.x()) * 73856093u) ^ (static_cast<size_t>(v.y()) * 19349663u) ^
           (static_cast<size_t>(v.z()) * 83492791u);
  }
};
struct CellEq {
  bool operator()(const Eigen::Vector3i& a, const Eigen::Vector3i& b) const { return a == b; }
};

// Connected pieces of `idx` (points in the same or neighbouring cells join).
std::vector<std::vector<size_t>> pieces(const std::vector<Eigen::Vector3d>& pts,
                                        const std::vector<size_t>& idx, double cell) {
  std::unordered_map<Eigen::Vector3i, std::vector<size_t>, CellHash, CellEq> cells;
  for (size_t i : idx) cells[(pts[i] / cell).array().floor().cast<int>()].push_back(i);
  std::unordered_map<Eigen::Vector3i, int, CellHash, CellEq> label;
  std::vector<std::vector<size_t>> out;
  for (const auto& [key, members] : cells) {
    if (label.count(key)) continue;
    const int id = static_cast<int>(out.size());
    out.emplace_back();
    std::vector<Eigen::Vector3i> stack{key};
    label[key] = id;
    while (!stack.empty()) {
      const Eigen::Vector3i k = stack.back();
      stack.pop_back();
      const auto& m = cells.at(k);
      out[id].insert(out[id].end(), m.begin(), m.end());
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            const Eigen::Vector3i nk = k + Eigen::Vector3i(dx, dy, dz);
            if (cells.count(nk) && !label.count(nk)) {
              label[nk] = id;
              stack.push_back(nk);
            }
          }
    }
  }
  return out;
}

struct Candidate {
  std::vector<size_t> idx;
  Eigen::Vector3d centre;
  double w, h;
  // The region in the piece's raster: cell (u - lo) / cell of B^T x, dilated by one cell.
  cv::Mat region;
  Eigen::Matrix<double, 3, 2> B;
  Eigen::Vector2d lo;
  Eigen::Vector2d long_side;  // unit, in the (u, v) of B: along the rectangle's long side
  double cell = 0.02;
  bool contains(const Eigen::Vector3d& x) const {
    const Eigen::Vector2d q = (B.transpose() * x - lo) / cell;
    const int c = static_cast<int>(q.x()) + 1, r = static_cast<int>(q.y()) + 1;
    return q.x() >= 0 && q.y() >= 0 && r < region.rows && c < region.cols &&
           region.at<uint8_t>(r, c) != 0;
  }
};

// The board-sized parts of one planar piece. The piece is rasterized in its plane (2 cm cells),
// closed (gaps between rings filled), then opened with a kernel of half the board's short side,
// which removes thin things joined to the board (its stand's post, a leg, a cable) but keeps a
// board; each remaining region whose minimum-area rectangle has the board's size is a candidate,
// with the piece's points that fall in it.
std::vector<Candidate> board_shaped(const std::vector<Eigen::Vector3d>& all,
                                    const std::vector<size_t>& piece, const Eigen::Vector3d& n,
                                    double W, double H, const BoardSearch& s) {
  const double cell = 0.02;
  const Eigen::Matrix<double, 3, 2> B = tangent(n);
  std::vector<Eigen::Vector2d> uv(piece.size());
  Eigen::Vector2d lo(INFINITY, INFINITY), hi(-INFINITY, -INFINITY);
  for (size_t k = 0; k < piece.size(); ++k) {
    uv[k] = B.transpose() * all[piece[k]];
    lo = lo.cwiseMin(uv[k]), hi = hi.cwiseMax(uv[k]);
  }
  const Eigen::Vector2d size = hi - lo;
  // A piece smaller than the board's short side, or too large to hold it as a part worth a raster
  // (walls, floors: their board-sized parts would be flat patches of wall), is skipped early.
  if (std::max(size.x(), size.y()) < W - s.short_m || std::min(size.x(), size.y()) < H - s.short_m)
    return {};
  if (size.x() * size.y() > 16.0) return {};
  const int cols = static_cast<int>(size.x() / cell) + 3,
            rows = static_cast<int>(size.y() / cell) + 3;
  cv::Mat mask = cv::Mat::zeros(rows, cols, CV_8U);
  std::vector<cv::Point> at(piece.size());
  for (size_t k = 0; k < piece.size(); ++k) {
    at[k] = cv::Point(static_cast<int>((uv[k].x() - lo.x()) / cell) + 1,
                      static_cast<int>((uv[k].y() - lo.y()) / cell) + 1);
    mask.at<uint8_t>(at[k]) = 255;
  }
  const int close = 5, open = std::max(3, static_cast<int>(0.5 * H / cell));
  cv::morphologyEx(mask, mask, cv::MORPH_CLOSE,
                   cv::getStructuringElement(cv::MORPH_RECT, cv::Size(close, close)));
  cv::morphologyEx(mask, mask, cv::MORPH_OPEN,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(open, open)));
  cv::Mat labels;
  const int n_labels = cv::connectedComponents(mask, labels, 8, CV_32S);
  std::vector<Candidate> out;
  for (int l = 1; l < n_labels; ++l) {
    std::vector<cv::Point2f> region;
    Candidate c;
    c.centre.setZero();
    for (size_t k = 0; k < piece.size(); ++k) {
      if (labels.at<int>(at[k]) != l) continue;
      region.emplace_back(static_cast<float>(uv[k].x()), static_cast<float>(uv[k].y()));
      c.idx.push_back(piece[k]);
      c.centre += all[piece[k]];
    }
    if (c.idx.size() < static_cast<size_t>(s.min_points)) continue;
    c.centre /= static_cast<double>(c.idx.size());
    const cv::RotatedRect rect = cv::minAreaRect(region);
    c.w = std::max(rect.size.width, rect.size.height);
    c.h = std::min(rect.size.width, rect.size.height);
    if (c.w < W - s.short_m || c.w > W + s.long_m || c.h < H - s.short_m || c.h > H + s.long_m)
      continue;
    cv::dilate(labels == l, c.region, cv::Mat::ones(3, 3, CV_8U));
    cv::Point2f v[4];
    rect.points(v);
    const Eigen::Vector2d e1(v[1].x - v[0].x, v[1].y - v[0].y),
        e2(v[2].x - v[1].x, v[2].y - v[1].y);
    c.long_side = (e1.norm() >= e2.norm() ? e1 : e2).normalized();
    c.B = B;
    c.lo = lo;
    c.cell = cell;
    out.push_back(std::move(c));
  }
  return out;
}

// The points without stubs that the raster kept at the board's edges (a stand's post just below
// the board, an arm holding it): along each side of the board's rectangle, 1 cm strips across it
// whose points span less than half the board are dropped from both ends (a board's strip spans
// the board, a post's its own few centimetres). Strips inside the board are kept whatever their
// span (sparse rings).
std::vector<Eigen::Vector3d> without_stubs(const std::vector<Eigen::Vector3d>& pts,
                                           const Candidate& c, double W, double H) {
  const Eigen::Vector2d a = c.long_side, b(-a.y(), a.x());
  std::vector<Eigen::Vector3d> out = pts;
  for (const auto& [along, across, size_across] : {std::tuple{a, b, H}, std::tuple{b, a, W}}) {
    const double strip = 0.01;
    std::map<int, std::pair<double, double>> span;  // strip -> min, max across
    // `along` copied: clang 14 (the sanitizer build) cannot capture a structured binding.
    auto strip_of = [&, along = along](const Eigen::Vector3d& x) {
      return static_cast<int>(std::floor(along.dot(c.B.transpose() * x) / strip));
    };
    for (const Eigen::Vector3d& x : out) {
      const double t = across.dot(c.B.transpose() * x);
      auto [it, fresh] = span.try_emplace(strip_of(x), t, t);
      if (!fresh) it->second = {std::min(it->second.first, t), std::max(it->second.second, t)};
    }
    int first = INT_MAX, last = INT_MIN;
    for (const auto& [k, mm] : span) {
      if (mm.second - mm.first >= 0.5 * size_across) first = std::min(first, k), last = k;
    }
    if (first > last) continue;  // no strip spans half the board: leave the points alone
    std::vector<Eigen::Vector3d> kept;
    for (const Eigen::Vector3d& x : out) {
      const int k = strip_of(x);
      if (k >= first && k <= last) kept.push_back(x);
    }
    out.swap(kept);
  }
  return out;
}

// Points are dropped beyond kTrim times the RMS of the points kept (until nothing changes).
constexpr double kTrim = 2.5;

// The covariance of a least-squares fit on Gaussian residuals trimmed at k times their own RMS,
// over the formula's (residual variance of the kept points times (J^T J)^-1). The trimming stops
// where c = k sqrt((P - 2 c phi(c)) / P), c the cut in true sigmas, P = P(|x| < c); the trimmed
// (skipped) estimator's variance is then sigma^2 / (P - 2 c phi(c)) per kept point's share, the
// formula's (P - 2 c phi(c)) / P sigma^2: the ratio is P^2 / (P - 2 c phi(c))^2, 1.29 for k = 2.5
// (sigmas 14 % larger; 20 simulated seeds: the LiDAR planes' errors were 1.14-1.22 of their sigmas
// before).
double trimmed_covariance_factor(double k) {
  auto phi = [](double x) { return std::exp(-0.5 * x * x) / std::sqrt(2 * M_PI); };
  auto P = [](double x) { return std::erf(x / std::sqrt(2.0)); };
  double c = k;
  for (int i = 0; i < 50; ++i) c = k * std::sqrt((P(c) - 2 * c * phi(c)) / P(c));
  const double a = P(c) - 2 * c * phi(c);
  return P(c) * P(c) / (a * a);
}

}  // namespace

LidarBoard find_board(const std::vector<Eigen::Vector3d>& all, const BoardSearch& s) {
  LidarBoard out;
  std::vector<size_t> remaining;
  for (size_t i = 0; i < all.size(); ++i) {
    const double r = all[i].norm();
    if (!(r >= s.min_range_m && r <= s.max_range_m)) continue;
    if (s.roi && ((all[i].array() < s.roi->first.array()).any() ||
                  (all[i].array() > s.roi->second.array()).any()))
      continue;
    remaining.push_back(i);
  }
  const double W = std::max(s.board_width_m, s.board_height_m),
               H = std::min(s.board_width_m, s.board_height_m);
  std::mt19937_64 rng(s.seed);
  std::vector<Candidate> candidates;
  // The best plane of `pool` by RANSAC: normal, offset and inlier count.
  auto ransac = [&](const std::vector<size_t>& pool, Eigen::Vector3d& best_n, double& best_d) {
    std::uniform_int_distribution<size_t> pick(0, pool.size() - 1);
    size_t best_count = 0;
    for (int it = 0; it < 300; ++it) {
      const Eigen::Vector3d &a = all[pool[pick(rng)]], &b = all[pool[pick(rng)]],
                            &c = all[pool[pick(rng)]];
      Eigen::Vector3d n = (b - a).cross(c - a);
      if (n.norm() < 1e-9) continue;
      n.normalize();
      const double d = n.dot(a);
      size_t count = 0;
      for (size_t i : pool) count += std::abs(n.dot(all[i]) - d) < s.plane_threshold_m;
      if (count > best_count) best_count = count, best_n = n, best_d = d;
    }
    return best_count;
  };
  auto split = [&](const std::vector<size_t>& pool, const Eigen::Vector3d& n, double d,
                   std::vector<size_t>& in, std::vector<size_t>& rest) {
    for (size_t i : pool)
      (std::abs(n.dot(all[i]) - d) < s.plane_threshold_m ? in : rest).push_back(i);
  };
  const double diagonal = std::hypot(W, H);
  // 1. The large planes (floor, walls, ceiling): RANSAC over the whole scan; a plane's pieces
  //    larger than 3 board diagonals and 3 m are removed, smaller ones (a board on its stand, a
  //    board that happens to lie in a wall's plane, clutter) go back. A small board among tens of
  //    thousands of points would never win a global RANSAC; it is looked for in step 2.
  for (int plane = 0; plane < s.max_planes && remaining.size() >= static_cast<size_t>(s.min_points);
       ++plane) {
    Eigen::Vector3d n;
    double d = 0;
    if (ransac(remaining, n, d) < static_cast<size_t>(s.min_points)) break;
    std::vector<size_t> in, rest;
    split(remaining, n, d, in, rest);
    bool removed = false;
    for (std::vector<size_t>& piece : pieces(all, in, s.cell_m)) {
      Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
      for (size_t i : piece) lo = lo.cwiseMin(all[i]), hi = hi.cwiseMax(all[i]);
      if ((hi - lo).norm() > std::max(3.0 * diagonal, 3.0)) {
        removed = true;
      } else {
        rest.insert(rest.end(), piece.begin(), piece.end());
      }
    }
    remaining.swap(rest);
    if (!removed) break;
  }
  // 2. What is left, in connected clusters; in each cluster of a plausible size (a board on a
  //    stand, a person holding it), up to five planes, each tested for the board's shape.
  for (const std::vector<size_t>& cluster : pieces(all, remaining, s.cell_m)) {
    if (cluster.size() < static_cast<size_t>(s.min_points)) continue;
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
    for (size_t i : cluster) lo = lo.cwiseMin(all[i]), hi = hi.cwiseMax(all[i]);
    const double extent = (hi - lo).norm();
    if (extent < 0.5 * diagonal || extent > 4.0 * diagonal + 1.0) continue;
    std::vector<size_t> pool = cluster;
    for (int k = 0; k < 5 && pool.size() >= static_cast<size_t>(s.min_points); ++k) {
      Eigen::Vector3d n;
      double d = 0;
      if (ransac(pool, n, d) < static_cast<size_t>(s.min_points)) break;
      std::vector<size_t> in, rest;
      split(pool, n, d, in, rest);
      // The RANSAC plane refitted on its inliers and the inliers taken again: a plane through
      // three noisy points can cut a board obliquely and split it.
      std::vector<Eigen::Vector3d> inlier_points;
      for (size_t i : in) inlier_points.push_back(all[i]);
      const Plane refit = fit_plane(inlier_points);
      in.clear(), rest.clear();
      split(pool, refit.n, refit.d, in, rest);
      n = refit.n;
      for (std::vector<size_t>& piece : pieces(all, in, s.cell_m)) {
        if (piece.size() < static_cast<size_t>(s.min_points)) continue;
        for (Candidate& c : board_shaped(all, piece, n, W, H, s))
          candidates.push_back(std::move(c));
      }
      pool.swap(rest);
    }
  }
  out.candidates = static_cast<int>(candidates.size());
  if (candidates.empty()) {
    out.reason = fmt::format(
        "no planar piece of the board's size ({:.2f} x {:.2f} m) between {} and {} m{}: "
        "give --roi around the board",
        W, H, s.min_range_m, s.max_range_m, s.roi ? " inside the ROI" : "");
    return out;
  }
  const Candidate* best = nullptr;
  if (s.expected_centre) {
    double dmin = s.max_centre_distance_m;
    for (const Candidate& c : candidates) {
      const double d = (c.centre - *s.expected_centre).norm();
      if (d <= dmin) dmin = d, best = &c;
    }
    if (!best) {
      out.reason = fmt::format(
          "{} planar pieces of the board's size, none within {} m of where the board is expected",
          candidates.size(), s.max_centre_distance_m);
      return out;
    }
  } else {
    if (candidates.size() > 1) {
      out.reason = fmt::format(
          "{} planar pieces of the board's size and no expected position to choose among them",
          candidates.size());
      return out;
    }
    best = &candidates.front();
  }
  out.found = true;
  // Refit, then gather again every point near the plane inside the region (board points another
  // plane took come back; the stand's post, removed from the region by the opening, stays out),
  // and refit dropping points beyond 2.5 RMS until nothing changes (a few mixed edge returns).
  // Distances are along the rays (the range each point would need), as the noise is: a window
  // symmetric about a plane tilted by the orthogonal fit's bias would keep that bias.
  std::vector<Eigen::Vector3d> first;
  for (size_t i : best->idx) first.push_back(all[i]);
  double rms = 0;
  Plane p0 = fit_plane_along_rays(first, &rms);
  const double tol = std::clamp(3.0 * rms, 0.01, s.plane_threshold_m);
  std::vector<Eigen::Vector3d> near;
  for (const Eigen::Vector3d& x : all) {
    if (std::abs(range_residual(p0.n, p0.d, x)) <= tol && best->contains(x)) near.push_back(x);
  }
  near = without_stubs(near, *best, W, H);
  for (int it = 0; it < 5 && near.size() >= static_cast<size_t>(s.min_points); ++it) {
    p0 = fit_plane_along_rays(near, &rms);
    std::vector<Eigen::Vector3d> kept;
    for (const Eigen::Vector3d& x : near) {
      if (std::abs(range_residual(p0.n, p0.d, x)) <= kTrim * rms) kept.push_back(x);
    }
    const bool same = kept.size() == near.size();
    near.swap(kept);
    if (same) break;
  }
  out.points = near;
  out.plane = fit_plane_along_rays(out.points, &out.plane_rms_m);
  out.plane.covariance *= trimmed_covariance_factor(kTrim);
  out.centre = best->centre;
  out.width_m = best->w;
  out.height_m = best->h;
  out.reason = fmt::format("board found: {} points, {:.2f} x {:.2f} m, plane RMS {:.1f} mm{}",
                           out.points.size(), out.width_m, out.height_m, 1e3 * out.plane_rms_m,
                           candidates.size() > 1
                               ? fmt::format(" ({} candidates, the nearest to the expected "
                                             "position taken)",
                                             candidates.size())
                               : "");
  return out;
}

}  // namespace rigcal::lidar_camera
