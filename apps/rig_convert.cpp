// rigcal rig convert FILE --to FORMAT --out PATH: exports for other tools.
#include <fmt/format.h>

#include <memory>

#include "cli.h"
#include "rigcal/rig/export.h"
#include "rigcal/rig/import.h"
#include "rigcal/rig/rig_yaml.h"

namespace rigcal::cli {
namespace rig_convert_command {

struct Options {
  std::string file, to, out, imu;
};

}  // namespace rig_convert_command

void add_rig_convert(CLI::App& parent) {
  using namespace rig_convert_command;
  auto o = std::make_shared<Options>();
  CLI::App* cmd = parent.add_subcommand(
      "convert",
      "Write the rig for another tool (doc/exports.md):\n"
      "  rigcal  the full rigcal YAML (e.g. to normalise a VBR file)\n"
      "  vbr     only the keys of the published vbr_calib.yaml\n"
      "  kalibr  Kalibr camchain (T_cn_cnm1, T_cam_imu, timeshift_cam_imu)\n"
      "  opencv  cv::FileStorage YAML: K1 D1 K2 D2 R T E F + stereo rectification\n"
      "  opencv-sample  OpenCV's stereo_calib sample's intrinsics.yml (M1 D1 M2 D2) and\n"
      "          extrinsics.yml (R T R1 R2 P1 P2 Q, alpha 1) into the folder --out\n"
      "  ros     one camera_info YAML per camera into the folder --out\n"
      "  mrcal   one .cameramodel per camera into the folder --out\n"
      "Files are written to a temporary name and renamed: a failed run writes nothing.");
  cmd->add_option("file", o->file,
                  "calibration file (rigcal, VBR, Kalibr camchain, ROS camera_info, OpenCV, mrcal)")
      ->required();
  cmd->add_option("--to", o->to, "rigcal | vbr | kalibr | opencv | opencv-sample | ros | mrcal")
      ->required();
  cmd->add_option("--out", o->out, "output file (a folder for opencv-sample, ros and mrcal)")
      ->required();
  cmd->add_option("--imu", o->imu,
                  "kalibr: the IMU for T_cam_imu (default: the sensor 'imu', else the first IMU)");
  cmd->callback([o] {
    const rig::ExportFormat format = rig::export_format_from_string(o->to);
    const rig::Rig r = rig::read_calibration_file(o->file);
    const std::vector<io::OutputFile> files =
        rig::export_files(r, format, o->out, rig::ExportOptions{o->imu});
    io::refuse_outputs_over_inputs(files, {{"the calibration", o->file}});
    io::write_files_atomic(files);
    for (const io::OutputFile& f : files) fmt::print("wrote {} ({})\n", f.path.string(), o->to);
    if (format == rig::ExportFormat::vbr) {
      for (const std::string& d : rig::vbr_drops(r)) fmt::print("dropped: {}\n", d);
    }
  });
}

}  // namespace rigcal::cli
