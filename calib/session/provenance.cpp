#include "rigcal/session/provenance.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>

#include "rigcal/core/error.h"
#include "rigcal/core/sha256.h"

namespace rigcal::session {
namespace fs = std::filesystem;

HashedInput hash_input(const std::string& role, const fs::path& path) {
  HashedInput h{role, fs::absolute(path).lexically_normal(), "", 1};
  if (fs::is_regular_file(path)) {
    h.sha256 = sha256_file(path);
    return h;
  }
  if (!fs::is_directory(path))
    throw Error(fmt::format("{}: no such file or folder", path.string()));
  std::vector<fs::path> files;
  // Folders behind links are followed (a recording's data/ may live on another disk).
  for (const fs::directory_entry& e :
       fs::recursive_directory_iterator(path, fs::directory_options::follow_directory_symlink)) {
    if (e.is_regular_file()) files.push_back(fs::relative(e.path(), path));
  }
  std::sort(files.begin(), files.end());
  Sha256 all;
  for (const fs::path& f : files) {
    all.update(f.generic_string());
    all.update(std::string_view("\0", 1));
    all.update(sha256_file(path / f));
    all.update("\n");
  }
  h.sha256 = all.hex();
  h.files = files.size();
  return h;
}

std::string figure_key(const report::Figure& f) {
  std::string unit = f.unit;
  std::replace(unit.begin(), unit.end(), '/', '_');
  const std::string suffix = "_" + unit;
  if (f.unit.empty() || (f.name.size() > suffix.size() &&
                         f.name.compare(f.name.size() - suffix.size(), suffix.size(), suffix) == 0))
    return f.name;
  return f.name + suffix;
}

std::string steps_yaml(const std::vector<StepRecord>& records) {
  YAML::Emitter e;
  e << YAML::Flow << YAML::BeginMap;
  for (const StepRecord& r : records) {
    e << YAML::Key << r.step << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "status" << YAML::Value << r.status;
    e << YAML::Key << "tool_version" << YAML::Value << r.tool_version;
    if (!r.reason.empty()) e << YAML::Key << "reason" << YAML::Value << r.reason;
    e << YAML::Key << "inputs" << YAML::Value << YAML::BeginSeq;
    for (const HashedInput& in : r.inputs) {
      e << YAML::BeginMap << YAML::Key << "role" << YAML::Value << in.role << YAML::Key << "path"
        << YAML::Value << in.path.string() << YAML::Key << "sha256" << YAML::Value << in.sha256;
      if (fs::is_directory(in.path)) e << YAML::Key << "files" << YAML::Value << in.files;
      e << YAML::EndMap;
    }
    e << YAML::EndSeq;
    for (const auto& [name, figures] :
         {std::pair{"sigmas", &r.sigmas}, std::pair{"residuals", &r.residuals}}) {
      e << YAML::Key << name << YAML::Value << YAML::BeginMap;
      for (const report::Figure& f : *figures) {
        e << YAML::Key << figure_key(f) << YAML::Value
          << (std::isfinite(f.value) ? fmt::format("{:.4g}", f.value) : std::string("null"));
      }
      e << YAML::EndMap;
    }
    e << YAML::EndMap;
  }
  e << YAML::EndMap;
  return e.c_str();
}

std::vector<StepRecord> read_steps(const rig::Rig& rig) {
  std::vector<StepRecord> out;
  for (const auto& [key, text] : rig.extra_metadata) {
    if (key != "steps") continue;
    try {
      const YAML::Node steps = YAML::Load(text);
      for (auto it = steps.begin(); it != steps.end(); ++it) {
        StepRecord r;
        const YAML::Node n = it->second;
        r.step = it->first.as<std::string>();
        auto text = [&](const char* key) {
          const YAML::Node v = n[key];
          return v ? v.as<std::string>() : std::string();
        };
        r.status = text("status");
        r.tool_version = text("tool_version");
        r.reason = text("reason");
        const YAML::Node inputs = n["inputs"];
        for (size_t i = 0; inputs && i < inputs.size(); ++i) {
          const YAML::Node in = inputs[i];
          const YAML::Node files = in["files"];
          r.inputs.push_back({in["role"].as<std::string>(), in["path"].as<std::string>(),
                              in["sha256"].as<std::string>(), files ? files.as<size_t>() : 1});
        }
        for (const auto& [name, figures] :
             {std::pair{"sigmas", &r.sigmas}, std::pair{"residuals", &r.residuals}}) {
          const YAML::Node map = n[name];
          if (!map) continue;
          for (auto f = map.begin(); f != map.end(); ++f) {
            const double v = f->second.IsNull() ? NAN : f->second.as<double>();
            figures->push_back({f->first.as<std::string>(), v, ""});
          }
        }
        out.push_back(std::move(r));
      }
    } catch (const YAML::Exception& e) {
      throw Error(
          fmt::format("rigcal.steps: not the provenance rigcal calibrate writes ({})", e.what()));
    }
  }
  return out;
}

std::map<std::string, double> stored_sigmas(const rig::Rig& rig) {
  std::map<std::string, double> out;
  for (const StepRecord& s : read_steps(rig))
    for (const report::Figure& f : s.sigmas) out[f.name] = f.value;
  return out;
}

}  // namespace rigcal::session
