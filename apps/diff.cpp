// rigcal diff A.yaml B.yaml: two calibrations of one rig side by side (doc/diff.md).
#include "rigcal/session/diff.h"

#include <fmt/format.h>

#include <memory>

#include "cli.h"
#include "rigcal/core/text.h"
#include "rigcal/rig/import.h"
#include "rigcal/rig/rig_yaml.h"

namespace rigcal::cli {
namespace diff_command {

struct Options {
  std::string a, b, report, cameras;
  double grid_step_px = 20;
};

void run(const Options& o) {
  rig::ImportOptions import;
  for (std::string_view name : split_fields(o.cameras)) import.camera_names.emplace_back(name);
  const rig::Rig a = rig::read_calibration_file(o.a, import),
                 b = rig::read_calibration_file(o.b, import);
  session::DiffConfig config;
  config.grid_step_px = o.grid_step_px;
  const session::RigDifference d = session::diff_rigs(a, b, config);
  fmt::print("A: {}\nB: {}\n", o.a, o.b);
  for (const std::string& line : session::diff_lines(d)) fmt::print("{}\n", line);
  if (!o.report.empty()) {
    const std::vector<io::OutputFile> files = session::diff_report_files(d, o.report);
    io::refuse_outputs_over_inputs(files, {{"calibration A", o.a}, {"calibration B", o.b}});
    io::write_files_atomic(files);
    fmt::print("report: {0}/report.html, {0}/diff.json\n", o.report);
  }
}

}  // namespace diff_command

void add_diff(CLI::App& app) {
  using namespace diff_command;
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "diff",
      "Compare two calibrations of one rig (doc/diff.md): every sensor's pose in A's base frame\n"
      "and each relation a step estimated (rotation about the first frame's axes in deg,\n"
      "translation in mm), clock offsets (ms) and drifts, camera intrinsics, and each camera's\n"
      "projection difference: the ray of each pixel by A's lens projected by B's, over a grid\n"
      "of the image, raw and with the best rotation of the camera taken out (mrcal's\n"
      "projection-diff at infinity). Where the calibrations store sigmas (rigcal.steps), each\n"
      "difference is weighed by them: chi-square, and its probability if nothing changed\n"
      "(p < 0.001 says 'changed'). Exit status 0 whatever the differences; 2 on bad input.");
  cmd->add_option("a", o->a,
                  "the first calibration (the reference): rigcal or VBR YAML, Kalibr camchain,\n"
                  "ROS camera_info, OpenCV FileStorage, mrcal .cameramodel")
      ->required();
  cmd->add_option("b", o->b, "the second calibration (the same formats)")->required();
  cmd->add_option("--report", o->report,
                  "folder for diff.json and projection_diff_<camera>.svg (the map over the image)");
  cmd->add_option(
      "--cameras", o->cameras,
      "names for the cameras of a file from another tool, in its order (Kalibr's cam0,\n"
      "cam1 ...; default cam_l, cam_r, or the name the file gives)");
  cmd->add_option("--grid-step", o->grid_step_px, "the projection grid's spacing, px")
      ->capture_default_str()
      ->check(finite_number(true) & CLI::Range(1.0, 1000.0));
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::cli
