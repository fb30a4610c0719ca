#include "rigcal/io/session.h"

#include <fmt/format.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <map>
#include <mutex>

#include "rigcal/core/error.h"
#include "rigcal/io/bag.h"
#include "rigcal/io/convert.h"
#include "rigcal/io/files.h"
#include "rigcal/io/ouster_pcap.h"
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

// The bags of a folder given as a session (sorted; none when it is a recording or has a
// session.yaml), or the bag or capture file given.
std::vector<fs::path> recorded_files(const fs::path& root) try {
  std::vector<fs::path> files;
  if (fs::is_regular_file(root)) {
    if (is_ros1_bag(root) || is_pcap_capture(root)) files.push_back(root);
    return files;
  }
  if (!fs::is_directory(root) || is_recording(root) || fs::exists(root / "session.yaml"))
    return files;
  std::error_code ec;  // an unreadable folder or entry holds no bags
  for (fs::directory_iterator it(root, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code kind;
    if (it->path().extension() == ".bag" && it->is_regular_file(kind)) files.push_back(it->path());
  }
  std::sort(files.begin(), files.end());
  return files;
} catch (const fs::filesystem_error&) {  // a path the file system refuses: not bags; said later
  return {};
}

// The temporary recordings of this process, by what they were converted from; removed when the
// process ends (normally or through exit()).
class ConvertedSessions {
 public:
  ~ConvertedSessions() {
    for (const auto& [from, scratch] : scratch_) {
      std::error_code ec;
      fs::remove_all(scratch, ec);
    }
  }
  fs::path recording_of(const std::vector<fs::path>& files, const SessionProgress& progress) {
    const std::lock_guard<std::mutex> lock(mutex_);
    std::string key;
    for (const fs::path& f : files) key += fs::weakly_canonical(f).string() + '\n';
    if (const auto it = scratch_.find(key); it != scratch_.end()) return it->second / "recording";
    std::string pattern = (fs::temp_directory_path() / "rigcal-session-XXXXXX").string();
    if (!mkdtemp(pattern.data())) {
      throw Error(
          fmt::format("cannot create a temporary folder for the converted session in {} "
                      "(set TMPDIR to a folder with room for it)",
                      fs::temp_directory_path().string()));
    }
    const fs::path scratch = pattern;
    ConvertOptions o;
    o.bags = files;
    o.out = scratch / "recording";
    if (is_pcap_capture(files.front())) {
      o.ouster_metadata = fs::path(files.front()).replace_extension(".json");
      if (!fs::is_regular_file(o.ouster_metadata)) {
        std::error_code ec;
        fs::remove_all(scratch, ec);
        throw Error(fmt::format(
            "--session {}: an Ouster capture needs its metadata JSON beside it ({}); or convert "
            "it first: rigcal convert {} --metadata M.json --out RECORDING",
            files.front().string(), o.ouster_metadata.string(), files.front().string()));
      }
    }
    o.progress = progress;
    try {
      convert_recording(o);
    } catch (...) {
      std::error_code ec;
      fs::remove_all(scratch, ec);
      throw;
    }
    scratch_.emplace(key, scratch);
    return o.out;
  }

 private:
  std::mutex mutex_;
  std::map<std::string, fs::path> scratch_;
};

ConvertedSessions& converted_sessions() {
  static ConvertedSessions sessions;
  return sessions;
}

std::string conversion_note(const ConvertedInput& c) {
  return fmt::format("{} ({} file{}) converted into the temporary recording {} (removed at exit)",
                     c.given.string(), c.files.size(), c.files.size() == 1 ? "" : "s",
                     c.recording.string());
}

// target.yaml and rig.yaml in `root`, where session.yaml named none.
void find_target_and_rig(const fs::path& root, Session& s) {
  if (s.target.empty() && fs::exists(root / "target.yaml")) s.target = root / "target.yaml";
  if (s.rig.empty() && fs::exists(root / "rig.yaml")) s.rig = root / "rig.yaml";
}

void read_session_yaml(const fs::path& file, Session& s, const SessionProgress& progress) {
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
    std::error_code unreadable;  // a name too long, a folder not searchable: said with the line
    if (!fs::exists(*where, unreadable)) {
      fail_at(file.string(), yaml_line(it->second), key,
              unreadable ? fmt::format("{}: {}", where->string(), unreadable.message())
                         : fmt::format("{} does not exist", where->string()));
    }
    s.notes.push_back(fmt::format("{}: {} (session.yaml)", key, where->string()));
    const bool recording = key == "cameras" || key == "lidar_camera" || key == "motion";
    if (const std::vector<fs::path> files =
            recording ? recorded_files(*where) : std::vector<fs::path>{};
        !files.empty()) {
      const fs::path converted = converted_sessions().recording_of(files, progress);
      s.converted.push_back({where->lexically_normal(), files, converted});
      s.notes.push_back(fmt::format("{}: {}", key, conversion_note(s.converted.back())));
      *where = converted;
    }
  }
}

