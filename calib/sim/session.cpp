#include "rigcal/sim/session.h"

#include <fmt/format.h>

#include <limits>
#include <map>
#include <set>

#include "rigcal/core/error.h"
#include "rigcal/io/image_io.h"

namespace rigcal::sim {
namespace {

const rig::Sensor& camera_named(const rig::Rig& rig, std::string_view name, size_t fallback_index) {
  const rig::Sensor* camera = rig::find_sensor(rig, name);
  if (!camera || camera->type != rig::SensorType::camera) {
    const std::vector<const rig::Sensor*> cams = rig::cameras(rig);
    if (cams.size() <= fallback_index) {
      throw Error(fmt::format("the rig needs {} camera(s) to simulate this; it has {}",
                              fallback_index + 1, cams.size()));
    }
    camera = cams[fallback_index];
  }
  // Images rigcal could not read back are not rendered (nor their memory spent).
  const long long width = camera->camera.width, height = camera->camera.height;
  if (!io::within_image_limits(width, height)) {
    throw Error(fmt::format("{}: {} x {} px is larger than rigcal reads ({} Mpx); not simulated",
                            camera->name, width, height, io::kMaxImagePixels / 1000000));
  }
  return *camera;
}

const rig::Sensor* imu_named(const rig::Rig& rig, std::string_view name) {
  const rig::Sensor* s = rig::find_sensor(rig, name);
  return s && s->type == rig::SensorType::imu ? s : nullptr;
}

}  // namespace

camera::Target default_target() {
  camera::Target t;
  t.name = "a3_checkerboard_8x5_40mm";
  t.type = camera::TargetType::checkerboard;
  t.cols = 8;
  t.rows = 5;
  t.square = 0.040;
  t.margin = 0.028;  // a 28 mm quiet zone: 416 x 296 mm on an A3 sheet
  return t;
}

std::mt19937_64 part_rng(uint64_t seed, std::string_view part) {
  uint64_t h = 1469598103934665603ULL;  // FNV-1a of the part's name, mixed with the seed
  for (char c : part) h = (h ^ static_cast<uint8_t>(c)) * 1099511628211ULL;
  std::seed_seq seq{static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32),
                    static_cast<uint32_t>(h), static_cast<uint32_t>(h >> 32)};
  return std::mt19937_64(seq);
}

StereoPart simulate_stereo(const rig::Rig& rig, const SimConfig& cfg) {
  std::mt19937_64 rng = part_rng(cfg.seed, "stereo");
  const rig::Sensor& left = camera_named(rig, "cam_l", 0);
  const rig::Sensor& right = camera_named(rig, "cam_r", 1);
  StereoPart part;
  part.left_name = left.name;
  part.right_name = right.name;
  const SE3 T_right_left = rig::T_a_b(rig, right.name, left.name);
  part.T_left_board =
      board_poses(left.camera, &right.camera, T_right_left, cfg.target, cfg.boards, rng);
  const camera::Pattern pattern(cfg.target);
  const PixelRays rays_l = pixel_rays(left.camera), rays_r = pixel_rays(right.camera);
  std::vector<Eigen::Vector3d> points = camera::object_points(cfg.target);
  for (Eigen::Vector3d& p : points) p = camera::warped(cfg.target, p, cfg.board_warp_m);
  for (size_t k = 0; k < part.T_left_board.size(); ++k) {
    const SE3& T_l = part.T_left_board[k];
    const SE3 T_r = T_right_left * T_l;
    part.stamps.push_back(Time::from_seconds(cfg.base_start_s + k * cfg.frame_period_s));
    part.left.push_back(
        render_board(rays_l, cfg.target, pattern, T_l, cfg.image, rng, cfg.board_warp_m));
    part.right.push_back(
        render_board(rays_r, cfg.target, pattern, T_r, cfg.image, rng, cfg.board_warp_m));
    part.corners_left.push_back(project_points(left.camera, T_l, points));
    part.corners_right.push_back(project_points(right.camera, T_r, points));
  }
  return part;
}

