#include "rigcal/session/publish.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <fstream>
#include <memory>
#include <set>

#include "rigcal/core/error.h"
#include "rigcal/core/sha256.h"
#include "rigcal/io/files.h"
#include "rigcal/rig/rig_yaml.h"

namespace rigcal::session {
namespace fs = std::filesystem;
namespace {

constexpr std::string_view kHeader = "# rigcal calibration sha256: ";

// A file's name in the sequence folder for each format (folders for ros and mrcal).
fs::path export_name(rig::ExportFormat f) {
  switch (f) {
    case rig::ExportFormat::vbr:
      return "vbr_calib.yaml";
    case rig::ExportFormat::rigcal:
      return "rigcal_calib.yaml";
    case rig::ExportFormat::kalibr:
      return "camchain-imucam.yaml";
    case rig::ExportFormat::opencv:
      return "opencv_stereo.yaml";
    case rig::ExportFormat::opencv_sample:
      return "opencv_sample";
    case rig::ExportFormat::ros:
      return "ros";
    case rig::ExportFormat::mrcal:
      return "mrcal";
  }
  return "";
}

// YAML files carry the header as a comment; mrcal's .cameramodel allows '#' comments too.
// OpenCV's FileStorage needs its %YAML directive first: the header goes after it.
std::string with_header(const std::string& sha, const std::string& text) {
  if (text.rfind("%YAML", 0) == 0) {
    const size_t eol = text.find('\n');
    return text.substr(0, eol + 1) + published_header(sha) + "\n" + text.substr(eol + 1);
  }
  return published_header(sha) + "\n" + text;
}

}  // namespace

std::string published_header(const std::string& sha256) { return std::string(kHeader) + sha256; }

std::string published_hash(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  if (!in || !std::getline(in, line)) return "";
  if (line.rfind("%YAML", 0) == 0 && !std::getline(in, line)) return "";  // OpenCV's: second
  if (line.rfind(kHeader, 0) != 0) return "";
  return line.substr(kHeader.size());
}

PublishResult publish(const fs::path& calibration, const std::vector<fs::path>& sequences,
                      const PublishOptions& o) {
  if (sequences.empty()) throw Error("give at least one sequence folder");
  const rig::Rig rig = rig::read_rig_file(calibration);
  PublishResult out;
  out.sha256 = sha256_file(calibration);
  out.dropped = rig::vbr_drops(rig);

  std::vector<rig::ExportFormat> formats = {rig::ExportFormat::vbr};
  for (rig::ExportFormat f : o.formats) {
    if (std::find(formats.begin(), formats.end(), f) == formats.end()) formats.push_back(f);
  }
  std::vector<io::OutputFile> files;
  std::vector<std::string> refused;
  std::vector<std::unique_ptr<io::FolderLock>> claims;  // every sequence, for the whole run
  std::set<fs::path> claimed;
  for (const fs::path& seq : sequences) {
    if (!fs::is_directory(seq))
      throw Error(
          fmt::format("{}: not a folder (a sequence folder, <place>/<seq>/)", seq.string()));
    if (claimed.insert(fs::canonical(seq)).second)
      claims.push_back(std::make_unique<io::FolderLock>(seq));
    // File by file: one holding this calibration is left as it is, one holding another (or a
    // file rigcal did not publish) is replaced only when forced.
    Published p;
    p.sequence = seq;
    bool replaced = false;
    for (rig::ExportFormat f : formats) {
      for (const io::OutputFile& e : rig::export_files(rig, f, seq / export_name(f))) {
        if (fs::exists(e.path)) {
          const std::string old = published_hash(e.path);
          if (old == out.sha256) continue;
          if (!o.force) {
            refused.push_back(fmt::format(
                "{} holds {}", e.path.string(),
                old.empty() ? "a file rigcal did not publish"
                            : fmt::format("another calibration (sha256 {})", old.substr(0, 12))));
            continue;
          }
          replaced = true;
        }
        files.push_back({e.path, with_header(out.sha256, e.content)});
        p.files.push_back(e.path);
      }
    }
    p.state = p.files.empty() ? "unchanged" : replaced ? "replaced" : "written";
    out.sequences.push_back(p);
  }
  if (!refused.empty()) {
    throw Error(fmt::format("not replacing a different calibration without --force: {}",
                            fmt::join(refused, "; ")));
  }
  io::refuse_outputs_over_inputs(files, {{"the calibration", calibration}});
  io::write_files_atomic(files);
  return out;
}

}  // namespace rigcal::session