Session read_session_folder(const fs::path& root, const SessionProgress& progress);

}  // namespace

bool is_recording(const fs::path& folder) {
  for (const char* f : kRecordingFolders) {
    if (fs::is_directory(folder / f)) return true;
  }
  return false;
}

Session read_session(const fs::path& root, const SessionProgress& progress) {
  const std::vector<fs::path> files = recorded_files(root);
  if (files.empty()) return read_session_folder(root, progress);
  const fs::path recording = converted_sessions().recording_of(files, progress);
  Session s = read_session_folder(recording, progress);
  s.root = root;
  s.converted = {{root, files, recording}};
  s.notes.insert(s.notes.begin(), conversion_note(s.converted.front()));
  if (fs::is_directory(root)) find_target_and_rig(root, s);  // a folder of bags' own
  return s;
}

fs::path source_path(const Session& s, const fs::path& path) {
  for (const ConvertedInput& c : s.converted) {
    const fs::path inside = path.lexically_relative(c.recording);
    if (inside.empty() || *inside.begin() == "..") continue;
    return inside == "." ? c.given : c.given / inside;
  }
  return path;
}

namespace {
Session read_session_folder(const fs::path& root, const SessionProgress& progress) {
  if (!fs::is_directory(root)) {
    throw Error(fmt::format(
        "--session {}: not a folder{}", root.string(),
        fs::is_regular_file(root) ? " (nor a ROS1 bag or an Ouster pcap/pcapng capture)" : ""));
  }
  Session s;
  s.root = root;
  if (fs::exists(root / "session.yaml")) read_session_yaml(root / "session.yaml", s, progress);
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
  find_target_and_rig(root, s);
  return s;
}
}  // namespace

const fs::path& recording_for(const Session& s, std::string_view purpose) {
  const fs::path& p = purpose == "cameras"        ? s.cameras
                      : purpose == "lidar_camera" ? s.lidar_camera
                                                  : s.motion;
  if (p.empty()) {
    const char* needs = purpose == "cameras"        ? "camera_left/ or camera_right/"
                        : purpose == "lidar_camera" ? "ouster_points/ and a camera folder"
                                                    : "imu/, ouster_imu/ or gnss/";
    if (!s.converted.empty() && s.converted.front().given == s.root) {
      throw Error(fmt::format(
          "session {}: no recording for {}: no topic of it converts into {} (the folders are "
          "vbr-devkit's names of the topics; for other names convert it first, rigcal convert "
          "... --topic TOPIC=FOLDER, and give the recording); see doc/session.md",
          s.root.string(), purpose, needs));
    }
    throw Error(fmt::format(
        "session {}: no recording for {}: expected {}/ holding {}, the session folder itself "
        "holding them, or session.yaml naming one ({}: FOLDER); see doc/session.md",
        s.root.string(), purpose, default_folder(purpose), needs, purpose));
  }
  return p;
}

}  // namespace rigcal::io