LidarCameraPart simulate_lidar_camera(const rig::Rig& rig, const SimConfig& cfg) {
  std::mt19937_64 rng = part_rng(cfg.seed, "lidar-camera");
  const rig::Sensor& cam = camera_named(rig, cfg.lidar_camera_camera, 1);
  LidarCameraPart part;
  part.camera_name = cam.name;
  const SE3 T_lidar_cam = rig::T_a_b(rig, rig.base_frame, cam.name);
  BoardPoseConfig boards = cfg.boards;
  boards.views = cfg.lidar_camera_pairs;
  boards.min_fill = 0.15;
  boards.max_fill = 0.45;  // a board on a stand, 1.5 to 4 m away
  boards.max_tilt_deg = 40;
  part.T_camera_board = board_poses(cam.camera, nullptr, SE3(), cfg.target, boards, rng);
  const camera::Pattern pattern(cfg.target);
  const PixelRays rays = pixel_rays(cam.camera);
  std::vector<Eigen::Vector3d> points = camera::object_points(cfg.target);
  for (Eigen::Vector3d& p : points) p = camera::warped(cfg.target, p, cfg.board_warp_m);
  const double z_floor = -1.3, z_ceiling = 2.2;  // the LiDAR 1.3 m above the floor
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (size_t k = 0; k < part.T_camera_board.size(); ++k) {
    const SE3 T_lidar_board = T_lidar_cam * part.T_camera_board[k];
    part.T_lidar_board.push_back(T_lidar_board);
    part.stamps.push_back(Time::from_seconds(cfg.base_start_s + 10.0 * k));
    part.images.push_back(render_board(rays, cfg.target, pattern, part.T_camera_board[k], cfg.image,
                                       rng, cfg.board_warp_m));
    part.corners.push_back(project_points(cam.camera, part.T_camera_board[k], points));
    Scene scene;
    add_room(scene, 7.0, 5.0, z_floor, z_ceiling);
    add_board(scene, cfg.target, pattern, T_lidar_board, z_floor, 1);
    if (cfg.clutter) {
      // A person-sized box 0.6 to 1 m beside the board, on the floor.
      const Eigen::Vector3d c = T_lidar_board * Eigen::Vector3d(0.2, 0.15, 0.0);
      const Eigen::Vector3d side = Eigen::Vector3d(-c.y(), c.x(), 0.0).normalized();
      SE3 T_person;
      T_person.t = c + side * (0.8 + 0.2 * U(rng)) * (U(rng) > 0 ? 1 : -1);
      T_person.t.z() = z_floor + 0.9;
      T_person.R = Eigen::AngleAxisd(U(rng), Eigen::Vector3d::UnitZ()).toRotationMatrix();
      add_box(scene, T_person, Eigen::Vector3d(0.25, 0.15, 0.9), 0.4, 2);
    }
    part.scans.push_back(sweep(
        scene, cfg.lidar, [](double) { return SE3(); }, 0.0, rng));
  }
  return part;
}

ImuPart simulate_imu_part(const rig::Rig& rig, const SimConfig& cfg) {
  std::mt19937_64 rng = part_rng(cfg.seed, "imu");
  ImuPart part;
  part.motion = random_motion(cfg.imu_motion, cfg.imu_duration_s + 1.0, rng);
  const rig::Sensor* imu = imu_named(rig, "imu");
  const rig::Sensor* os_imu = imu_named(rig, "os_imu");
  if (!imu || !os_imu)
    throw Error("simulating IMU streams needs IMU sensors named 'imu' and 'os_imu' in the rig");
  part.imu_name = imu->name;
  part.os_imu_name = os_imu->name;
  ImuSimConfig a = cfg.imu, b = cfg.os_imu;
  a.time_offset_s = imu->time_offset;  // the truth is the rig's
  b.time_offset_s = os_imu->time_offset;
  if (imu->update_rate) a.rate_hz = *imu->update_rate;
  if (os_imu->update_rate) b.rate_hz = *os_imu->update_rate;
  part.imu_offset_s = a.time_offset_s;
  part.os_imu_offset_s = b.time_offset_s;
  part.imu_drift_ppm = a.drift_ppm;
  part.os_imu_drift_ppm = b.drift_ppm;
  const Time start = Time::from_seconds(cfg.base_start_s);
  part.imu =
      simulate_imu(part.motion, imu->T_base_sensor, imu->imu, a, start, cfg.imu_duration_s, rng);
  part.os_imu = simulate_imu(part.motion, os_imu->T_base_sensor, os_imu->imu, b, start,
                             cfg.imu_duration_s, rng);
  return part;
}

