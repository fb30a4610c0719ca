#pragma once
// A building on a simulated walk (doc/simulator.md, "The ground-truth recording"): over a span of
// the walk (the GNSS outage) the path is indoors. The building follows the path as a corridor
// (walls 1.8 m to each side of it, a roof), entered and left through a door (1 m wide, 2.1 m
// tall) in the walls across the path where it enters and leaves; inside, a flight of stairs the
// path climbs by a storey, a gallery along the path up there, and a second flight down, so the
// walk leaves at ground level. The path's height follows the stairs: the pose source is wrapped,
// so the truth, the odometry, the GNSS and the sweeps all see it.
#include <Eigen/Core>
#include <memory>
#include <vector>

#include "rigcal/core/se3.h"
#include "rigcal/sim/trajectories.h"

namespace rigcal::sim {

struct Building {
  double t_in = 0, t_out = 0;  // motion time (s) the path goes through the doors
  // The path over [t_in, t_out] every 0.05 s: time, its length since the entrance (m), and its
  // horizontal position (world frame).
  std::vector<double> t, s;
  std::vector<Eigen::Vector2d> p;
  double length_m = 0;  // of the path indoors
  // Stairs of 15 steps rising 0.17 m on 0.28 m treads (a usual public stair: 2 x rise + tread
  // = 0.62 m, within the 0.60-0.65 m of the step rule): a storey of 2.55 m over 4.2 m of path.
  int steps = 15;
  double rise_m = 0.17, tread_m = 0.28;
  double storey_m() const { return steps * rise_m; }
  double flight_m() const { return steps * tread_m; }
  // The path's length from the entrance to the first step up, and from the last step down to
  // the exit: a hall at ground level at each door.
  double hall_m = 2.0;
  double up_from_s = 0, down_from_s = 0;  // path length where each flight starts
  double half_width_m = 1.8;              // the walls from the path
  double door_width_m = 1.0, door_height_m = 2.1;
  // The roof above the ground (m): the gallery's floor plus 2.7 m.
  double height_m() const { return storey_m() + 2.7; }
};

// The building over the motion time [t_in, t_out] of `flat` (the path without the stairs'
// height). Throws rigcal::Error when that part of the path is too short for two flights of
// stairs and the halls (2 x 2 m + 2 x 4.2 m + 1 m of gallery).
Building plan_building(const PoseSource& flat, double t_in, double t_out);

// The height the stairs add to the path at motion time t (0 outside the building): eased into
// and out of each flight (a cubic smoothstep over the flight's length), so the motion stays
// smooth.
double stairs_height(const Building& building, double t);

// `flat` with the stairs' height added.
PoseSource climbing(const PoseSource& flat, std::shared_ptr<const Building> building);

// The building's parts: walls (object id kBuildingWall), roof (kBuildingRoof), steps
// (kBuildingStairs) and the gallery's floor (kBuildingGallery), as boxes standing on the ground
// at z_ground. A wall or step that `outdoor` (the rest of the path, horizontal positions) comes
// within 1 m of is left out (a walk that comes back across the building passes through a gap).
struct Box {
  SE3 T_world_box;
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();
  int id = 0;
};
constexpr int kBuildingWall = 201, kBuildingRoof = 202, kBuildingStairs = 203,
              kBuildingGallery = 204;
std::vector<Box> building_boxes(const Building& building, double z_ground,
                                const std::vector<Eigen::Vector2d>& outdoor);

// The horizontal distance from q to the path indoors (its samples), m.
double distance_to_indoor_path(const Building& building, const Eigen::Vector2d& q);

}  // namespace rigcal::sim
