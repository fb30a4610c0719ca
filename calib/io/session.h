#pragma once
// The session layout (doc/session.md), one reader for every step and command.
//
// A recording is a folder in the layout vbr-devkit's `convert kitti` writes: camera_left/,
// camera_right/, ouster_points/, imu/, ouster_imu/ (and rigcal's gnss/) at its root, each with
// timestamps.txt and data/. A calibration session is a folder of recordings, one per purpose:
// the board for the cameras (stereo/), the board for LiDAR-camera (lidar_camera/), a motion
// recording for the IMU clock offsets and hand-eye (motion/), named by an optional session.yaml,
// or a single recording serving every step. `--session` means this for every command.
//
// `--session` may also name what the rig recorded, read without a separate `rigcal convert`:
// a ROS1 bag, a folder of bags (one recording's chunks), or an Ouster capture (CAPTURE.pcap with
// its metadata CAPTURE.json beside it). It is converted once a process, streaming (memory does
// not grow with the bag's length; doc/session.md, "From bags"), into a temporary recording under
// $TMPDIR, which serves every purpose its topics serve and is removed when the process ends.
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace rigcal::io {

// A bag, a folder of bags or a capture read as a recording: what was given, the files converted
// (bags sorted, or the capture) and the temporary recording they became.
struct ConvertedInput {
  std::filesystem::path given;
  std::vector<std::filesystem::path> files;
  std::filesystem::path recording;
};

struct Session {
  std::filesystem::path root;
  // The recording serving each purpose ("" where the session has none).
  std::filesystem::path cameras, lidar_camera, motion;
  // Named by session.yaml or found by default ("" where neither): the target YAML, the prior rig,
  // the motion's LiDAR odometry (T_odom_lidar) and GNSS/INS poses or fixes.
  std::filesystem::path target, rig, odometry, gnss;
  std::vector<std::string> notes;  // how each was found
  // The bags and captures converted for it: the session itself given as one (`root` is then what
  // was given), or session.yaml naming one for a purpose (cameras: stereo.bag).
  std::vector<ConvertedInput> converted;
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
// A bag, a folder of bags (not a recording, no session.yaml) or a capture is converted first (see
// above; the same input is converted once a process), with `progress` told of the messages done;
// the target.yaml and rig.yaml of a folder of bags are its defaults. session.yaml's cameras,
// lidar_camera and motion may name one too. Throws rigcal::Error as
// `rigcal convert` does on a damaged bag or capture, and for a capture without CAPTURE.json.
using SessionProgress = std::function<void(std::string_view what, size_t done, size_t total)>;
Session read_session(const std::filesystem::path& root, const SessionProgress& progress = {});

// What a user knows a path of the session as: inside a converted temporary recording, the given
// bag, folder or capture followed by the path inside the recording
// ("campus.bag/camera_left"); any other path as it is.
std::filesystem::path source_path(const Session& session, const std::filesystem::path& path);

// The recording of a purpose ("cameras", "lidar_camera", "motion"); throws rigcal::Error naming
// the session and what it lacks when there is none.
const std::filesystem::path& recording_for(const Session& session, std::string_view purpose);

}  // namespace rigcal::io
