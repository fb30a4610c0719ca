#pragma once
// The pages a person reads (report.html), one self-contained HTML file a run, rendered from what
// the run stored (its JSON and figures) and nothing else, so that `rigcal report DIR` renders the
// same page again: `rigcal calibrate` (OUT/report.html), `rigcal check` and `rigcal diff`
// (DIR/report.html).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "rigcal/io/files.h"

namespace rigcal::session {

// A figure by file name and its text (SVG).
using NamedFigures = std::vector<std::pair<std::string, std::string>>;

// diff.json and the projection maps (projection_diff_<camera>.svg); diff_html_sections is its
// body, which check's page includes.
std::string diff_html(const nlohmann::json& diff, const NamedFigures& figures);
std::string diff_html_sections(const nlohmann::json& diff, const NamedFigures& figures);
// check.json (with its difference) and the projection maps.
std::string check_html(const nlohmann::json& check, const NamedFigures& figures);
// A calibrate run's folder OUT: OUT/reports/calibrate.json (the steps' statuses, summaries,
// warnings), each step's OUT/reports/<step>/<step>.json and its figures (PNGs inlined; the
// cameras' residuals.csv drawn as plots with axes in px).
std::string calibrate_html(const std::filesystem::path& out);
// A single step's report folder (`rigcal cameras --report DIR`, and lidar-camera, time-offset,
// hand-eye): DIR/run.json (calibrate.h's step_run_file) and the step's report beside it; the
// same section as on the calibrate page, under the step's verdict.
std::string step_html(const std::filesystem::path& dir);

// DIR/report.html rendered again from what a run stored in DIR: a calibrate output folder
// (reports/calibrate.json), else a single step's (run.json), else ground_truth.json
// (gt/report_html.h), else check.json, else diff.json. Throws rigcal::Error when DIR holds
// none, or one rigcal did not write.
io::OutputFile render_report(const std::filesystem::path& dir);

}  // namespace rigcal::session
