#include "rigcal/sim/lidar.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace rigcal::sim {

void add_box(Scene& scene, const SE3& T, const Eigen::Vector3d& h, double reflectivity, int id) {
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign : {-1, 1}) {
      const int a = (axis + 1) % 3, b = (axis + 2) % 3;
      Rect r;
      r.centre = T * (sign * h[axis] * Eigen::Vector3d::Unit(axis));
      r.u = T.R.col(a);
      r.v = T.R.col(b);
      r.half_u = h[a];
      r.half_v = h[b];
      r.reflectivity = reflectivity;
      r.id = id;
      scene.rects.push_back(r);
    }
  }
}

void add_board(Scene& scene, const camera::Target& target, const camera::Pattern& pattern,
               const SE3& T_world_board, double z_floor, int id) {
  const camera::Outline o = camera::outline(target);
  const Eigen::Vector2d c(0.5 * (o.x_min + o.x_max), 0.5 * (o.y_min + o.y_max));
  Rect front;
  front.centre = T_world_board * Eigen::Vector3d(c.x(), c.y(), 0.0);
  front.u = T_world_board.R.col(0);
  front.v = T_world_board.R.col(1);
  front.half_u = 0.5 * o.width();
  front.half_v = 0.5 * o.height();
  front.reflectivity = 0.9;
  front.pattern = &pattern;
  front.board_origin_uv = c;
  front.id = id;
  // The rest of the board: a box of the board's thickness behind the printed face.
  const double th = std::max(target.thickness, 1e-4);
  SE3 T_box = T_world_board;
  T_box.t = T_world_board * Eigen::Vector3d(c.x(), c.y(), 0.5 * th + 1e-5);
  add_box(scene, T_box, Eigen::Vector3d(0.5 * o.width(), 0.5 * o.height(), 0.5 * th), 0.5, id);
  scene.rects.push_back(front);  // last: wins ties with the box's front face
  // A stand: a thin vertical post (4 x 4 cm) from the floor up behind the board's centre. Its top
  // is lowered until no part of it is inside the board's slab (a tilted board would otherwise be
  // pierced by it, and post points would lie on or in front of the printed face).
  const SE3 T_board_world = T_world_board.inverse();
  const Eigen::Vector3d centre_back = T_world_board * Eigen::Vector3d(c.x(), c.y(), th + 0.03);
  const double half = 0.02;
  auto pierces = [&](double top) {
    for (double z = z_floor; z <= top + 1e-9; z += 0.005) {
      for (double dx = -half; dx <= half + 1e-9; dx += 0.01) {
        for (double dy = -half; dy <= half + 1e-9; dy += 0.01) {
          const Eigen::Vector3d q =
              T_board_world * Eigen::Vector3d(centre_back.x() + dx, centre_back.y() + dy, z);
          if (q.z() < th + 0.002 && q.z() > -0.05 && q.x() > o.x_min - 0.01 &&
              q.x() < o.x_max + 0.01 && q.y() > o.y_min - 0.01 && q.y() < o.y_max + 0.01)
            return true;
        }
      }
    }
    return false;
  };
  double top = centre_back.z();
  while (top - z_floor > 0.05 && pierces(top)) top -= 0.01;
  const double height = top - z_floor;
  if (height > 0.05) {
    SE3 T_post;
    T_post.t = Eigen::Vector3d(centre_back.x(), centre_back.y(), z_floor + 0.5 * height);
    add_box(scene, T_post, Eigen::Vector3d(half, half, 0.5 * height), 0.4, 0);
  }
}

void add_room(Scene& scene, double hx, double hy, double z_floor, double z_ceiling) {
  SE3 T;
  T.t = Eigen::Vector3d(0, 0, 0.5 * (z_floor + z_ceiling));
  // The inside faces of a big box.
  add_box(scene, T, Eigen::Vector3d(hx, hy, 0.5 * (z_ceiling - z_floor)), 0.3, 0);
}

LidarModel os0_128() { return {128, 90.0, 2048, 10.0, 0.01, 0.3, 50.0}; }
LidarModel os1_64() { return {64, 45.0, 1024, 20.0, 0.01, 0.5, 120.0}; }

namespace {

// A rectangle's bounding sphere radius and its highest point.
double radius(const Rect& r) { return std::hypot(r.half_u, r.half_v); }
double top_z(const Rect& r) {
  return r.centre.z() + std::abs(r.u.z()) * r.half_u + std::abs(r.v.z()) * r.half_v;
}

}  // namespace

