#include "rigcal/session/provenance.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>

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
    if (!r.correlations.empty()) {
      // Each quantity's correlation matrix, rows in the order of `keys` (the sigmas' keys).
      e << YAML::Key << "correlations" << YAML::Value << YAML::BeginMap;
      for (const report::Correlation& c : r.correlations) {
        e << YAML::Key << c.name << YAML::Value << YAML::BeginMap << YAML::Key << "keys"
          << YAML::Value << YAML::BeginSeq;
        for (const std::string& name : c.names) {
          const auto f = std::find_if(r.sigmas.begin(), r.sigmas.end(),
                                      [&](const report::Figure& s) { return s.name == name; });
          e << (f == r.sigmas.end() ? name : figure_key(*f));
        }
        e << YAML::EndSeq << YAML::Key << "rho" << YAML::Value << YAML::BeginSeq;
        for (const double v : c.rho) e << fmt::format("{:.6g}", std::isfinite(v) ? v : 0.0);
        e << YAML::EndSeq << YAML::EndMap;
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
        if (const YAML::Node c = n["correlations"]) {
          for (auto q = c.begin(); q != c.end(); ++q) {
            report::Correlation k{q->first.as<std::string>(),
                                  q->second["keys"].as<std::vector<std::string>>(),
                                  q->second["rho"].as<std::vector<double>>()};
            if (k.rho.size() != k.names.size() * k.names.size()) {
              throw Error(fmt::format(
                  "rigcal.steps: {}: correlations of {}: {} values for {} keys (a square "
                  "matrix, row by row)",
                  r.step, k.name, k.rho.size(), k.names.size()));
            }
            for (const double v : k.rho) {
              if (!(std::abs(v) <= 1.0))
                throw Error(
                    fmt::format("rigcal.steps: {}: correlations of {}: {} is not in [-1, 1]",
                                r.step, k.name, v));
            }
            r.correlations.push_back(std::move(k));
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

double StoredUncertainty::correlation(const std::string& a, const std::string& b) const {
  if (a == b) return 1.0;
  const auto it = rho.find({a, b});
  return it == rho.end() ? 0.0 : it->second;
}

StoredUncertainty uncertainty_of(const std::vector<StepRecord>& records) {
  StoredUncertainty out;
  for (const StepRecord& s : records) {
    // By the keys they are (or would be) stored under: a record read back has them as names.
    std::map<std::string, std::string> key_of;
    for (const report::Figure& f : s.sigmas) {
      key_of[f.name] = figure_key(f);
      out.sigma[figure_key(f)] = f.value;
    }
    const auto key = [&](const std::string& name) {
      const auto it = key_of.find(name);
      return it == key_of.end() ? name : it->second;
    };
    for (const report::Correlation& c : s.correlations) {
      const size_t n = c.names.size();
      for (size_t i = 0; i < n; ++i)
        for (size_t j = 0; j < n; ++j)
          if (i != j) out.rho[{key(c.names[i]), key(c.names[j])}] = c.rho[i * n + j];
    }
  }
  return out;
}

StoredUncertainty stored_uncertainty(const rig::Rig& rig) {
  return uncertainty_of(read_steps(rig));
}

}  // namespace rigcal::session
