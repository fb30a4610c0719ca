// rigcal publish CALIB.yaml SEQUENCE_DIR...: the calibration into each sequence folder
// (doc/session.md).
#include "rigcal/session/publish.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <memory>

#include "cli.h"
#include "rigcal/core/text.h"

namespace rigcal::cli {
namespace publish_command {

struct Options {
  std::string calibration, formats = "vbr";
  std::vector<std::string> sequences;
  bool force = false;
};

void run(const Options& o) {
  session::PublishOptions po;
  po.formats.clear();
  for (std::string_view f : split_fields(o.formats))
    po.formats.push_back(rig::export_format_from_string(f));
  po.force = o.force;
  std::vector<std::filesystem::path> sequences(o.sequences.begin(), o.sequences.end());
  const session::PublishResult r = session::publish(o.calibration, sequences, po);
  fmt::print("calibration {} (sha256 {})\n", o.calibration, r.sha256);
  for (const std::string& d : r.dropped) fmt::print("vbr_calib.yaml drops: {}\n", d);
  for (const session::Published& p : r.sequences) {
    if (p.state == "unchanged") {
      fmt::print("{}: holds this calibration already, left as it is\n", p.sequence.string());
      continue;
    }
    std::vector<std::string> names;
    for (const auto& f : p.files) names.push_back(f.filename().string());
    fmt::print("{}: {} {}\n", p.sequence.string(), p.state, fmt::join(names, ", "));
  }
}

}  // namespace publish_command

void add_publish(CLI::App& app) {
  using namespace publish_command;
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "publish",
      "Publish a calibration with recorded sequences (doc/session.md): vbr_calib.yaml (the\n"
      "published VBR keys only, so every VBR loader reads it) and the chosen exports into each\n"
      "sequence folder (<place>/<seq>/), each file's first line naming the calibration's\n"
      "sha256. Says what the VBR format drops (clock offsets, provenance). A folder holding a\n"
      "different calibration is refused unless --force; all files are written, or none.");
  cmd->add_option("calibration", o->calibration, "the calibration YAML (rigcal calibrate's)")
      ->required();
  cmd->add_option("sequences", o->sequences, "sequence folders")->required();
  cmd->add_option(
         "--formats", o->formats,
         "comma-separated: vbr (always), rigcal, kalibr, ros, opencv, opencv-sample, mrcal")
      ->capture_default_str();
  cmd->add_flag("--force", o->force, "replace a different calibration");
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::cli
