#pragma once
// Publishing a calibration with recorded sequences (doc/session.md): vbr_calib.yaml, and the
// chosen exports, into each sequence folder of the VBR layout (<place>/<seq>/vbr_calib.yaml),
// each carrying the calibration's SHA-256 in its first line (OpenCV's: its second). File by file:
// one holding this calibration is left as it is; one holding another, or a file rigcal did not
// publish, is not replaced unless forced. All files of all sequences are written at once, or none.
// Exports of formats not asked for this time are left where an earlier run wrote them.
#include <filesystem>
#include <string>
#include <vector>

#include "rigcal/rig/export.h"

namespace rigcal::session {

struct PublishOptions {
  std::vector<rig::ExportFormat> formats = {rig::ExportFormat::vbr};  // vbr is always written
  bool force = false;
};

struct Published {
  std::filesystem::path sequence;
  std::vector<std::filesystem::path> files;  // written
  // "written", "replaced" (forced over another calibration), "unchanged" (every file holds this
  // calibration already)
  std::string state;
};

struct PublishResult {
  std::string sha256;                // of the calibration file
  std::vector<std::string> dropped;  // what the VBR format cannot hold, said once
  std::vector<Published> sequences;
};

// The first line of every published file (OpenCV's: the second): "# rigcal calibration sha256:
// HEX".
std::string published_header(const std::string& sha256);
// The hash a published file names in its first line, or "" when it names none.
std::string published_hash(const std::filesystem::path& file);

// Throws rigcal::Error for an invalid calibration, a sequence that is not a folder, or sequences
// holding another calibration (each listed, with its hash) when not forced: nothing is written.
PublishResult publish(const std::filesystem::path& calibration,
                      const std::vector<std::filesystem::path>& sequences,
                      const PublishOptions& options);

}  // namespace rigcal::session
