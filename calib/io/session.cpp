#include "rigcal/io/session.h"

#include <fmt/format.h>

#include "rigcal/core/error.h"
#include "rigcal/io/files.h"
#include "rigcal/io/yaml.h"

namespace rigcal::io {
namespace fs = std::filesystem;
namespace {

bool has(const fs::path& dir, std::initializer_list<const char*> folders) {
  for (const char* f : folders) {
    if (fs::is_directory(dir / f)) return true;
  }
  return false;
}

// What a purpose needs of a recording.
bool serves(const fs::path& dir, std::string_view purpose) {
  if (purpose == "cameras") return has(dir, {"camera_left", "camera_right"});
  if (purpose == "lidar_camera")
    return has(dir, {"ouster_points"}) && has(dir, {"camera_left", "camera_right"});
  return has(dir, {"imu", "ouster_imu", "gnss"});  // motion
}

const char* default_folder(std::string_view purpose) {
  return purpose == "cameras" ? "stereo" : purpose == "lidar_camera" ? "lidar_camera" : "motion";
}

void read_session_yaml(const fs::path& file, Session& s) {
  const YAML::Node root = load_yaml(read_text_file(file, kMaxYamlBytes), file.string());
  if (root.IsNull()) return;
  if (!root.IsMap()) fail_at(file.string(), yaml_line(root), "", "expected a map of keys to paths");
  const std::pair<const char*, fs::path*> keys[] = {
      {"cameras", &s.cameras}, {"lidar_camera", &s.lidar_camera},
      {"motion", &s.motion},   {"target", &s.target},
      {"rig", &s.rig},         {"odometry", &s.odometry},
      {"gnss", &s.gnss}};
  for (auto it = root.begin(); it != root.end(); ++it) {
    const std::string key = it->first.Scalar();
    fs::path* where = nullptr;
    for (const auto& [name, p] : keys) {
      if (key == name) where = p;
    }
    if (!where) {
      fail_at(file.string(), yaml_line(it->first), key,
              "unknown key; session.yaml knows cameras, lidar_camera, motion, target, rig, "
              "odometry and gnss");
    }
    if (!it->second.IsScalar() || it->second.Scalar().empty())
      fail_at(file.string(), yaml_line(it->second), key, "expected a path");
    if (!where->empty()) fail_at(file.string(), yaml_line(it->first), key, "given twice");
    const fs::path p = fs::path(it->second.Scalar());
    *where = p.is_absolute() ? p : s.root / p;
    if (!fs::exists(*where)) {
      fail_at(file.string(), yaml_line(it->second), key,
              fmt::format("{} does not exist", where->string()));
    }
    s.notes.push_back(fmt::format("{}: {} (session.yaml)", key, where->string()));
  }
}

}  // namespace

bool is_recording(const fs::path& folder) {
  for (const char* f : kRecordingFolders) {
    if (fs::is_directory(folder / f)) return true;
  }
  return false;
}

Session read_session(const fs::path& root) {
  if (!fs::is_directory(root))
    throw Error(fmt::format("--session {}: not a folder", root.string()));
  Session s;
  s.root = root;
  if (fs::exists(root / "session.yaml")) read_session_yaml(root / "session.yaml", s);
  for (const auto& [purpose, p] :
       {std::pair{"cameras", &s.cameras}, std::pair{"lidar_camera", &s.lidar_camera},
        std::pair{"motion", &s.motion}}) {
    if (!p->empty()) continue;
    const fs::path sub = root / default_folder(purpose);
    if (fs::is_directory(sub)) {
      // A default folder is the purpose's recording, or none: never the root in its place.
      if (serves(sub, purpose))
        *p = sub;
      else
        s.notes.push_back(
            fmt::format("{}: lacks the folders {} needs; not used", sub.string(), purpose));
    } else if (serves(root, purpose)) {
      *p = root;
    }
  }
  if (!s.motion.empty() && s.gnss.empty()) {
    for (const char* f : {"poses.tum", "fixes.csv"}) {
      if (fs::exists(s.motion / "gnss" / f)) {
        s.gnss = s.motion / "gnss" / f;
        break;
      }
    }
  }
  if (s.target.empty() && fs::exists(root / "target.yaml")) s.target = root / "target.yaml";
  if (s.rig.empty() && fs::exists(root / "rig.yaml")) s.rig = root / "rig.yaml";
  return s;
}

const fs::path& recording_for(const Session& s, std::string_view purpose) {
  const fs::path& p = purpose == "cameras"        ? s.cameras
                      : purpose == "lidar_camera" ? s.lidar_camera
                                                  : s.motion;
  if (p.empty()) {
    const char* needs = purpose == "cameras"        ? "camera_left/ or camera_right/"
                        : purpose == "lidar_camera" ? "ouster_points/ and a camera folder"
                                                    : "imu/, ouster_imu/ or gnss/";
    throw Error(fmt::format(
        "session {}: no recording for {}: expected {}/ holding {}, the session folder itself "
        "holding them, or session.yaml naming one ({}: FOLDER); see doc/session.md",
        s.root.string(), purpose, default_folder(purpose), needs, purpose));
  }
  return p;
}

}  // namespace rigcal::io
