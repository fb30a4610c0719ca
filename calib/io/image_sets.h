#pragma once
// Sets of camera images, frame by frame (doc/cameras.md): from file globs paired by the frame
// number in the file names, or from a session folder (camera_left/, camera_right/) paired by
// timestamp. A frame may lack an image of some camera ("").
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rigcal/core/time.h"

namespace rigcal::io {

struct ImageSet {
  std::vector<std::string> names;               // cameras
  std::vector<std::vector<std::string>> files;  // per camera, per frame ("" = none)
  std::vector<std::string> notes;
};

// Sorted paths matching a shell glob.
std::vector<std::string> glob_files(const std::string& pattern);
// The last run of digits in the file name's stem.
std::optional<long> frame_number(const std::string& path);
// Pairs by frame number; throws rigcal::Error for a name without a number or a number used twice
// in one camera.
ImageSet pair_by_frame_number(
    const std::vector<std::pair<std::string, std::vector<std::string>>>& cameras);
// A session folder in the vbr-devkit layout: data/*<extension> (sorted) and timestamps.txt, one
// stamp a line (ISO-8601 or seconds) for each file, strictly increasing. Throws rigcal::Error
// naming the line for a stamp not read or not after the previous one, and when the counts differ.
struct StampedFolder {
  std::vector<std::string> files;
  std::vector<Time> stamps;
};
StampedFolder read_stamped_folder(const std::filesystem::path& folder,
                                  const std::string& extension);
// The same for another layout: `files` (a subfolder) and `stamps` (a file) of `folder`. A KITTI
// odometry sequence is read with ("velodyne", "times.txt"): seconds since the sequence's start.
StampedFolder read_stamped_folder(const std::filesystem::path& folder, const std::string& extension,
                                  const std::string& files, const std::string& stamps);
// For each stamp of `a`, the nearest stamp of `b` within `tolerance`, each of `b` taken once
// (first come); nullopt where none.
std::vector<std::optional<size_t>> pair_by_stamp(const std::vector<Time>& a,
                                                 const std::vector<Time>& b, Time tolerance);
// camera_left/ (cam_l) and camera_right/ (cam_r) of a session, paired by stamp within 5 ms.
ImageSet read_session_images(const std::filesystem::path& session);

}  // namespace rigcal::io
