#include "rigcal/sim/building.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "rigcal/core/error.h"

namespace rigcal::sim {
namespace {

// 3 u^2 - 2 u^3 on [0, 1]: from 0 to 1 with zero slope at both ends.
double building_ease(double u) {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * (3.0 - 2.0 * u);
}

// The path's horizontal position at path length s (clamped to the building's span).
Eigen::Vector2d building_point_at(const Building& b, double s) {
  s = std::clamp(s, 0.0, b.length_m);
  const size_t j = std::min<size_t>(
      b.s.size() - 1,
      std::max<size_t>(1, size_t(std::lower_bound(b.s.begin(), b.s.end(), s) - b.s.begin())));
  const double ds = b.s[j] - b.s[j - 1];
  const double f = ds > 0 ? (s - b.s[j - 1]) / ds : 0.0;
  return (1 - f) * b.p[j - 1] + f * b.p[j];
}

// The path's horizontal direction at path length s, over 1 m of it (the walk's sway averaged).
Eigen::Vector2d building_direction_at(const Building& b, double s) {
  Eigen::Vector2d d = building_point_at(b, s + 0.5) - building_point_at(b, s - 0.5);
  if (d.norm() < 1e-9) d = b.p.back() - b.p.front();
  if (d.norm() < 1e-9) d = Eigen::Vector2d::UnitX();
  return d.normalized();
}

double distance_to_segment(const Eigen::Vector2d& q, const Eigen::Vector2d& a,
                           const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double l2 = ab.squaredNorm();
  const double f = l2 > 0 ? std::clamp((q - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (a + f * ab - q).norm();
}

// A box on the ground, yawed along `along`: from z_ground + z_from to z_ground + z_to, the
// segment a-b (its length extended by `extend` at each end) and `half_width` to each side.
Box building_box(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double extend,
                 double half_width, double z_ground, double z_from, double z_to, int id) {
  Eigen::Vector2d along = b - a;
  const double length = along.norm();
  along = length > 1e-9 ? Eigen::Vector2d(along / length) : Eigen::Vector2d::UnitX();
  Box box;
  box.T_world_box.R.col(0) << along, 0;
  box.T_world_box.R.col(1) << -along.y(), along.x(), 0;
  box.T_world_box.R.col(2) = Eigen::Vector3d::UnitZ();
  box.T_world_box.t << 0.5 * (a + b), z_ground + 0.5 * (z_from + z_to);
  box.half_extents << 0.5 * length + extend, half_width, 0.5 * (z_to - z_from);
  box.id = id;
  return box;
}

}  // namespace

Building plan_building(const PoseSource& flat, double t_in, double t_out) {
  Building b;
  b.t_in = t_in;
  b.t_out = t_out;
  const int n = std::max(2, static_cast<int>(std::ceil((t_out - t_in) / 0.05)) + 1);
  for (int i = 0; i < n; ++i) {
    const double t = t_in + (t_out - t_in) * i / (n - 1);
    const Eigen::Vector2d p = flat(t).t.head<2>();
    b.s.push_back(b.p.empty() ? 0.0 : b.s.back() + (p - b.p.back()).norm());
    b.t.push_back(t);
    b.p.push_back(p);
  }
  b.length_m = b.s.back();
  const double needed = 2 * b.hall_m + 2 * b.flight_m() + 1.0;
  if (b.length_m < needed) {
    throw Error(fmt::format(
        "the building (trajectories.building): the path indoors, over the first outage ({} to "
        "{} s), is {:.1f} m long; its halls and two flights of stairs need {:.1f} m: a longer "
        "outage, or no building",
        t_in, t_out, b.length_m, needed));
  }
  b.up_from_s = b.hall_m;
  b.down_from_s = b.length_m - b.hall_m - b.flight_m();
  return b;
}

double stairs_height(const Building& b, double t) {
  if (!(t > b.t_in && t < b.t_out) || b.t.size() < 2) return 0.0;
  const double u = (t - b.t_in) / (b.t_out - b.t_in) * double(b.t.size() - 1);
  const size_t i = std::min(b.t.size() - 2, static_cast<size_t>(u));
  const double f = u - double(i);
  const double s = (1 - f) * b.s[i] + f * b.s[i + 1];
  return b.storey_m() * (building_ease((s - b.up_from_s) / b.flight_m()) -
                         building_ease((s - b.down_from_s) / b.flight_m()));
}

PoseSource climbing(const PoseSource& flat, std::shared_ptr<const Building> building) {
  return [flat, building](double t) {
    SE3 T = flat(t);
    T.t.z() += stairs_height(*building, t);
    return T;
  };
}

double distance_to_indoor_path(const Building& b, const Eigen::Vector2d& q) {
  double best = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector2d& p : b.p) best = std::min(best, (p - q).norm());
  return best;
}

std::vector<Box> building_boxes(const Building& b, double z_ground,
                                const std::vector<Eigen::Vector2d>& outdoor) {
  std::vector<Box> out;
  const double w = b.half_width_m, height = b.height_m(), thick = 0.05;  // walls 10 cm thick
  // A wall or step the rest of the path comes within 1 m of is left out.
  auto clear_of_outdoor = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& c, double reach) {
    for (const Eigen::Vector2d& q : outdoor)
      if (distance_to_segment(q, a, c) < reach + 1.0) return false;
    return true;
  };
  // The path every metre or so: the walls along it, the roof over it.
  const int m = std::max(1, static_cast<int>(std::round(b.length_m)));
  std::vector<Eigen::Vector2d> centre, across;
  for (int j = 0; j <= m; ++j) {
    const double s = b.length_m * j / m;
    const Eigen::Vector2d d = building_direction_at(b, s);
    centre.push_back(building_point_at(b, s));
    across.emplace_back(-d.y(), d.x());
  }
  for (int j = 0; j < m; ++j) {
    for (const double side : {-1.0, 1.0}) {
      const Eigen::Vector2d a = centre[j] + side * w * across[j];
      const Eigen::Vector2d c = centre[j + 1] + side * w * across[j + 1];
      // Where the path bends tighter than the corridor is wide, the inner wall folds back
      // towards it: left out where it would come within 1 m.
      double nearest = std::numeric_limits<double>::infinity();
      for (const Eigen::Vector2d& p : b.p)
        nearest = std::min(nearest, distance_to_segment(p, a, c));
      if (nearest < 1.0 || !clear_of_outdoor(a, c, thick)) continue;
      out.push_back(building_box(a, c, thick, thick, z_ground, 0.0, height, kBuildingWall));
    }
    out.push_back(building_box(centre[j], centre[j + 1], 1.0, w + 0.1, z_ground, height,
                               height + 0.1, kBuildingRoof));
  }
  // The walls across the path at the doors: on each side of the opening, and above it.
  for (const int end : {0, m}) {
    const Eigen::Vector2d& c = centre[end];
    const double half_door = 0.5 * b.door_width_m;
    for (const double side : {-1.0, 1.0}) {
      const Eigen::Vector2d a = c + side * half_door * across[end];
      const Eigen::Vector2d e = c + side * w * across[end];
      // A box whose length runs across the path: from the opening's side to the corner.
      if (clear_of_outdoor(a, e, thick))
        out.push_back(building_box(a, e, 0.0, thick, z_ground, 0.0, height, kBuildingWall));
    }
    out.push_back(building_box(c - half_door * across[end], c + half_door * across[end], 0.0, thick,
                               z_ground, b.door_height_m, height, kBuildingWall));
  }
  // The stairs: solid steps 1.2 m wide along the path, up from the first hall and down to the
  // second.
  for (int i = 0; i < b.steps; ++i) {
    for (const bool up : {true, false}) {
      const double s0 = (up ? b.up_from_s : b.down_from_s) + i * b.tread_m;
      const double top = (up ? i + 1 : b.steps - i) * b.rise_m;
      const Eigen::Vector2d a = building_point_at(b, s0), c = building_point_at(b, s0 + b.tread_m);
      if (!clear_of_outdoor(a, c, 0.6)) continue;
      out.push_back(building_box(a, c, 0.005, 0.6, z_ground, 0.0, top, kBuildingStairs));
    }
  }
  // The gallery between the flights: a floor 1.6 m wide, 0.2 m thick, at the storey's height.
  const double from = b.up_from_s + b.flight_m(), to = b.down_from_s;
  const int g = std::max(1, static_cast<int>(std::round(to - from)));
  for (int j = 0; j < g; ++j) {
    const Eigen::Vector2d a = building_point_at(b, from + (to - from) * j / g);
    const Eigen::Vector2d c = building_point_at(b, from + (to - from) * (j + 1) / g);
    out.push_back(
        building_box(a, c, 0.3, 0.8, z_ground, b.storey_m() - 0.2, b.storey_m(), kBuildingGallery));
  }
  return out;
}

}  // namespace rigcal::sim
