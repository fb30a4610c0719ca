#include "rigcal/report/step.h"

#include <fmt/format.h>

#include <stdexcept>

#include "rigcal/report/json.h"

namespace rigcal::report {

std::string_view to_string(StepStatus status) {
  return status == StepStatus::ok ? "ok" : "undetermined";
}

void finish_report(StepResult& r, std::string_view json_file, const nlohmann::json& extra) {
  for (io::OutputFile& f : r.report_files) {
    if (f.path != json_file) continue;
    r.report = nlohmann::json::parse(f.content);
    r.report["status"] = to_string(r.status);
    r.report["warnings"] = r.warnings;
    if (extra.is_object()) r.report.update(extra);
    if (r.status != StepStatus::ok) {
      r.report["reason"] = r.reason;
      r.report["remedy"] = r.remedy;
    }
    f.content = json_text(r.report);
    return;
  }
  throw std::logic_error(fmt::format("{}: no {} among its report files", r.step, json_file));
}

std::vector<io::OutputFile> report_files_in(const StepResult& result,
                                            const std::filesystem::path& dir) {
  std::vector<io::OutputFile> files;
  for (const io::OutputFile& f : result.report_files) files.push_back({dir / f.path, f.content});
  return files;
}

}  // namespace rigcal::report