TrajectoryPart simulate_trajectories(const rig::Rig& rig, const SimConfig& cfg,
                                     const Trajectory* replay) {
  std::mt19937_64 rng = part_rng(cfg.seed, "trajectories");
  TrajectoryPart part;
  const rig::Sensor* gnss = rig::find_sensor(rig, "gnss");
  if (!gnss) gnss = imu_named(rig, "imu");
  if (!gnss)
    throw Error("simulating GNSS/INS poses needs a sensor named 'gnss' or 'imu' in the rig");
  part.gnss_name = gnss->name;
  Motion motion;
  PoseSource source;
  double duration = cfg.trajectory_duration_s;
  if (replay) {
    auto [s, d] = pose_source(*replay);
    source = s;
    duration = std::min(duration, d);
  } else {
    motion = random_motion(cfg.trajectory_motion, duration + 1.0, rng);
    source = pose_source(motion);
  }
  if (cfg.building && cfg.trajectory_motion != MotionKind::car && !cfg.gnss.outages.empty()) {
    // Indoors over the first outage (the earliest), within the trajectory; a car does not take
    // the stairs.
    const auto first = *std::min_element(cfg.gnss.outages.begin(), cfg.gnss.outages.end());
    const double from = std::max(first.first, 0.0), to = std::min(first.second, duration);
    if (!(to > from)) {
      throw Error(fmt::format(
          "the building (trajectories.building) is over the first outage, {} to {} s, which is "
          "not within the trajectory's {} s",
          first.first, first.second, duration));
    }
    part.building = std::make_shared<const Building>(plan_building(source, from, to));
    source = climbing(source, part.building);
  }
  const rig::Sensor& base = rig::sensor(rig, rig.base_frame);
  part.rate_hz = base.update_rate.value_or(10.0);
  const double rate = part.rate_hz;
  const Time start = Time::from_seconds(cfg.base_start_s);
  part.truth_base = sample_poses(source, rate, duration, start);
  part.source = source;
  part.odometry = simulate_odometry(part.truth_base, cfg.odometry, rng);
  part.T_enu_world =
      SE3::from_rotation_vector(Eigen::Vector3d(0, 0, 0.7), Eigen::Vector3d(120.0, -45.0, 21.0));
  GnssNoise noise = cfg.gnss;
  noise.time_offset_s = gnss->time_offset;
  if (gnss->update_rate) noise.rate_hz = *gnss->update_rate;
  part.gnss = simulate_gnss(source, duration, start, gnss->T_base_sensor, part.T_enu_world, noise,
                            rng, &part.gnss_outliers, &part.gnss_states);
  for (const FixState state : part.gnss_states) {
    const auto [h, v] = fix_sigmas(noise, state);
    part.gnss_std_enu_m.emplace_back(h, h, v);
  }
  return part;
}

