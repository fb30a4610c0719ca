#pragma once
// The session layout (doc/session.md), one reader for every step and command.
//
// A recording is a folder in the layout vbr-devkit's `convert kitti` writes: camera_left/,
// camera_right/, ouster_points/, imu/, ouster_imu/ (and rigcal's gnss/) at its root, each with
// timestamps.txt and data/. A calibration session is a folder of recordings, one per purpose:
// the board for the cameras (stereo/), the board for LiDAR-camera (lidar_camera/), a motion
// recording for the IMU clock offsets and hand-eye (motion/), named by an optional session.yaml,
// or a single recording serving every step. `--session` means this for every command.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace rigcal::io {

struct Session {
  std::filesystem::path root;
  // The recording serving each purpose ("" where the session has none).
  std::filesystem::path cameras, lidar_camera, motion;
  // Named by session.yaml or found by default ("" where neither): the target YAML, the prior rig,
  // the motion's LiDAR odometry (T_odom_lidar) and GNSS/INS poses or fixes.
  std::filesystem::path target, rig, odometry, gnss;
  std::vector<std::string> notes;  // how each was found
};

// The topic folders a recording may hold.
inline constexpr const char* kRecordingFolders[] = {"camera_left", "camera_right", "ouster_points",
                                                    "imu",         "ouster_imu",   "gnss"};
// A folder holding at least one of them.
bool is_recording(const std::filesystem::path& folder);

// Reads session.yaml where present (keys: cameras, lidar_camera, motion, target, rig, odometry,
// gnss; paths relative to the session folder; an unknown key is an error naming it and its line),
// then fills what it leaves open by default: stereo/, lidar_camera/ and motion/ where they are
// recordings, else the root where it is a recording with the folders the purpose needs; for the
// motion, gnss/poses.tum or gnss/fixes.csv inside it, and target.yaml or rig.yaml at the root.
// Throws rigcal::Error when `root` is not a folder or session.yaml is malformed or names a path
// that does not exist.
Session read_session(const std::filesystem::path& root);

// The recording of a purpose ("cameras", "lidar_camera", "motion"); throws rigcal::Error naming
// the session and what it lacks when there is none.
const std::filesystem::path& recording_for(const Session& session, std::string_view purpose);

}  // namespace rigcal::io
