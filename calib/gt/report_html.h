#pragma once
// The page a person reads for a ground-truth run (doc/ground-truth.md, "The report"): the verdict
// (markers against the survey, what is undetermined), the trajectory from above, the GNSS priors
// with every rejected one, the bundle adjustment's windows. Rendered from ground_truth.json and
// the top view stored beside it, so `rigcal report DIR` renders it again.
#include <nlohmann/json.hpp>
#include <string>

#include "rigcal/gt/types.h"

namespace rigcal::gt {

// The trajectory from above (east, north in m), coloured by each pose's horizontal 1-sigma in
// mm, the poses whose GNSS prior was rejected marked: trajectory_top.svg beside the JSON.
std::string trajectory_top_svg(const PoseGraphResult& graph);

// report.html from ground_truth.json (`report`) and trajectory_top.svg's text ("" if none).
std::string ground_truth_html(const nlohmann::json& report, const std::string& top_view_svg);

}  // namespace rigcal::gt
