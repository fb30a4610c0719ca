// rigcal rig validate FILE: reads a calibration YAML with every check and says what it holds.
#include <fmt/format.h>

#include <memory>

#include "cli.h"
#include "rigcal/rig/import.h"
#include "rigcal/rig/rig_yaml.h"

namespace rigcal::cli {

void add_rig_validate(CLI::App& parent) {
  auto file = std::make_shared<std::string>();
  CLI::App* cmd = parent.add_subcommand(
      "validate",
      "Check a calibration: shapes, rotations (max |R^T R - I| <= 1e-5, det > 0), focal\n"
      "lengths, distortion models and coefficient counts, required keys, duplicate sensors.\n"
      "Reads rigcal's YAML, VBR's vbr_calib.yaml, a Kalibr camchain, a ROS camera_info, an\n"
      "OpenCV FileStorage file and an mrcal .cameramodel (doc/exports.md: what each becomes).\n"
      "Exit 0 when valid; else one line naming file, line and key, and exit 2.");
  cmd->add_option("file", *file, "calibration file (rigcal, VBR, Kalibr, ROS, OpenCV, mrcal)")
      ->required();
  cmd->callback([file] {
    const rig::Rig r = rig::read_calibration_file(*file);
    std::vector<std::string> names;
    for (const rig::Sensor& s : r.sensors)
      names.push_back(fmt::format("{} ({})", s.name, rig::to_string(s.type)));
    fmt::print("{}: valid, {} sensors: {}; base frame {}\n", *file, r.sensors.size(),
               fmt::join(names, ", "), r.base_frame);
    for (const std::string& note : r.notes) fmt::print("note: {}\n", note);
  });
}

}  // namespace rigcal::cli
