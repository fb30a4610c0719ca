#include "rigcal/io/target_yaml.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <set>

#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/io/files.h"
#include "rigcal/io/yaml.h"

namespace rigcal::io {

camera::Target parse_target_yaml(std::string_view text, std::string_view file) {
  const YAML::Node root = io::load_yaml(text, file);
  io::refuse_duplicate_keys(root, file);
  if (!root.IsMap()) fail_at(file, 0, "", "expected a map with target_type");
  auto line = [](const YAML::Node& n) { return yaml_line(n); };
  auto get = [&](const char* key) -> YAML::Node {
    const YAML::Node n = root[key];
    if (!n) fail_at(file, line(root), key, "missing required key");
    return n;
  };
  auto number = [&](const char* key) {
    const YAML::Node n = get(key);
    double v = NAN;
    try {
      v = n.as<double>();
    } catch (const YAML::Exception&) {
    }
    if (!std::isfinite(v)) {
      fail_at(file, line(n), key,
              fmt::format("expected a finite number, got '{}'", printable(n.Scalar())));
    }
    return v;
  };
  auto integer = [&](const char* key) {
    const double v = number(key);
    if (v != std::floor(v)) fail_at(file, line(root[key]), key, "expected a whole number");
    if (v < 1 || v > camera::kMaxTargetCorners) {
      fail_at(file, line(root[key]), key,
              fmt::format("{} is outside 1..{}", v, camera::kMaxTargetCorners));
    }
    return static_cast<int>(v);
  };
  auto scalar = [&](const char* key) {
    const YAML::Node n = get(key);
    if (!n.IsScalar() || n.Scalar().empty()) fail_at(file, line(n), key, "expected a text value");
    return n.Scalar();
  };
  camera::Target t;
  const std::string type = scalar("target_type");
  std::set<std::string> known = {"target_type", "name", "margin", "thickness"};
  if (type == "checkerboard") {
    t.type = camera::TargetType::checkerboard;
    t.cols = integer("targetCols");
    t.rows = integer("targetRows");
    const double row = number("rowSpacingMeters"), col = number("colSpacingMeters");
    if (row != col)
      fail_at(file, line(root["colSpacingMeters"]), "colSpacingMeters",
              "rigcal needs square checkerboard cells (rowSpacingMeters == colSpacingMeters)");
    t.square = row;
    known.insert({"targetCols", "targetRows", "rowSpacingMeters", "colSpacingMeters"});
  } else if (type == "aprilgrid") {
    t.type = camera::TargetType::aprilgrid;
    t.cols = integer("tagCols");
    t.rows = integer("tagRows");
    t.tag_size = number("tagSize");
    t.tag_spacing = number("tagSpacing");
    known.insert({"tagCols", "tagRows", "tagSize", "tagSpacing", "tagFamily", "codeOffset"});
  } else {
    fail_at(file, line(root["target_type"]), "target_type",
            fmt::format("unknown target type '{}'; expected checkerboard or aprilgrid",
                        printable(type)));
  }
  for (auto it = root.begin(); it != root.end(); ++it) {
    if (!known.count(it->first.Scalar())) {
      fail_at(file, line(it->first), printable(it->first.Scalar()),
              "unknown key for this target type");
    }
  }
  if (root["name"])
    t.name = scalar("name");
  else
    t.name = std::filesystem::path(std::string(file)).stem().string();
  if (root["margin"]) {
    t.margin = number("margin");
    if (t.margin < 0) fail_at(file, line(root["margin"]), "margin", "must be >= 0 m");
  }
  if (root["thickness"]) t.thickness = number("thickness");
  try {
    camera::validate(t);
  } catch (const Error& e) {
    fail_at(file, 0, "", e.what());
  }
  return t;
}

camera::Target read_target_file(const std::filesystem::path& path) {
  return parse_target_yaml(read_text_file(path, kMaxYamlBytes), path.string());
}

std::string target_to_yaml(const camera::Target& t) {
  camera::validate(t);
  std::string out;
  if (t.type == camera::TargetType::checkerboard) {
    out += fmt::format(
        "target_type: checkerboard\ntargetCols: {}\ntargetRows: {}\nrowSpacingMeters: {}\n"
        "colSpacingMeters: {}\n",
        t.cols, t.rows, format_double(t.square), format_double(t.square));
  } else {
    out += fmt::format(
        "target_type: aprilgrid\ntagCols: {}\ntagRows: {}\ntagSize: {}\ntagSpacing: {}\n", t.cols,
        t.rows, format_double(t.tag_size), format_double(t.tag_spacing));
  }
  YAML::Emitter name;  // quoted when the text needs it (a colon, a leading '!', ...)
  name << t.name;
  out += fmt::format("name: {}\n", name.c_str());
  if (t.margin >= 0) out += fmt::format("margin: {}\n", format_double(t.margin));
  out += fmt::format("thickness: {}\n", format_double(t.thickness));
  return out;
}

}  // namespace rigcal::io
