#pragma once
// Loading YAML text with errors that name the file and line (every YAML reader of rigcal).
#include <yaml-cpp/yaml.h>

#include <string_view>

namespace rigcal::io {

// Throws rigcal::Error "FILE:LINE: YAML syntax error: ..." on malformed text.
YAML::Node load_yaml(std::string_view text, std::string_view file_name);
// 1-based line of a node, 0 when unknown.
int yaml_line(const YAML::Node& node);

}  // namespace rigcal::io
