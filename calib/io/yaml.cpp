#include "rigcal/io/yaml.h"

#include <fmt/format.h>

#include "rigcal/core/error.h"

namespace rigcal::io {

namespace {
// Counts nodes as a reader walking the tree would meet them (an alias once per use).
void count_nodes(const YAML::Node& node, size_t& count, std::string_view file, int depth = 0) {
  if (depth > kMaxYamlDepth) {
    fail_at(file, yaml_line(node), "",
            fmt::format("YAML nested deeper than {} levels (or an alias inside itself)",
                        kMaxYamlDepth));
  }
  if (++count > kMaxYamlNodes) {
    fail_at(file, yaml_line(node), "",
            fmt::format("more than {} YAML nodes once anchors and aliases are expanded",
                        kMaxYamlNodes));
  }
  if (node.IsSequence()) {
    for (const YAML::Node& child : node) count_nodes(child, count, file, depth + 1);
  } else if (node.IsMap()) {
    for (auto it = node.begin(); it != node.end(); ++it) {
      count_nodes(it->first, count, file, depth + 1);
      count_nodes(it->second, count, file, depth + 1);
    }
  }
}
}  // namespace

YAML::Node load_yaml(std::string_view text, std::string_view file) {
  if (text.size() > kMaxYamlBytes) {
    fail_at(file, 0, "",
            fmt::format("{} bytes, more than a YAML input of rigcal may be ({} bytes)", text.size(),
                        kMaxYamlBytes));
  }
  try {
    YAML::Node root = YAML::Load(std::string(text));
    size_t count = 0;
    count_nodes(root, count, file);
    return root;
  } catch (const YAML::Exception& e) {
    fail_at(file, e.mark.is_null() ? 0 : e.mark.line + 1, "",
            fmt::format("YAML syntax error: {}", e.msg));
  }
}

int yaml_line(const YAML::Node& node) { return node.Mark().is_null() ? 0 : node.Mark().line + 1; }

}  // namespace rigcal::io
