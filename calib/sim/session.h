#pragma once
// A complete simulated session for a rig (doc/simulator.md). Each part is computed on its own,
// from its own random stream (seed, part), so that selecting parts does not change the others
// and the same seed gives identical output. calib/io/session_io.h writes the parts to disk.
#include <functional>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/camera/target.h"
#include "rigcal/core/trajectory.h"
#include "rigcal/rig/rig.h"
#include "rigcal/sim/building.h"
#include "rigcal/sim/imu.h"
#include "rigcal/sim/lidar.h"
#include "rigcal/sim/stereo.h"
#include "rigcal/sim/trajectories.h"

namespace rigcal::sim {

// The A3 checkerboard rigcal assumes for a VBR-like rig: 8 x 5 inner corners, 40 mm squares,
// a 28 mm white margin (416 x 296 mm on a 420 x 297 mm sheet). The VBR paper does not give its
// board's numbers.
camera::Target default_target();

struct SimConfig {
  uint64_t seed = 1;
  double base_start_s = 1000.0;  // the base clock at the start (like vbr-devkit's small bag times)
  camera::Target target = default_target();
  // The printed board's warp (camera/target.h), m; zero: flat. In the stereo and lidar-camera
  // images (the LiDAR sees a flat board: a few mm are below its noise).
  Eigen::Vector2d board_warp_m = Eigen::Vector2d::Zero();
  // stereo: target images seen by both cameras
  BoardPoseConfig boards;
  ImageConfig image;
  double frame_period_s = 0.5;
  // lidar-camera: scans and images of the board on a stand in a room
  int lidar_camera_pairs = 10;
  std::string lidar_camera_camera = "cam_r";
  LidarModel lidar = os0_128();
  bool clutter = true;  // a person-sized box next to the board
  // imu: two streams of one hand-held motion
  double imu_duration_s = 120.0;
  MotionKind imu_motion = MotionKind::handheld;
  ImuSimConfig imu;     // the external IMU ("imu"); offsets come from the rig's time_offset
  ImuSimConfig os_imu;  // the LiDAR's IMU ("os_imu")
  // trajectories
  double trajectory_duration_s = 300.0;
  MotionKind trajectory_motion = MotionKind::handheld;
  std::string replay_tum;  // non-empty: replay this trajectory instead of a generated motion
  OdometryNoise odometry;
  GnssNoise gnss;
  // LiDAR sweeps along the trajectory, one at each true pose (the motion recording's
  // ouster_points/), in a courtyard of boxes around the path: rigcal's own odometry can then run
  // on them instead of the simulated lidar_odometry.tum.
  bool trajectory_scans = false;
  // Survey markers in that courtyard (with trajectory_scans): retro-reflective squares on posts
  // on both sides of the 24 m of path around its middle, at three heights, as a total station's
  // targets for checking the ground truth's map. -1: none, or 6 for `rigcal simulate --what
  // ground-truth`.
  int markers = -1;
  double marker_side_m = 0.2;
  // A building over the first GNSS outage (building.h): the path goes indoors through a door,
  // climbs a storey by stairs and comes down another flight, and leaves through a second door;
  // the walls, roof and stairs are in the sweeps' world. Without an outage, or for a car, no
  // building. On in the ground-truth part's defaults.
  bool building = false;
  // scans along a trajectory in a street world
  int scans = 10;
};

struct StereoPart {
  std::vector<Time> stamps;
  std::vector<SE3> T_left_board;
  std::vector<cv::Mat> left, right;
  std::vector<std::vector<Eigen::Vector2d>> corners_left, corners_right;  // true pixels
  std::string left_name, right_name;
};

struct LidarCameraPart {
  std::vector<Time> stamps;
  std::vector<SE3> T_lidar_board, T_camera_board;
  std::vector<cv::Mat> images;
  std::vector<std::vector<LidarPoint>> scans;
  std::vector<std::vector<Eigen::Vector2d>> corners;
  std::string camera_name;
};

struct ImuPart {
  Motion motion;
  std::vector<ImuSample> imu, os_imu;
  std::string imu_name, os_imu_name;
  double imu_offset_s = 0, os_imu_offset_s = 0, imu_drift_ppm = 0, os_imu_drift_ppm = 0;
};

// A point on the WGS84 ellipsoid: latitude, longitude (deg), ellipsoidal height (m).
struct GeodeticPoint {
  double latitude_deg = 0, longitude_deg = 0, height_m = 0;
};

struct TrajectoryPart {
  Trajectory truth_base;  // T_world_lidar at the LiDAR rate
  double rate_hz = 10.0;  // truth_base's: the base sensor's update rate
  Trajectory odometry;    // T_odom_lidar
  Trajectory gnss;        // T_enu_gnss on the GNSS clock
  std::vector<size_t> gnss_outliers;
  std::vector<FixState> gnss_states;  // one a pose of `gnss`
  // The standard deviations of each pose's position error (east, north, up; m): its state's.
  std::vector<Eigen::Vector3d> gnss_std_enu_m;
  SE3 T_enu_world;
  // The ENU frame's origin, for the fixes as latitude, longitude and height: by the Colosseum in
  // Rome, about 21 m above the sea, the geoid there some 48 m above the ellipsoid.
  GeodeticPoint enu_origin{41.890210, 12.492231, 69.0};
  std::string gnss_name;
  // T_world_base at motion time (s); truth_base samples it. A replay's refers to the replayed
  // trajectory.
  PoseSource source;
  // With SimConfig::building and an outage: the building, whose stairs `source` climbs.
  std::shared_ptr<const Building> building;
};

struct ScanPart {
  std::vector<Time> stamps;
  std::vector<SE3> T_world_lidar;  // at the start of each sweep
  std::vector<std::vector<LidarPoint>> scans;
};

// Sweeps made one at a time along a path, so that a drive of any length needs the memory of one
// sweep: the world, the sensor's path, and the random stream the sweeps draw from.
struct SweepDrive {
  Scene scene;
  LidarModel lidar;
  std::function<SE3(double)> T_world_lidar;  // motion time, s
  double base_start_s = 0;
  double first_s = 1.0;  // motion time of the first sweep's start
  std::mt19937_64 rng;
  int next = 0;                          // the next sweep's index
  std::vector<Eigen::Vector3d> markers;  // the survey markers' centres in the world frame
  std::vector<Box> building;             // the building's walls, roof, stairs (when there is one)
};
// The street drive of simulate_scans: ground, box buildings, poles and parked cars along a car's
// path.
SweepDrive street_drive(const rig::Rig& rig, const SimConfig& config);
// Sweeps along the trajectories part's path, sweep k starting at its pose k (the same stamps):
// a courtyard of boxes of many sizes (kiosks, walls, buildings, poles) on a ground plane around
// the path, none nearer than 2 m to it, drawn from the part's own random stream
// ("trajectory-scans"); config.markers survey markers (SimConfig), with no box or pole within
// 1.5 m of their posts (the courtyard is otherwise the same as without them); the part's
// building, if it has one (then the markers go along the longest stretch of path outdoors).
SweepDrive trajectory_drive(const rig::Rig& rig, const SimConfig& config,
                            const TrajectoryPart& part);
struct Sweep {
  Time stamp;
  SE3 T_world_lidar;  // at the start of the sweep
  std::vector<LidarPoint> points;
};
// The next sweep of the drive (street_drive: config.scans of them fit the world built; later
// ones leave it).
Sweep next_sweep(SweepDrive& drive);

// What `rigcal simulate --what ground-truth` starts from (a config file then changes it): a
// 60 s walk with the LiDAR's sweeps (64 beams over 90 deg, 1024 columns: a quarter of an
// OS0-128's points, a few hundred MB), 6 survey markers, RTK noise of 1 cm horizontal and 2 cm
// vertical correlated over 5 s, a 15 s outage with 4 s of float fixes on each side, and 2 s of
// single fixes; the outage indoors, in a building with stairs (SimConfig::building).
void ground_truth_defaults(SimConfig& config);

StereoPart simulate_stereo(const rig::Rig& rig, const SimConfig& config);
LidarCameraPart simulate_lidar_camera(const rig::Rig& rig, const SimConfig& config);
ImuPart simulate_imu_part(const rig::Rig& rig, const SimConfig& config);
TrajectoryPart simulate_trajectories(const rig::Rig& rig, const SimConfig& config,
                                     const Trajectory* replay = nullptr);
ScanPart simulate_scans(const rig::Rig& rig, const SimConfig& config);

// The random stream of one part: independent of which other parts run.
std::mt19937_64 part_rng(uint64_t seed, std::string_view part);

}  // namespace rigcal::sim
