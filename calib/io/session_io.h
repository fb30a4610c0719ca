#pragma once
// Writes simulated sessions in the session layout (doc/simulator.md, ../shared/DESIGN.md):
//   stereo/camera_left|camera_right/{timestamps.txt, data/%010d.png, corners_truth.csv}
//   lidar_camera/<camera>/..., lidar_camera/ouster_points/{timestamps.txt, data/%010d.bin,
//   fields/%010d.bin} imu/{timestamps.txt, data/imu.txt}, ouster_imu/{...}
//   trajectories/{truth_lidar.tum, lidar_odometry.tum, gnss_ins.tum}, ouster_points/{...} (sweeps
//   along the trajectory, when asked)
//   scans/ouster_points/{...}, scans/truth_lidar.tum
//   truth.yaml (the true rig), truth.json (per-item truth)
// Paths are relative to one output folder; callers write into a temporary folder and rename it.
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>

#include "rigcal/sim/session.h"

namespace rigcal::io {

void write_stereo(const std::filesystem::path& dir, const sim::StereoPart& part,
                  nlohmann::json& truth);
void write_lidar_camera(const std::filesystem::path& dir, const sim::LidarCameraPart& part,
                        nlohmann::json& truth);
void write_imu(const std::filesystem::path& dir, const sim::ImuPart& part, nlohmann::json& truth);
void write_trajectories(const std::filesystem::path& dir, const sim::TrajectoryPart& part,
                        nlohmann::json& truth);
void write_scans(const std::filesystem::path& dir, const sim::ScanPart& part,
                 nlohmann::json& truth);
// `count` sweeps of the drive (sim::trajectory_drive) as the motion recording's ouster_points/,
// made and written one at a time (a sweep's memory, whatever the length); `progress` is told
// after each.
void write_trajectory_scans(const std::filesystem::path& dir, sim::SweepDrive& drive, size_t count,
                            nlohmann::json& truth,
                            const std::function<void(size_t done, size_t total)>& progress = {});
// The drive's survey markers (sim::SimConfig::markers): trajectories/markers.csv as a total
// station gives them (`id,x,y,z`, m, in the world frame: the station's own, not the ENU frame of
// the GNSS) and, in truth.json, their centres in both frames (T_enu_world of the part).
void write_markers(const std::filesystem::path& dir, const sim::SweepDrive& drive,
                   const SE3& T_enu_world, nlohmann::json& truth);

// The parts of a simulated session ("stereo", "lidar-camera", "imu", "trajectories",
// "ground-truth", "scans") computed and written into `dir` in the session layout, with
// truth.yaml, truth.json, target.yaml and session.yaml; `say` is told what is being done (a
// part's name, its sweeps, its seconds).
void write_simulated_session(const std::filesystem::path& dir, const rig::Rig& rig,
                             const sim::SimConfig& config, const std::vector<std::string>& parts,
                             const std::function<void(const std::string&)>& say);

// session.yaml of a simulated session (doc/session.md) with the parts written ("stereo",
// "lidar-camera", "imu", "trajectories", "scans"): the recordings of each step, target.yaml, and
// the motion's GNSS/INS trajectory, and its odometry unless the motion recording has sweeps
// (`trajectory_scans`: rigcal's own odometry runs on them); the truth is not named as a prior rig.
std::string simulated_session_yaml(const std::vector<std::string>& parts,
                                   bool trajectory_scans = false);

// The vbr-devkit IMU layout: timestamps.txt (ISO-8601 a line) and data/imu.txt (a header line,
// then 37 comma-separated columns: acc xyz, gyro xyz, orientation wxyz, three 3x3 covariances).
std::string imu_txt(const std::vector<sim::ImuSample>& samples);
std::string timestamps_txt(const std::vector<Time>& stamps);
// A scan as KITTI-style float32 x y z intensity, and its fields (uint32 t_ns, uint16 ring, uint16
// 0).
std::string points_bin(const std::vector<sim::LidarPoint>& points);
std::string fields_bin(const std::vector<sim::LidarPoint>& points);

}  // namespace rigcal::io
