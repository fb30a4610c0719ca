#pragma once
// The calibration YAML (doc/calibration-yaml.md): a superset of the published VBR vbr_calib.yaml.
// A VBR-only file reads (pinhole + radtan assumed, said in rig.notes); a file rigcal writes reads
// back to the identical rig, every double bit for bit.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "rigcal/rig/rig.h"

namespace rigcal::rig {

// Parses YAML text; `file_name` is used in messages. Throws rigcal::Error naming file, line and key
// on any problem: YAML syntax, missing key, wrong shape, bad values (see validate()).
Rig parse_rig_yaml(std::string_view text, std::string_view file_name);
Rig read_rig_file(const std::filesystem::path& path);

// The full rigcal form. Validates first (throws rigcal::Error on an invalid rig).
std::string rig_to_yaml(const Rig& rig);
// Writes rig_to_yaml atomically (temporary file, then rename).
void write_rig_file(const Rig& rig, const std::filesystem::path& path);

// Only the keys of the published VBR format (T_b, intrinsics, distortion_coeffs, resolution, the
// IMU noise keys and update_rate), for strict VBR loaders. Throws for what VBR cannot express
// (equidistant distortion). Sensors of other types are written with their T_b only.
std::string rig_to_vbr_yaml(const Rig& rig);

// Shortest YAML text of a double that reads back bit-identical, with a '.' as YAML 1.1 wants.
std::string yaml_number(double value);
// "[a, b, c]" of yaml_number()s.
std::string yaml_list(const std::vector<double>& values);
// The 4 rows of T's matrix as a block list of flow rows, each line starting with `indent`.
std::string yaml_matrix4_rows(const SE3& T, std::string_view indent);

}  // namespace rigcal::rig
