#include "rigcal/sim/stereo.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "rigcal/camera/lens.h"
#include "rigcal/core/error.h"

namespace rigcal::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

bool fully_visible(const rig::CameraModel& cam, const SE3& T_cam_board,
                   const std::vector<Eigen::Vector3d>& pts, double margin) {
  for (const Eigen::Vector3d& p : pts) {
    const Eigen::Vector3d pc = T_cam_board * p;
    if (pc.z() < 0.1) return false;
    const std::optional<Eigen::Vector2d> px = camera::project(cam, pc);
    if (!px || px->x() < margin || px->y() < margin || px->x() > cam.width - 1 - margin ||
        px->y() > cam.height - 1 - margin) {
      return false;
    }
    // The lens must be well inside its valid range: distortion folds back far off-axis.
    if (pc.head<2>().norm() / pc.z() > 2.0) return false;
  }
  return true;
}

// The smallest distance between neighbouring checkerboard corners in the image (foreshortened
// squares); AprilGrids are not limited this way (see board_poses).
double smallest_spacing(const rig::CameraModel& cam, const SE3& T_cam_board,
                        const camera::Target& target) {
  std::vector<Eigen::Vector2d> px;
  for (const Eigen::Vector3d& p : camera::object_points(target)) {
    px.push_back(camera::project(cam, T_cam_board * p).value_or(Eigen::Vector2d(NAN, NAN)));
  }
  double smallest = INFINITY;
  for (int j = 0; j < target.rows; ++j) {
    for (int i = 0; i < target.cols; ++i) {
      const int k = j * target.cols + i;
      if (i + 1 < target.cols) smallest = std::min(smallest, (px[k + 1] - px[k]).norm());
      if (j + 1 < target.rows) smallest = std::min(smallest, (px[k + target.cols] - px[k]).norm());
    }
  }
  return smallest;
}

}  // namespace

std::vector<SE3> board_poses(const rig::CameraModel& left, const rig::CameraModel* right,
                             const SE3& T_right_left, const camera::Target& target,
                             const BoardPoseConfig& cfg, std::mt19937_64& rng) {
  const camera::Outline o = camera::outline(target);
  // What must be seen: the outline's corners and every object point.
  std::vector<Eigen::Vector3d> check = camera::object_points(target);
  for (double x : {o.x_min, o.x_max}) {
    for (double y : {o.y_min, o.y_max}) check.emplace_back(x, y, 0.0);
  }
  const Eigen::Vector3d centre_board(0.5 * (o.x_min + o.x_max), 0.5 * (o.y_min + o.y_max), 0.0);
  const double extent = std::max(o.width(), o.height());
  // The board faces the camera: checkerboard rows go down the image, AprilGrid rows go up.
  const Eigen::Matrix3d R0 = target.type == camera::TargetType::aprilgrid
                                 ? Eigen::Vector3d(1, -1, -1).asDiagonal().toDenseMatrix()
                                 : Eigen::Matrix3d::Identity();
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::vector<SE3> poses;
  for (int view = 0; view < cfg.views; ++view) {
    const int cell = view % 9;
    bool found = false;
    // The fill is drawn once and shrunk by 5 % every 50 failed placements, so that views keep
    // the largest fill that fits (both cameras seeing the whole board bounds it for a stereo pair).
    double fill = cfg.min_fill + (cfg.max_fill - cfg.min_fill) * u01(rng);
    for (int attempt = 0; attempt < 4000 && !found; ++attempt) {
      if (attempt > 0 && attempt % 50 == 0) fill = std::max(cfg.min_fill, 0.95 * fill);
      // Relax the cell after many failures (a large board may not fit in a corner).
      const bool relax = attempt > 2000;
      const double distance = left.fx * extent / (fill * left.width);
      const double cu = ((relax ? 3 * u01(rng) : cell % 3 + u01(rng)) / 3.0) * left.width;
      const double cv = ((relax ? 3 * u01(rng) : cell / 3 + u01(rng)) / 3.0) * left.height;
      const Eigen::Vector2d ray = camera::unproject(left, Eigen::Vector2d(cu, cv));
      const Eigen::Vector3d centre = distance * Eigen::Vector3d(ray.x(), ray.y(), 1.0).normalized();
      const double axis_angle = 2 * M_PI * u01(rng);
      const Eigen::Vector3d tilt_axis(std::cos(axis_angle), std::sin(axis_angle), 0.0);
      const double tilt = cfg.max_tilt_deg * kDeg * std::sqrt(u01(rng));
      const double roll = cfg.max_roll_deg * kDeg * (2 * u01(rng) - 1);
      SE3 T_cam_board;
      T_cam_board.R = Eigen::AngleAxisd(tilt, tilt_axis).toRotationMatrix() *
                      Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R0;
      T_cam_board.t = centre - T_cam_board.R * centre_board;
      if (!fully_visible(left, T_cam_board, check, cfg.margin_px)) continue;
      if (right && !fully_visible(*right, T_right_left * T_cam_board, check, cfg.margin_px))
        continue;
      if (target.type == camera::TargetType::checkerboard) {
        if (smallest_spacing(left, T_cam_board, target) < cfg.min_square_px) continue;
        if (right &&
            smallest_spacing(*right, T_right_left * T_cam_board, target) < cfg.min_square_px) {
          continue;
        }
      }
      poses.push_back(T_cam_board);
      found = true;
    }
    if (!found) {
      throw Error(
          fmt::format("could not place the {:.3f} x {:.3f} m target '{}' in view {} so that "
                      "{} camera(s) see all of it; lower max_fill or use a smaller target",
                      o.width(), o.height(), target.name, view, right ? 2 : 1));
    }
  }
  return poses;
}

