#pragma once
// Loading YAML text with errors that name the file and line (every YAML reader of rigcal).
#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <string_view>

namespace rigcal::io {

// What a YAML input of rigcal (calibration, target, simulator config, session) may be: a
// calibration with its provenance is tens of kB, so these bound a hostile file's time and
// memory (a 1 MiB file loads in well under a second), not a real one.
inline constexpr size_t kMaxYamlBytes = 1 << 20;
// Nodes after expanding anchors and aliases (a "billion laughs" file is a few lines).
inline constexpr size_t kMaxYamlNodes = 1'000'000;
// Levels of nesting (an alias used inside its own anchor is infinitely deep).
inline constexpr int kMaxYamlDepth = 200;

// Throws rigcal::Error "FILE:LINE: YAML syntax error: ..." on malformed text, and when the text or
// its expansion is over the limits above.
YAML::Node load_yaml(std::string_view text, std::string_view file_name);
// Throws rigcal::Error "FILE:LINE: key 'K': given twice" for a key repeated in any map of the
// tree (yaml-cpp keeps one of them silently).
void refuse_duplicate_keys(const YAML::Node& node, std::string_view file_name);
// 1-based line of a node, 0 when unknown.
int yaml_line(const YAML::Node& node);

}  // namespace rigcal::io
