#include "rigcal/report/step.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "rigcal/report/json.h"

namespace rigcal::report {

std::string_view to_string(StepStatus status) {
  return status == StepStatus::ok ? "ok" : "undetermined";
}

Correlation correlation_of(std::string name, std::vector<std::string> names,
                           const Eigen::MatrixXd& covariance) {
  const Eigen::Index n = static_cast<Eigen::Index>(names.size());
  if (covariance.rows() != n || covariance.cols() != n)
    throw std::logic_error(fmt::format("{}: a {}x{} covariance for {} names", name,
                                       covariance.rows(), covariance.cols(), n));
  Correlation c{std::move(name), std::move(names), {}};
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < n; ++j) {
      const double v = covariance(i, i) * covariance(j, j);
      c.rho.push_back(i == j ? 1.0 : v > 0 ? covariance(i, j) / std::sqrt(v) : 0.0);
    }
  }
  return c;
}

void add_pose_uncertainty(std::vector<Figure>& sigmas, std::vector<Correlation>& correlations,
                          const std::string& name, const Eigen::Matrix<double, 6, 6>& covariance) {
  const auto sigma = [&](int i) { return std::sqrt(std::max(0.0, covariance(i, i))); };
  for (int a = 0; a < 3; ++a)
    sigmas.push_back({fmt::format("{}.t.{}", name, "xyz"[a]), sigma(3 + a), "m"});
  for (int a = 0; a < 3; ++a) {
    sigmas.push_back(
        {fmt::format("{}.rotation.{}", name, "xyz"[a]), sigma(a) * 180.0 / M_PI, "deg"});
  }
  std::vector<std::string> names;  // the covariance's order: rotation, then translation
  for (const char* part : {"rotation", "t"})
    for (int a = 0; a < 3; ++a) names.push_back(fmt::format("{}.{}.{}", name, part, "xyz"[a]));
  correlations.push_back(correlation_of(name, names, covariance));
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
