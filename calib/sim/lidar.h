#pragma once
// Ray-cast Ouster scans (doc/simulator.md): a spinning multi-beam LiDAR against a scene of
// rectangles (walls, floor, boxes, the calibration board with its printed pattern and thickness),
// with range noise, intensity, ring and per-point time; poses may change during a sweep (motion
// distortion), as in raw Ouster scans.
#include <functional>
#include <random>
#include <vector>

#include "rigcal/camera/target.h"
#include "rigcal/core/scan.h"
#include "rigcal/core/se3.h"

namespace rigcal::sim {

struct Rect {
  Eigen::Vector3d centre, u, v;  // u, v: orthonormal in-plane axes
  double half_u = 0, half_v = 0;
  double reflectivity = 0.3;
  // The board's printed face: reflectivity * albedo at the board point (u, v are the board's x, y).
  const camera::Pattern* pattern = nullptr;
  Eigen::Vector2d board_origin_uv = Eigen::Vector2d::Zero();  // board point at the centre
  int id = 0;  // which object (0 background; the board's faces > 0)
  // A retro-reflective sheet (a survey marker): it returns 1000 * reflectivity whatever the
  // incidence, where a diffuse surface returns that times the cosine of the incidence.
  bool retroreflective = false;
};

struct Scene {
  std::vector<Rect> rects;
};

// A box: six faces.
void add_box(Scene& scene, const SE3& T_world_box, const Eigen::Vector3d& half_extents,
             double reflectivity, int id = 0);
// The calibration board: its printed front face (the target's outline) at T_world_board, the back
// and the edges of its thickness behind it (board +z), and a stand down to the floor at z_floor.
void add_board(Scene& scene, const camera::Target& target, const camera::Pattern& pattern,
               const SE3& T_world_board, double z_floor, int id);
// A room: floor, ceiling and four walls around the origin.
void add_room(Scene& scene, double half_x, double half_y, double z_floor, double z_ceiling);

struct LidarModel {
  int beams = 128;
  double vertical_fov_deg = 90.0;  // symmetric about the horizon
  int columns = 2048;
  double rate_hz = 10.0;
  double range_noise_m = 0.01;
  double min_range_m = 0.3, max_range_m = 100.0;
};
LidarModel os0_128();  // 128 beams over 90 deg, 2048 columns, 10 Hz
LidarModel os1_64();   // 64 beams over 45 deg, 1024 columns, 20 Hz

struct LidarPoint {
  Eigen::Vector3f p = Eigen::Vector3f::Zero();  // sensor frame at the point's own time, m
  float intensity = 0;
  uint16_t ring = 0;  // beam, 0 = top
  uint32_t t_ns = 0;  // since the start of the sweep
  int object = 0;     // the scene object hit (truth, not written to .bin)
};

// The sweep as the odometry reads it (what the written .bin and its sidecar give): each point
// with its time, intensity and ring.
Scan scan_of(const std::vector<LidarPoint>& points, Time stamp);

// One sweep starting at motion time t0; T_world_lidar(t) gives the sensor pose during it.
std::vector<LidarPoint> sweep(const Scene& scene, const LidarModel& model,
                              const std::function<SE3(double)>& T_world_lidar, double t0,
                              std::mt19937_64& rng);

}  // namespace rigcal::sim