std::vector<LidarPoint> sweep(const Scene& scene, const LidarModel& m,
                              const std::function<SE3(double)>& T_world_lidar, double t0,
                              std::mt19937_64& rng) {
  const double period = 1.0 / m.rate_hz;
  std::vector<std::vector<LidarPoint>> columns(m.columns);
  std::vector<SE3> poses(m.columns);
  for (int c = 0; c < m.columns; ++c) poses[c] = T_world_lidar(t0 + period * c / m.columns);
  // The rectangles a ray of this sweep can reach, nearest first by a lower bound of their
  // distance from any of the sweep's origins; a ray stops once that bound passes its best hit.
  // Ties keep the scene's order (the later rectangle wins, as in a scan of all of them), so the
  // result is the same as testing every rectangle.
  double travel = 0;
  for (const SE3& T : poses) travel = std::max(travel, (T.t - poses[0].t).norm());
  struct Candidate {
    const Rect* rect;
    size_t index;
    double lower_bound;
  };
  std::vector<Candidate> near;
  double z_top = -std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < scene.rects.size(); ++i) {
    const Rect& r = scene.rects[i];
    const double lb = (r.centre - poses[0].t).norm() - radius(r) - travel;
    if (lb > m.max_range_m) continue;
    near.push_back({&r, i, lb});
    z_top = std::max(z_top, top_z(r));
  }
  std::sort(near.begin(), near.end(), [](const Candidate& a, const Candidate& b) {
    return a.lower_bound < b.lower_bound || (a.lower_bound == b.lower_bound && a.index < b.index);
  });
  // And by the azimuth of their bounding spheres seen from above: a ray heading (in the world's
  // x-y plane) within a sector meets only the rectangles whose azimuth span overlaps it (seen from
  // the sweep's first origin, the spheres grown by the sweep's travel).
  constexpr int kSectors = 128;
  auto sector_of = [](double azimuth) {
    const int k = static_cast<int>(std::floor((azimuth + M_PI) / (2.0 * M_PI) * kSectors));
    return ((k % kSectors) + kSectors) % kSectors;
  };
  std::vector<std::vector<Candidate>> sectors(kSectors);
  for (const Candidate& k : near) {
    const Eigen::Vector2d dxy = (k.rect->centre - poses[0].t).head<2>();
    const double reach = radius(*k.rect) + travel, dist = dxy.norm();
    if (dist <= reach * (1.0 + 1e-9) + 1e-9) {
      for (std::vector<Candidate>& sec : sectors) sec.push_back(k);
      continue;
    }
    const double azimuth = std::atan2(dxy.y(), dxy.x()), half = std::asin(reach / dist) + 1e-9;
    const int first =
        static_cast<int>(std::floor((azimuth - half + M_PI) / (2.0 * M_PI) * kSectors));
    const int last =
        static_cast<int>(std::floor((azimuth + half + M_PI) / (2.0 * M_PI) * kSectors));
    for (int j = first; j <= last && j < first + kSectors; ++j)
      sectors[((j % kSectors) + kSectors) % kSectors].push_back(k);
  }
  tbb::parallel_for(0, m.columns, [&](int c) {
    const SE3& T = poses[c];
    // Ouster spins clockwise seen from above: azimuth decreases with the column.
    const double azimuth = 2.0 * M_PI * (1.0 - static_cast<double>(c) / m.columns);
    for (int b = 0; b < m.beams; ++b) {
      const double elevation =
          (0.5 * m.vertical_fov_deg - m.vertical_fov_deg * b / std::max(1, m.beams - 1)) * M_PI /
          180.0;
      const Eigen::Vector3d d_lidar(std::cos(elevation) * std::cos(azimuth),
                                    std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
      const Eigen::Vector3d o = T.t, d = T.R * d_lidar;
      double best = m.max_range_m;
      // A ray rising above every rectangle's top cannot hit anything beyond that height.
      const double limit = d.z() > 1e-9 ? std::min(best, (z_top - o.z()) / d.z() + 1.0) : best;
      const Rect* hit = nullptr;
      size_t hit_index = 0;
      const bool vertical = d.head<2>().norm() < 1e-6;
      for (const Candidate& k : vertical ? near : sectors[sector_of(std::atan2(d.y(), d.x()))]) {
        if (k.lower_bound > std::min(best, limit)) break;
        const Rect& r = *k.rect;
        const Eigen::Vector3d n = r.u.cross(r.v);
        const double denom = n.dot(d);
        if (std::abs(denom) < 1e-12) continue;
        const double s = n.dot(r.centre - o) / denom;
        if (s < m.min_range_m || s > best) continue;
        if (s == best && hit && k.index < hit_index) continue;
        const Eigen::Vector3d q = o + s * d - r.centre;
        if (std::abs(q.dot(r.u)) > r.half_u || std::abs(q.dot(r.v)) > r.half_v) continue;
        best = s;
        hit = &r;
        hit_index = k.index;
      }
      if (!hit) continue;
      LidarPoint p;
      p.p = (best * d_lidar).cast<float>();  // noise is added below, in a fixed order
      p.ring = static_cast<uint16_t>(b);
      p.t_ns = static_cast<uint32_t>(std::llround(1e9 * period * c / m.columns));
      p.object = hit->id;
      const Eigen::Vector3d n = hit->u.cross(hit->v);
      double albedo = 1.0;
      if (hit->pattern) {
        const Eigen::Vector3d q = o + best * d - hit->centre;
        albedo = 0.1 + 0.9 * hit->pattern->albedo(hit->board_origin_uv.x() + q.dot(hit->u),
                                                  hit->board_origin_uv.y() + q.dot(hit->v));
      }
      const double incidence = hit->retroreflective ? 1.0 : std::abs(n.dot(d));
      p.intensity = static_cast<float>(1000.0 * hit->reflectivity * albedo * incidence);
      columns[c].push_back(p);
    }
  });
  // Range noise, drawn in a fixed order so that results do not depend on threads.
  std::normal_distribution<double> N(0.0, m.range_noise_m);
  std::vector<LidarPoint> out;
  for (auto& col : columns) {
    for (LidarPoint& p : col) {
      const double r = p.p.cast<double>().norm();
      p.p = (p.p.cast<double>() * ((r + N(rng)) / r)).cast<float>();
      out.push_back(p);
    }
  }
  return out;
}

Scan scan_of(const std::vector<LidarPoint>& points, Time stamp) {
  Scan scan;
  scan.stamp = stamp;
  scan.point_times = true;
  scan.points.reserve(points.size());
  for (const LidarPoint& p : points)
    scan.points.push_back({.p = p.p, .t_ns = p.t_ns, .intensity = p.intensity, .ring = p.ring});
  return scan;
}

}  // namespace rigcal::sim
