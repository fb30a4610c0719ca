#pragma once
// Target files (targets/*.yaml, doc/targets.md): Kalibr's target YAML read as it is
//   target_type: aprilgrid, tagCols, tagRows, tagSize (m), tagSpacing (gap / tagSize)
//   target_type: checkerboard, targetCols, targetRows (inner corners), rowSpacingMeters,
//   colSpacingMeters
// plus rigcal's optional keys: name, margin (m), thickness (m).
#include <filesystem>
#include <string>
#include <string_view>

#include "rigcal/camera/target.h"

namespace rigcal::io {

camera::Target parse_target_yaml(std::string_view text, std::string_view file_name);
camera::Target read_target_file(const std::filesystem::path& path);
// The target in the same format; parse_target_yaml reads it back to the same target.
std::string target_to_yaml(const camera::Target& target);

}  // namespace rigcal::io
