#pragma once
// Publishing a calibration with recorded sequences (doc/session.md): vbr_calib.yaml, and the
// chosen exports, into each sequence folder of the VBR layout (<place>/<seq>/vbr_calib.yaml),
// each carrying the calibration's SHA-256 in its first line. A sequence that holds a different
// calibration is not replaced unless forced; one holding this calibration already is left as it
// is. All files of all sequences are written at once, or none.
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
  std::string state;  // "written", "replaced" (forced), "unchanged" (this calibration already)
};

struct PublishResult {
  std::string sha256;                // of the calibration file
  std::vector<std::string> dropped;  // what the VBR format cannot hold, said once
  std::vector<Published> sequences;
};

// The first line of every published file: "# rigcal calibration sha256: HEX".
std::string published_header(const std::string& sha256);
// The hash a published file names in its first line, or "" when it names none.
std::string published_hash(const std::filesystem::path& file);

// Throws rigcal::Error for an invalid calibration, a sequence that is not a folder, or sequences
// holding another calibration (each listed, with its hash) when not forced: nothing is written.
PublishResult publish(const std::filesystem::path& calibration,
                      const std::vector<std::filesystem::path>& sequences,
                      const PublishOptions& options);

}  // namespace rigcal::session
