#pragma once
// What every calibration step returns (calib/<step>/step.h), so that any caller (the command
// line, the session pipeline, check, the tests) runs a step the same way and reads one answer:
// the updated rig, the step's report as data (the JSON and its figures, not yet written), lines
// for people, and a status. "The data do not determine this" is said one way: status
// undetermined, with the reason and the data that would settle it. Bad input is not a status: it
// raises rigcal::Error naming file, line or key.
#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "rigcal/io/files.h"
#include "rigcal/rig/rig.h"

namespace rigcal::report {

enum class StepStatus { ok, undetermined };
std::string_view to_string(StepStatus status);

// A named figure of the estimate: a standard deviation or a residual statistic, with its unit.
struct Figure {
  std::string name;  // "cam_l.fx", "rms_px", "T_cam_r_lidar.t.x"
  double value = 0;
  std::string unit;  // "px", "m", "deg", "s", ""
};

// The correlations among a group of the step's sigmas (one estimated quantity: a pose's six
// components, a lens's fx fy cx cy), so that a comparison can use the whole covariance.
struct Correlation {
  std::string name;                // the quantity: "T_cam_r_lidar", "cam_l"
  std::vector<std::string> names;  // the sigmas' names (Figure::name), in the matrix's order
  std::vector<double> rho;         // row-major, names.size() squared, 1 on the diagonal
};
// The correlation matrix of `covariance` (rows and columns in the order of `names`); a component
// with no variance is uncorrelated.
Correlation correlation_of(std::string name, std::vector<std::string> names,
                           const Eigen::MatrixXd& covariance);

// A pose T_a_b's 1-sigmas into `sigmas` (translation "<name>.t.x" m, then rotation
// "<name>.rotation.x" deg, about a's axes) and its correlation into `correlations`, from its
// 6 x 6 covariance in rigcal's tangent (rotation rad on the left, then translation m).
void add_pose_uncertainty(std::vector<Figure>& sigmas, std::vector<Correlation>& correlations,
                          const std::string& name, const Eigen::Matrix<double, 6, 6>& covariance);

// An input file or folder the step read (the session pipeline hashes them for provenance and
// its cache).
struct Input {
  std::string role;  // "target", "images cam_l", "reference", ...
  std::filesystem::path path;
};

struct StepResult {
  std::string step;  // "cameras", "lidar_camera", "time_sync", "hand_eye"
  StepStatus status = StepStatus::ok;
  std::string reason;  // undetermined: what the data do not determine, and why
  std::string remedy;  // undetermined: the data or option that would settle it
  // The rig with this step's estimate written in (when undetermined: the rig as given).
  rig::Rig rig;
  // The sensors whose entries this step wrote (the pipeline copies exactly these).
  std::vector<std::string> wrote;
  // <step>.json and the figures beside it, paths relative to the report folder.
  nlohmann::json report;
  std::vector<io::OutputFile> report_files;
  // Lines for people, in the order a terminal shows them; notes are what was assumed or noticed.
  std::vector<std::string> summary, notes;
  // What a person must look at before trusting an ok result (many outlier pairs, an image half
  // without corners): printed as "warning:", first in the report.
  std::vector<std::string> warnings;
  std::vector<Figure> sigmas, residuals;
  std::vector<Correlation> correlations;
  std::vector<Input> inputs;
};

// Sets result.report from its JSON file among report_files (`json_file`), with the status, the
// warnings (and the reason and remedy when undetermined) added, and writes it back. Throws when it
// is absent.
// `extra`: keys added to the report as they are (an object, or null for none).
void finish_report(StepResult& result, std::string_view json_file,
                   const nlohmann::json& extra = nullptr);

// The report's files under `dir`: <step>.json (the report with the status added) and the figures.
std::vector<io::OutputFile> report_files_in(const StepResult& result,
                                            const std::filesystem::path& dir);

// Progress of long work: called with what is being done, items done and the total. Callers
// decide how to show it (the command line: one updating line on a terminal, whole lines in a
// log). An empty function shows nothing.
using Progress = std::function<void(std::string_view what, size_t done, size_t total)>;
inline void tell(const Progress& progress, std::string_view what, size_t done, size_t total) {
  if (progress) progress(what, done, total);
}

}  // namespace rigcal::report