SweepDrive street_drive(const rig::Rig& rig, const SimConfig& cfg) {
  SweepDrive drive;
  std::mt19937_64& rng = drive.rng;
  rng = part_rng(cfg.seed, "scans");
  Scene& scene = drive.scene;
  Motion motion = random_motion(MotionKind::car, cfg.scans / cfg.lidar.rate_hz + 2.0, rng);
  motion.speed = 5.0;
  prepare(motion, cfg.scans / cfg.lidar.rate_hz + 2.0);
  // A street world: ground, box buildings on both sides of the path, poles, clutter.
  SE3 T_ground;
  T_ground.t = Eigen::Vector3d(0, 0, -1.8 - 0.05);
  add_box(scene, T_ground, Eigen::Vector3d(400, 400, 0.05), 0.2);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const double length = motion.speed * (cfg.scans / cfg.lidar.rate_hz + 2.0) + 40.0;
  for (double s = -20.0; s < length; s += 8.0 + 8.0 * U(rng)) {
    for (int side : {-1, 1}) {
      // Along the path's start heading; the path turns slowly, so buildings are placed along it.
      const SE3 T_path =
          evaluate(motion, std::clamp(s / motion.speed, 0.0, cfg.scans / cfg.lidar.rate_hz + 1.9))
              .T_world_base;
      SE3 T_building;
      T_building.R = Eigen::AngleAxisd(rotation_vector(T_path.R).z() + 0.2 * (U(rng) - 0.5),
                                       Eigen::Vector3d::UnitZ())
                         .toRotationMatrix();
      const double setback = 9.0 + 6.0 * U(rng);
      T_building.t = T_path.t + T_building.R * Eigen::Vector3d(0.0, side * setback, 0.0);
      const Eigen::Vector3d h(3.0 + 3.0 * U(rng), 2.0 + 2.0 * U(rng), 4.0 + 8.0 * U(rng));
      T_building.t.z() = -1.8 + h.z();
      T_building.t += T_building.R * Eigen::Vector3d(0.0, side * h.y(), 0.0);
      add_box(scene, T_building, h, 0.3 + 0.3 * U(rng));
      if (U(rng) < 0.6) {  // a pole at the kerb
        SE3 T_pole;
        T_pole.t = T_path.t + T_building.R * Eigen::Vector3d(2.0 * U(rng), side * 5.0, 0.0);
        T_pole.t.z() = -1.8 + 3.0;
        add_box(scene, T_pole, Eigen::Vector3d(0.08, 0.08, 3.0), 0.6);
      }
      if (U(rng) < 0.3) {  // clutter: a parked car-sized box
        SE3 T_car;
        T_car.R = T_building.R;
        T_car.t = T_path.t + T_building.R * Eigen::Vector3d(3.0 * U(rng), side * 3.5, 0.0);
        T_car.t.z() = -1.8 + 0.75;
        add_box(scene, T_car, Eigen::Vector3d(2.2, 0.9, 0.75), 0.5);
      }
    }
  }
  const SE3 T_base_lidar = rig::sensor(rig, rig.base_frame).T_base_sensor;
  drive.T_world_lidar = [motion, T_base_lidar](double t) {
    return evaluate(motion, t).T_world_base * T_base_lidar;
  };
  drive.lidar = cfg.lidar;
  drive.base_start_s = cfg.base_start_s;
  return drive;
}

