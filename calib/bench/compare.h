#pragma once
// Several results side by side (evo_res's job): estimates scored against one ground truth in one
// run (`rigcal bench --est A --est B`), or saved results (`rigcal bench compare RESULT...`, each
// a bench.json or a folder holding one). A table of their figures and plots of them together.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "rigcal/bench/evaluate.h"
#include "rigcal/bench/report.h"

namespace rigcal::bench {

struct NamedResult {
  std::string name;        // the estimate file's stem, or the result's folder
  nlohmann::json summary;  // a bench.json
};

// Reads a bench.json (or DIR/bench.json). Throws rigcal::Error naming the file when it is not
// one (no convention, ate or rpe).
NamedResult read_result(const std::filesystem::path& path);
// Names made unique by appending " (2)", " (3)", ... to repeats, in order.
void make_names_unique(std::vector<NamedResult>& results);

// The table: a row a result; ATE translation rmse, mean, median, std, max (m) and rotation rmse
// (deg); each RPE kind's drift (%) or, for delta pairs, translation rmse (m); "-" where a
// result has no such figure. The convention is a column, and a note under the table says when
// the results' conventions differ (their figures are then not defined alike).
std::string compare_markdown(const std::vector<NamedResult>& results);
std::string compare_csv(const std::vector<NamedResult>& results);
nlohmann::json compare_json(const std::vector<NamedResult>& results);
// DIR/compare.{md,csv,json} and evo_res's plots of the ATE translation and of the delta pairs'
// RPE translation: compare_{ate,rpe}_stats.svg (rmse, mean, median, std, min, max as grouped
// bars) and, for results whose bench.json holds the errors' distribution (written with
// --report), compare_{ate,rpe}_box.svg and compare_{ate,rpe}_histogram.svg. Returns the names of
// the files written.
std::vector<std::string> write_compare_report(const std::vector<NamedResult>& results,
                                              const std::filesystem::path& dir);

// Several estimates against one ground truth, evaluated with keep_per_pose: DIR/trajectories.svg
// (the ground truth and every aligned estimate, in the ground truth's plane) and DIR/ate.svg
// (each estimate's ATE along the trajectory).
void write_overlay_plots(const std::vector<const EvalResult*>& results,
                         const std::vector<std::string>& names, const std::filesystem::path& dir,
                         PlotMode mode);

}  // namespace rigcal::bench
