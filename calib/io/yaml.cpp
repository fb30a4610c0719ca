#include "rigcal/io/yaml.h"

#include <fmt/format.h>

#include "rigcal/core/error.h"

namespace rigcal::io {

YAML::Node load_yaml(std::string_view text, std::string_view file) {
  try {
    return YAML::Load(std::string(text));
  } catch (const YAML::Exception& e) {
    fail_at(file, e.mark.is_null() ? 0 : e.mark.line + 1, "",
            fmt::format("YAML syntax error: {}", e.msg));
  }
}

int yaml_line(const YAML::Node& node) { return node.Mark().is_null() ? 0 : node.Mark().line + 1; }

}  // namespace rigcal::io