PixelRays pixel_rays(const rig::CameraModel& cam) {
  PixelRays r;
  r.width = cam.width;
  r.height = cam.height;
  r.xn.resize(static_cast<size_t>(cam.width) * cam.height);
  r.dxn_dpixel.resize(r.xn.size());
  tbb::parallel_for(0, cam.height, [&](int v) {
    for (int u = 0; u < cam.width; ++u) {
      const size_t i = static_cast<size_t>(v) * cam.width + u;
      r.xn[i] = camera::unproject(cam, Eigen::Vector2d(u, v));
      const Eigen::Vector2d du = camera::unproject(cam, Eigen::Vector2d(u + 0.5, v)) -
                                 camera::unproject(cam, Eigen::Vector2d(u - 0.5, v));
      const Eigen::Vector2d dv = camera::unproject(cam, Eigen::Vector2d(u, v + 0.5)) -
                                 camera::unproject(cam, Eigen::Vector2d(u, v - 0.5));
      r.dxn_dpixel[i].col(0) = du;
      r.dxn_dpixel[i].col(1) = dv;
    }
  });
  return r;
}

cv::Mat render_board(const PixelRays& rays, const camera::Target& target,
                     const camera::Pattern& pattern, const SE3& T_cam_board, const ImageConfig& cfg,
                     std::mt19937_64& rng, const Eigen::Vector2d& board_warp_m) {
  const bool flat = board_warp_m.isZero();
  // How far a warp can move where a ray meets the board: its height (the parabolas grow to 1.5
  // times the warp at the board's edges) times the tangent of a ray's incidence (< 3: 72 deg).
  const double reach = 5 * board_warp_m.cwiseAbs().sum();
  const Eigen::Vector2d inverse_extent = camera::board_points_extent(target).cwiseInverse();
  const camera::Outline o = camera::outline(target);
  const Eigen::Vector3d n = T_cam_board.R.col(2), t = T_cam_board.t;
  const Eigen::Vector3d ex = T_cam_board.R.col(0), ey = T_cam_board.R.col(1);
  const double n_dot_t = n.dot(t);
  // Where the ray meets the board's plane (false: it does not, in front of the camera).
  auto plane_hit = [&](const Eigen::Vector3d& ray, double& bx, double& by) {
    const double denom = n.dot(ray);
    if (std::abs(denom) <= 1e-12 || n_dot_t / denom <= 0) return false;
    const Eigen::Vector3d d = n_dot_t / denom * ray - t;
    bx = ex.dot(d), by = ey.dot(d);
    return true;
  };
  // A warped board: one step from board point (bx, by) to where the ray meets the plane z = w at
  // it, w the warp there. Each step shrinks the error by the surface's slope times the ray's
  // obliquity (< 0.1 for a few mm over A3). Returns how far the point moved.
  auto warp_step = [&](const Eigen::Vector3d& ray, double& bx, double& by) {
    const double w = board_warp_m.dot(camera::board_warp_basis(inverse_extent, bx, by));
    const Eigen::Vector3d d = (n_dot_t + w) / n.dot(ray) * ray - t;
    const double x = ex.dot(d), y = ey.dot(d), moved = std::abs(x - bx) + std::abs(y - by);
    bx = x, by = y;
    return moved;
  };
  const int S = std::max(1, cfg.supersample);
  auto on_board = [&](double bx, double by) {
    return bx >= o.x_min && bx <= o.x_max && by >= o.y_min && by <= o.y_max;
  };
  auto printed = [&](double bx, double by) {
    return cfg.black_dn + (cfg.white_dn - cfg.black_dn) * pattern.albedo(bx, by);
  };
  // The one value every sample of pixel i has on a flat board, where the pixel sees one cell of
  // the pattern, or the background, whole: the four outermost samples meet the board in one cell
  // (or all miss its outline on one side), so the samples between them do too (the samples' rays
  // are an affine grid, the plane's hits a projective image of it: inside the four's convex
  // hull). Most pixels are such; nothing where they are not.
  auto one_value = [&](size_t i) -> std::optional<double> {
    const double h = 0.5 - 0.5 / S;
    std::array<Eigen::Vector2d, 4> hit;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d xn =
          rays.xn[i] + rays.dxn_dpixel[i] * Eigen::Vector2d(k & 1 ? h : -h, k & 2 ? h : -h);
      if (!plane_hit(Eigen::Vector3d(xn.x(), xn.y(), 1.0), hit[k].x(), hit[k].y()))
        return std::nullopt;
    }
    bool inside = true, left = true, right = true, below = true, above = true, one_cell = true;
    const auto first = pattern.cell(hit[0].x(), hit[0].y());
    for (const Eigen::Vector2d& b : hit) {
      inside = inside && on_board(b.x(), b.y());
      left = left && b.x() < o.x_min, right = right && b.x() > o.x_max;
      below = below && b.y() < o.y_min, above = above && b.y() > o.y_max;
      one_cell = one_cell && pattern.cell(b.x(), b.y()) == first;
    }
    if (inside && one_cell) return printed(hit[0].x(), hit[0].y());
    if (left || right || below || above) return cfg.background_dn;
    return std::nullopt;
  };
  cv::Mat signal(rays.height, rays.width, CV_64F);
  const double r_corner2 =
      0.25 * (double(rays.width) * rays.width + double(rays.height) * rays.height);
  tbb::parallel_for(0, rays.height, [&](int v) {
    double* row = signal.ptr<double>(v);
    for (int u = 0; u < rays.width; ++u) {
      const size_t i = static_cast<size_t>(v) * rays.width + u;
      // The warp's shift of the pixel centre's hit, converged; each sample starts from its plane
      // hit moved by it and takes one step (the shift changes by < 0.1 mm over a pixel: one step
      // leaves micrometres). Rays that miss the board by more than the warp can move them: none.
      Eigen::Vector2d shift = Eigen::Vector2d::Zero();
      bool warp_here = false;
      if (!flat) {
        const Eigen::Vector3d ray(rays.xn[i].x(), rays.xn[i].y(), 1.0);
        double bx, by;
        if (plane_hit(ray, bx, by) && bx >= o.x_min - reach && bx <= o.x_max + reach &&
            by >= o.y_min - reach && by <= o.y_max + reach) {
          warp_here = true;
          double x = bx, y = by;
          for (int k = 0; k < 10 && warp_step(ray, x, y) > 1e-8; ++k) {
          }
          shift = Eigen::Vector2d(x - bx, y - by);
        }
      }
      double sum = 0.0;
      if (const std::optional<double> value = flat && S > 1 ? one_value(i) : std::nullopt) {
        for (int k = 0; k < S * S; ++k) sum += *value;  // as the samples would sum: the same image
      } else {
        for (int sy = 0; sy < S; ++sy) {
          for (int sx = 0; sx < S; ++sx) {
            const Eigen::Vector2d off((sx + 0.5) / S - 0.5, (sy + 0.5) / S - 0.5);
            const Eigen::Vector2d xn = rays.xn[i] + rays.dxn_dpixel[i] * off;
            const Eigen::Vector3d ray(xn.x(), xn.y(), 1.0);
            double value = cfg.background_dn, bx, by;
            if (plane_hit(ray, bx, by)) {
              if (warp_here) {
                bx += shift.x(), by += shift.y();
                warp_step(ray, bx, by);
              }
              if (on_board(bx, by)) value = printed(bx, by);
            }
            sum += value;
          }
        }
      }
      const double du = u - 0.5 * (rays.width - 1), dv = v - 0.5 * (rays.height - 1);
      row[u] = sum / (S * S) * (1.0 - cfg.vignetting * (du * du + dv * dv) / r_corner2);
    }
  });
  if (cfg.blur_sigma_px > 0) cv::GaussianBlur(signal, signal, cv::Size(0, 0), cfg.blur_sigma_px);
  cv::Mat image(rays.height, rays.width, CV_8UC1);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int v = 0; v < rays.height; ++v) {
    const double* in = signal.ptr<double>(v);
    uint8_t* out = image.ptr<uint8_t>(v);
    for (int u = 0; u < rays.width; ++u) {
      double s = in[u];
      if (cfg.bayer)
        s *= (v % 2 == 0) ? (u % 2 == 0 ? cfg.gain_r : cfg.gain_g)
                          : (u % 2 == 0 ? cfg.gain_g : cfg.gain_b);
      const double sigma =
          std::sqrt(std::max(0.0, cfg.gain_dn_per_e * s) + cfg.read_noise_dn * cfg.read_noise_dn);
      out[u] = static_cast<uint8_t>(std::clamp(std::lround(s + sigma * normal(rng)), 0L, 255L));
    }
  }
  return image;
}

std::vector<Eigen::Vector2d> project_points(const rig::CameraModel& camera, const SE3& T_cam_board,
                                            const std::vector<Eigen::Vector3d>& points_board) {
  std::vector<Eigen::Vector2d> out;
  for (const Eigen::Vector3d& p : points_board) {
    const std::optional<Eigen::Vector2d> px = camera::project(camera, T_cam_board * p);
    out.push_back(px.value_or(Eigen::Vector2d(NAN, NAN)));
  }
  return out;
}

}  // namespace rigcal::sim
