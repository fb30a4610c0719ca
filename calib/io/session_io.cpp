#include "rigcal/io/session_io.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <opencv2/imgcodecs.hpp>

#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/core/version.h"
#include "rigcal/io/files.h"
#include "rigcal/io/gnss_fixes.h"
#include "rigcal/io/target_yaml.h"
#include "rigcal/io/trajectory_io.h"
#include "rigcal/report/json.h"
#include "rigcal/report/png.h"
#include "rigcal/rig/rig_yaml.h"

namespace rigcal::io {
namespace fs = std::filesystem;
namespace {

std::string frame_name(size_t k, std::string_view ext) { return fmt::format("{:010d}.{}", k, ext); }

std::string corners_csv(const std::vector<std::vector<Eigen::Vector2d>>& corners) {
  std::string out =
      "# frame, point, u [px], v [px]: true projections of the target's object points\n";
  for (size_t k = 0; k < corners.size(); ++k) {
    for (size_t i = 0; i < corners[k].size(); ++i) {
      out += fmt::format("{},{},{},{}\n", k, i, format_double(corners[k][i].x()),
                         format_double(corners[k][i].y()));
    }
  }
  return out;
}

void write_camera(const fs::path& dir, const std::vector<Time>& stamps,
                  const std::vector<cv::Mat>& images,
                  const std::vector<std::vector<Eigen::Vector2d>>& corners) {
  std::vector<OutputFile> files{{dir / "timestamps.txt", timestamps_txt(stamps)},
                                {dir / "corners_truth.csv", corners_csv(corners)}};
  for (size_t k = 0; k < images.size(); ++k)
    files.push_back({dir / "data" / frame_name(k, "png"), report::encode_png(images[k])});
  write_files_atomic(files);
}

void write_points(const fs::path& dir, const std::vector<Time>& stamps,
                  const std::vector<std::vector<sim::LidarPoint>>& scans) {
  std::vector<OutputFile> files{{dir / "timestamps.txt", timestamps_txt(stamps)}};
  for (size_t k = 0; k < scans.size(); ++k) {
    files.push_back({dir / "data" / frame_name(k, "bin"), points_bin(scans[k])});
    files.push_back({dir / "fields" / frame_name(k, "bin"), fields_bin(scans[k])});
  }
  write_files_atomic(files);
}

}  // namespace

void write_simulated_session(const fs::path& dir, const rig::Rig& rig, const sim::SimConfig& config,
                             const std::vector<std::string>& parts,
                             const std::function<void(const std::string&)>& say) {
  nlohmann::json truth;
  truth["tool_version"] = version_string();
  truth["seed"] = config.seed;
  truth["target"] = {
      {"name", config.target.name},
      {"type",
       config.target.type == camera::TargetType::checkerboard ? "checkerboard" : "aprilgrid"},
      {"cols", config.target.cols},
      {"rows", config.target.rows},
      {"board_warp_m", {config.board_warp_m.x(), config.board_warp_m.y()}}};
  Trajectory replay;
  if (!config.replay_tum.empty()) replay = io::read_trajectory(config.replay_tum).trajectory;
  for (const std::string& part : parts) {
    const auto t0 = std::chrono::steady_clock::now();
    say(fmt::format("simulating {} ...", part));
    if (part == "stereo") io::write_stereo(dir, sim::simulate_stereo(rig, config), truth);
    if (part == "lidar-camera")
      io::write_lidar_camera(dir, sim::simulate_lidar_camera(rig, config), truth);
    if (part == "imu") io::write_imu(dir, sim::simulate_imu_part(rig, config), truth);
    if (part == "trajectories" || part == "ground-truth") {
      const sim::TrajectoryPart t =
          sim::simulate_trajectories(rig, config, config.replay_tum.empty() ? nullptr : &replay);
      io::write_trajectories(dir, t, truth);
      if (config.trajectory_scans) {
        sim::SweepDrive drive = sim::trajectory_drive(rig, config, t);
        io::write_trajectory_scans(dir, drive, t.truth_base.size(), truth,
                                   [&](size_t done, size_t total) {
                                     if (done % 100 == 0 || done == total)
                                       say(fmt::format(" {}/{} sweeps", done, total));
                                   });
        if (!drive.markers.empty()) io::write_markers(dir, drive, t.T_enu_world, truth);
      }
    }
    if (part == "scans") io::write_scans(dir, sim::simulate_scans(rig, config), truth);
    say(fmt::format(" {:.1f} s\n",
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()));
  }
  io::write_files_atomic(
      {{dir / "truth.yaml", rig::rig_to_yaml(rig)},
       {dir / "truth.json", report::json_text(truth)},
       {dir / "target.yaml", io::target_to_yaml(config.target)},
       {dir / "session.yaml", io::simulated_session_yaml(parts, config.trajectory_scans)}});
}

std::string simulated_session_yaml(const std::vector<std::string>& parts, bool trajectory_scans) {
  auto has = [&](std::string_view p) {
    return std::find(parts.begin(), parts.end(), p) != parts.end();
  };
  std::string out =
      "# Written by rigcal simulate: which recording serves which step (doc/session.md).\n"
      "target: target.yaml\n";
  if (has("stereo")) out += "cameras: stereo\n";
  if (has("lidar-camera")) out += "lidar_camera: lidar_camera\n";
  const bool trajectories = has("trajectories") || has("ground-truth");
  trajectory_scans = trajectory_scans && trajectories;
  if (has("imu") || trajectory_scans) out += "motion: .\n";
  if (trajectories) {
    out += trajectory_scans
               ? "# No odometry named: rigcal's own runs on the motion's sweeps (ouster_points/).\n"
               : "# A simulated LiDAR odometry (no sweeps were simulated along the motion).\n"
                 "odometry: trajectories/lidar_odometry.tum\n";
    out += "gnss: trajectories/gnss_ins.tum\n";
  }
  return out;
}

std::string timestamps_txt(const std::vector<Time>& stamps) {
  std::string out;
  for (const Time& t : stamps) out += to_iso8601(t) + "\n";
  return out;
}

std::string imu_txt(const std::vector<sim::ImuSample>& samples) {
  std::string out =
      "linear_acceleration.x,linear_acceleration.y,linear_acceleration.z,angular_velocity.x,"
      "angular_velocity.y,angular_velocity.z,orientation.w,orientation.x,orientation.y,"
      "orientation.z";
  for (const char* c : {"orientation_covariance", "angular_velocity_covariance",
                        "linear_acceleration_covariance"}) {
    for (int i = 0; i < 9; ++i) out += fmt::format(",{}[{}]", c, i);
  }
  out += "\n";
  for (const sim::ImuSample& s : samples) {
    out += fmt::format("{},{},{},{},{},{},1.0,0.0,0.0,0.0,-1.0", format_double(s.accel.x()),
                       format_double(s.accel.y()), format_double(s.accel.z()),
                       format_double(s.gyro.x()), format_double(s.gyro.y()),
                       format_double(s.gyro.z()));
    for (int i = 0; i < 26; ++i) out += ",0.0";  // 27 covariance entries; the first is -1
    out += "\n";
  }
  return out;
}

std::string points_bin(const std::vector<sim::LidarPoint>& points) {
  std::string out(points.size() * 16, '\0');
  for (size_t i = 0; i < points.size(); ++i) {
    const float v[4] = {points[i].p.x(), points[i].p.y(), points[i].p.z(), points[i].intensity};
    std::memcpy(out.data() + 16 * i, v, 16);
  }
  return out;
}

std::string fields_bin(const std::vector<sim::LidarPoint>& points) {
  std::string out(points.size() * 8, '\0');
  for (size_t i = 0; i < points.size(); ++i) {
    const uint32_t t = points[i].t_ns;
    const uint16_t ring[2] = {points[i].ring, 0};
    std::memcpy(out.data() + 8 * i, &t, 4);
    std::memcpy(out.data() + 8 * i + 4, ring, 4);
  }
  return out;
}

void write_stereo(const fs::path& dir, const sim::StereoPart& part, nlohmann::json& truth) {
  write_camera(dir / "stereo" / "camera_left", part.stamps, part.left, part.corners_left);
  write_camera(dir / "stereo" / "camera_right", part.stamps, part.right, part.corners_right);
  nlohmann::json& j = truth["stereo"];
  j["cameras"] = {part.left_name, part.right_name};
  j["T_left_board"] = nlohmann::json::array();
  for (const SE3& T : part.T_left_board) j["T_left_board"].push_back(report::pose_json(T));
}

void write_lidar_camera(const fs::path& dir, const sim::LidarCameraPart& part,
                        nlohmann::json& truth) {
  const std::string cam_dir = part.camera_name == "cam_l" ? "camera_left" : "camera_right";
  write_camera(dir / "lidar_camera" / cam_dir, part.stamps, part.images, part.corners);
  write_points(dir / "lidar_camera" / "ouster_points", part.stamps, part.scans);
  nlohmann::json& j = truth["lidar_camera"];
  j["camera"] = part.camera_name;
  j["T_lidar_board"] = nlohmann::json::array();
  j["board_points"] = nlohmann::json::array();
  for (size_t k = 0; k < part.T_lidar_board.size(); ++k) {
    j["T_lidar_board"].push_back(report::pose_json(part.T_lidar_board[k]));
    size_t on_board = 0;
    for (const sim::LidarPoint& p : part.scans[k]) on_board += p.object == 1;
    j["board_points"].push_back(on_board);
  }
}

void write_imu(const fs::path& dir, const sim::ImuPart& part, nlohmann::json& truth) {
  std::vector<Time> a, b;
  for (const sim::ImuSample& s : part.imu) a.push_back(s.stamp);
  for (const sim::ImuSample& s : part.os_imu) b.push_back(s.stamp);
  write_files_atomic({{dir / "imu" / "timestamps.txt", timestamps_txt(a)},
                      {dir / "imu" / "data" / "imu.txt", imu_txt(part.imu)},
                      {dir / "ouster_imu" / "timestamps.txt", timestamps_txt(b)},
                      {dir / "ouster_imu" / "data" / "imu.txt", imu_txt(part.os_imu)}});
  nlohmann::json& j = truth["imu"];
  j[part.imu_name] = {{"folder", "imu"},
                      {"time_offset_s", part.imu_offset_s},
                      {"drift_ppm", part.imu_drift_ppm},
                      {"samples", part.imu.size()}};
  j[part.os_imu_name] = {{"folder", "ouster_imu"},
                         {"time_offset_s", part.os_imu_offset_s},
                         {"drift_ppm", part.os_imu_drift_ppm},
                         {"samples", part.os_imu.size()}};
  j["clock"] = "t_base = t_stamp + time_offset + drift_ppm * 1e-6 * (t_stamp - first stamp)";
}

void write_trajectories(const fs::path& dir, const sim::TrajectoryPart& part,
                        nlohmann::json& truth) {
  std::vector<FixType> fix_type;
  for (const sim::FixState s : part.gnss_states) {
    fix_type.push_back(s == sim::FixState::rtk_fixed   ? FixType::rtk_fixed
                       : s == sim::FixState::rtk_float ? FixType::rtk_float
                                                       : FixType::single);
  }
  const sim::GeodeticPoint& o = part.enu_origin;
  write_files_atomic(
      {{dir / "trajectories" / "truth_lidar.tum", trajectory_to_tum(part.truth_base)},
       {dir / "trajectories" / "lidar_odometry.tum", trajectory_to_tum(part.odometry)},
       {dir / "trajectories" / "gnss_ins.tum", trajectory_to_tum(part.gnss)},
       {dir / "trajectories" / "gnss_fixes.csv",
        gnss_fixes_csv(part.gnss, part.gnss_std_enu_m, fix_type,
                       {o.latitude_deg, o.longitude_deg, o.height_m})}});
  nlohmann::json& j = truth["trajectories"];
  j["gnss_sensor"] = part.gnss_name;
  j["T_enu_world"] = report::pose_json(part.T_enu_world);
  j["enu_origin"] = {{"latitude_deg", o.latitude_deg},
                     {"longitude_deg", o.longitude_deg},
                     {"height_m", o.height_m}};
  j["gnss_outlier_indices"] = part.gnss_outliers;
  j["files"] = {
      {"truth_lidar.tum", "T_world_lidar, the truth, LiDAR rate"},
      {"lidar_odometry.tum", "T_odom_lidar, drifting odometry"},
      {"gnss_ins.tum", "T_enu_gnss on the GNSS clock, with noise, outages, outliers"},
      {"gnss_fixes.csv",
       "gnss_ins.tum's positions as fixes (latitude, longitude, height at enu_origin's ENU "
       "frame), with their states' sigmas and fix types"}};
  if (part.building) {
    const sim::Building& b = *part.building;
    j["building"] = {
        {"indoors_s", {b.t_in, b.t_out}},
        {"path_indoors_m", b.length_m},
        {"storey_m", b.storey_m()},
        {"steps_a_flight", b.steps},
        {"rise_m", b.rise_m},
        {"tread_m", b.tread_m},
        {"flights_start_m", {b.up_from_s, b.down_from_s}},
        {"what",
         "indoors over the first outage: in through a door at indoors_s[0], up a flight and down "
         "another (starting flights_start_m along the path indoors), out through a door at "
         "indoors_s[1]"}};
  }
}

void write_trajectory_scans(const fs::path& dir, sim::SweepDrive& drive, size_t count,
                            nlohmann::json& truth,
                            const std::function<void(size_t, size_t)>& progress) {
  const fs::path out = dir / "ouster_points";
  std::vector<Time> stamps;
  for (size_t k = 0; k < count; ++k) {
    const sim::Sweep s = sim::next_sweep(drive);
    stamps.push_back(s.stamp);
    write_files_atomic({{out / "data" / frame_name(k, "bin"), points_bin(s.points)},
                        {out / "fields" / frame_name(k, "bin"), fields_bin(s.points)}});
    if (progress) progress(k + 1, count);
  }
  write_file_atomic(out / "timestamps.txt", timestamps_txt(stamps));
  truth["trajectories"]["scans"] = {
      {"folder", "ouster_points"},
      {"count", count},
      {"poses", "trajectories/truth_lidar.tum: sweep k starts at pose k"}};
}

void write_markers(const fs::path& dir, const sim::SweepDrive& drive, const SE3& T_enu_world,
                   nlohmann::json& truth) {
  std::string csv =
      "# Survey markers (rigcal simulate): id, then the centre of the retro-reflective square in\n"
      "# the survey's frame (the simulated world's, m); ground truth's --markers reads this file.\n"
      "id,x,y,z\n";
  nlohmann::json markers = nlohmann::json::array();
  for (size_t i = 0; i < drive.markers.size(); ++i) {
    const Eigen::Vector3d& p = drive.markers[i];
    const std::string id = fmt::format("M{}", i + 1);
    csv += fmt::format("{},{:.4f},{:.4f},{:.4f}\n", id, p.x(), p.y(), p.z());
    markers.push_back({{"id", id},
                       {"centre_world_m", report::vector_json(p)},
                       {"centre_enu_m", report::vector_json(T_enu_world * p)}});
  }
  write_file_atomic(dir / "trajectories" / "markers.csv", csv);
  truth["trajectories"]["markers"] = std::move(markers);
}

void write_scans(const fs::path& dir, const sim::ScanPart& part, nlohmann::json& truth) {
  write_points(dir / "scans" / "ouster_points", part.stamps, part.scans);
  Trajectory t;
  t.stamps = part.stamps;
  t.T_world_body = part.T_world_lidar;
  write_file_atomic(dir / "scans" / "truth_lidar.tum", trajectory_to_tum(t));
  truth["scans"] = {{"count", part.scans.size()},
                    {"poses", "scans/truth_lidar.tum: T_world_lidar at each sweep's start"}};
}

}  // namespace rigcal::io