SweepDrive trajectory_drive(const rig::Rig& rig, const SimConfig& cfg, const TrajectoryPart& part) {
  if (part.truth_base.empty() || !part.source)
    throw Error("sweeps along a trajectory need the trajectories part's poses");
  SweepDrive drive;
  std::mt19937_64& rng = drive.rng;
  rng = part_rng(cfg.seed, "trajectory-scans");
  std::uniform_real_distribution<double> U(0.0, 1.0);
  // The path every metre or so, in a hash grid of cells as large as the box grid's.
  constexpr double kCell = 8.0, kReach = 36.0, kClearance = 2.0;
  std::vector<Eigen::Vector2d> path;
  double z_min = std::numeric_limits<double>::infinity();
  for (const SE3& T : part.truth_base.T_world_body) {
    z_min = std::min(z_min, T.t.z());
    if (path.empty() || (T.t.head<2>() - path.back()).norm() > 1.0) path.push_back(T.t.head<2>());
  }
  auto cell_of = [&](const Eigen::Vector2d& p) {
    return std::pair<int, int>(static_cast<int>(std::floor(p.x() / kCell)),
                               static_cast<int>(std::floor(p.y() / kCell)));
  };
  std::map<std::pair<int, int>, std::vector<Eigen::Vector2d>> path_cells;
  Eigen::Vector2d lo = path[0], hi = path[0];
  for (const Eigen::Vector2d& p : path) {
    path_cells[cell_of(p)].push_back(p);
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  auto distance_to_path = [&](const Eigen::Vector2d& q, double within) {
    const auto [cx, cy] = cell_of(q);
    const int r = static_cast<int>(std::ceil(within / kCell));
    double best = std::numeric_limits<double>::infinity();
    for (int i = cx - r; i <= cx + r; ++i) {
      for (int j = cy - r; j <= cy + r; ++j) {
        const auto it = path_cells.find({i, j});
        if (it == path_cells.end()) continue;
        for (const Eigen::Vector2d& p : it->second) best = std::min(best, (p - q).norm());
      }
    }
    return best;
  };
  // The ground below the lowest pose (a LiDAR held or mounted 1.7 m up), wide enough for the
  // sensor's range.
  const double z_ground = z_min - 1.7;
  SE3 T_ground;
  T_ground.t << 0.5 * (lo + hi), z_ground - 0.05;
  const Eigen::Vector2d half = 0.5 * (hi - lo) + Eigen::Vector2d::Constant(cfg.lidar.max_range_m);
  add_box(drive.scene, T_ground, Eigen::Vector3d(half.x(), half.y(), 0.05), 0.2);
  // The survey markers, as a total station's targets around one place (a hexahedron, in the
  // VBR paper): over the 24 m of path around its middle (all of it, if shorter), a post 3 m
  // beside the path (the other side, or 5 m, where the path comes back nearer) at even
  // intervals, alternately left and right, each with a retro-reflective square facing the path
  // at 0.8, 1.5 or 2.2 m above the ground in turn.
  const int markers = std::max(cfg.markers, 0);
  std::vector<Eigen::Vector2d> posts;
  const std::vector<SE3>& poses = part.truth_base.T_world_body;
  std::vector<double> along_path = {0.0};
  for (size_t k = 1; k < poses.size(); ++k)
    along_path.push_back(along_path.back() + (poses[k].t - poses[k - 1].t).norm());
  // The building: its walls, roof and stairs; the path outside it (2 s from its doors) must not
  // cross them.
  const Building* building = part.building.get();
  auto outdoors = [&](size_t k, double margin_s) {
    const double t = (part.truth_base.stamps[k] - part.truth_base.stamps[0]).seconds();
    return !building || t < building->t_in - margin_s || t > building->t_out + margin_s;
  };
  if (building) {
    std::vector<Eigen::Vector2d> outdoor;
    for (size_t k = 0; k < poses.size(); ++k)
      if (outdoors(k, 2.0)) outdoor.push_back(poses[k].t.head<2>());
    drive.building = building_boxes(*building, z_ground, outdoor);
    for (const Box& box : drive.building)
      add_box(drive.scene, box.T_world_box, box.half_extents, 0.5, box.id);
  }
  // The markers over the middle of the path, or, with a building, of its longest stretch
  // outdoors (3 s from the doors).
  double stretch_from = 0.0, stretch_to = along_path.back();
  if (building) {
    stretch_to = stretch_from;
    for (size_t k = 0; k < poses.size();) {
      size_t e = k;
      while (e < poses.size() && outdoors(e, 3.0)) ++e;
      if (e > k && along_path[e - 1] - along_path[k] > stretch_to - stretch_from)
        stretch_from = along_path[k], stretch_to = along_path[e - 1];
      k = e + 1;
    }
  }
  const double section = std::min(24.0, stretch_to - stretch_from);
  const double section_start = stretch_from + 0.5 * (stretch_to - stretch_from - section);
  for (int i = 0; i < markers; ++i) {
    const double at_length = section_start + (i + 0.5) / markers * section;
    const size_t k = std::min<size_t>(
        poses.size() - 1, size_t(std::lower_bound(along_path.begin(), along_path.end(), at_length) -
                                 along_path.begin()));
    const size_t a = k >= 10 ? k - 10 : 0, b = std::min(k + 10, poses.size() - 1);
    Eigen::Vector2d along = (poses[b].t - poses[a].t).head<2>();
    if (along.norm() < 1e-6) along = poses[k].R.col(0).head<2>();
    along.normalize();
    const Eigen::Vector2d left(-along.y(), along.x()), at = poses[k].t.head<2>();
    Eigen::Vector2d post;
    for (double side : {3.0, -3.0, 5.0, -5.0}) {
      post = at + side * (i % 2 == 0 ? left : Eigen::Vector2d(-left));
      if (distance_to_path(post, kReach) > std::abs(side) - 0.5 &&
          (!building || distance_to_indoor_path(*building, post) > building->half_width_m + 1.0))
        break;
    }
    posts.push_back(post);
    const Eigen::Vector2d facing = (at - post).normalized();
    SE3 T_post;
    T_post.R.col(0) << facing, 0;
    T_post.R.col(1) << -facing.y(), facing.x(), 0;
    T_post.R.col(2) = Eigen::Vector3d::UnitZ();
    T_post.t << post, z_ground + 1.25;
    add_box(drive.scene, T_post, Eigen::Vector3d(0.15, 0.15, 1.25), 0.4);
    Rect marker;
    marker.centre << post + (0.15 + 0.002) * facing, z_ground + 0.8 + 0.7 * (i % 3);
    marker.u = T_post.R.col(1);
    marker.v = Eigen::Vector3d::UnitZ();
    marker.half_u = marker.half_v = 0.5 * cfg.marker_side_m;
    marker.reflectivity = 5.0;
    marker.retroreflective = true;
    marker.id = 100 + i;
    drive.scene.rects.push_back(marker);
    drive.markers.push_back(marker.centre);
  }
  auto near_a_post = [&](const Eigen::Vector2d& q, double reach) {
    for (const Eigen::Vector2d& p : posts)
      if ((p - q).norm() < reach + 1.5) return true;
    return false;
  };
  // A box (sometimes also a pole) in most cells of the grid within kReach of the path, never
  // nearer than kClearance to it.
  std::set<std::pair<int, int>> cells;
  const int reach = static_cast<int>(std::ceil(kReach / kCell));
  for (const auto& [c, points] : path_cells) {
    for (int i = -reach; i <= reach; ++i) {
      for (int j = -reach; j <= reach; ++j) cells.insert({c.first + i, c.second + j});
    }
  }
  for (const auto& [i, j] : cells) {
    const double yaw = M_PI * U(rng);
    const Eigen::Vector3d h(0.3 + 3.7 * U(rng), 0.3 + 1.7 * U(rng), 0.5 + 4.5 * U(rng));
    const Eigen::Vector2d centre((i + U(rng)) * kCell, (j + U(rng)) * kCell);
    const double reflectivity = 0.2 + 0.5 * U(rng);
    const bool box = U(rng) < 0.55, pole = U(rng) < 0.25;
    const Eigen::Vector2d pole_at((i + U(rng)) * kCell, (j + U(rng)) * kCell);
    if (box && distance_to_path(centre, kReach) > h.head<2>().norm() + kClearance &&
        !near_a_post(centre, h.head<2>().norm())) {
      SE3 T_box;
      T_box.R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      T_box.t << centre, z_ground + h.z();
      add_box(drive.scene, T_box, h, reflectivity);
    }
    if (pole && distance_to_path(pole_at, kReach) > kClearance && !near_a_post(pole_at, 0.1)) {
      SE3 T_pole;
      T_pole.t << pole_at, z_ground + 2.0;
      add_box(drive.scene, T_pole, Eigen::Vector3d(0.08, 0.08, 2.0), 0.6);
    }
  }
  const SE3 T_base_lidar = rig::sensor(rig, rig.base_frame).T_base_sensor;
  drive.T_world_lidar = [source = part.source, T_base_lidar](double t) {
    return source(t) * T_base_lidar;
  };
  drive.lidar = cfg.lidar;
  // A sweep every pose: the rate the poses are sampled at.
  drive.lidar.rate_hz = part.rate_hz;
  drive.base_start_s = cfg.base_start_s;
  drive.first_s = 0.0;
  return drive;
}

Sweep next_sweep(SweepDrive& drive) {
  const double t0 = drive.first_s + drive.next++ / drive.lidar.rate_hz;
  return {Time::from_seconds(drive.base_start_s + t0), drive.T_world_lidar(t0),
          sweep(drive.scene, drive.lidar, drive.T_world_lidar, t0, drive.rng)};
}

void ground_truth_defaults(SimConfig& c) {
  c.trajectory_duration_s = 60.0;
  c.trajectory_motion = MotionKind::walk;
  c.trajectory_scans = true;
  c.markers = 6;
  c.lidar = os0_128();
  c.lidar.beams = 64;
  c.lidar.columns = 1024;
  c.gnss.horizontal_sigma_m = 0.01;
  c.gnss.vertical_sigma_m = 0.02;
  c.gnss.correlation_time_s = 5.0;
  c.gnss.outages = {{20.0, 35.0}};
  // Float fixes for 4 s on each side of the outage (the sky closing in near the building), and
  // 2 s of single fixes later on.
  c.gnss.float_spans = {{16.0, 20.0}, {35.0, 39.0}};
  c.gnss.single_spans = {{48.0, 50.0}};
  c.building = true;  // over the outage
}

ScanPart simulate_scans(const rig::Rig& rig, const SimConfig& cfg) {
  SweepDrive drive = street_drive(rig, cfg);
  ScanPart part;
  for (int k = 0; k < cfg.scans; ++k) {
    Sweep s = next_sweep(drive);
    part.stamps.push_back(s.stamp);
    part.T_world_lidar.push_back(s.T_world_lidar);
    part.scans.push_back(std::move(s.points));
  }
  return part;
}

}  // namespace rigcal::sim
