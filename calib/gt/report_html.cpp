// The ground-truth page (report_html.h).
#include "rigcal/gt/report_html.h"

#include <fmt/format.h>

#include <cmath>
#include <string>
#include <vector>

#include "rigcal/report/html.h"
#include "rigcal/report/svg_plot.h"

namespace rigcal::gt {
namespace {

using nlohmann::json;
using report::html_escape;
using report::html_number;

// The RMS of a {rms, median, max} statistic in mm ("-" when there is none: null).
std::string rms(const json& s) {
  return s.is_object() ? html_number(s["rms"], "{:.1f}", 1e3) : "-";
}

// The RMS of a {rms, median, max} statistic in deg ("-" when there is none: null).
std::string rms_deg(const json& s) { return s.is_object() ? html_number(s["rms"], "{:.3f}") : "-"; }

// "median / max" of a {rms, median, max} statistic, scaled.
std::string median_max(const json& s, const char* format, double scale) {
  if (!s.is_object()) return "-";
  return html_number(s["median"], format, scale) + " / " + html_number(s["max"], format, scale);
}

std::string priors_section(const json& r) {
  std::string out =
      "<h2 id=\"priors\">GNSS priors</h2>\n<p>Each prior's residual after the solve: the pose's "
      "antenna position less the fix, in the local ENU frame. A prior is rejected when its "
      "squared Mahalanobis distance exceeds the chi-square gate of its 3 degrees of freedom; the "
      "graph is then solved again without it.</p>\n";
  report::PlotSeries h{"horizontal", {}, {}, {}}, v{"vertical", {}, {}, {}},
      rejected{"rejected (horizontal)", {}, {}, {}};
  std::vector<std::vector<std::string>> rows;
  double t0 = NAN;
  for (const json& p : r["priors"]) {
    const double t = std::stod(p["stamp_s"].get<std::string>());
    if (std::isnan(t0)) t0 = t;
    const json& e = p["residual_enu_m"];
    const double horizontal = 1e3 * std::hypot(e[0].get<double>(), e[1].get<double>());
    if (p.value("rejected", false)) {
      rejected.x.push_back(t - t0), rejected.y.push_back(horizontal);
      rows.push_back(
          {html_escape(p["stamp_s"].get<std::string>()), html_number(p["pose"], "{:.0f}"),
           fmt::format("{}, {}, {}", html_number(e[0], "{:.1f}", 1e3),
                       html_number(e[1], "{:.1f}", 1e3), html_number(e[2], "{:.1f}", 1e3)),
           html_number(p["mahalanobis2"], "{:.1f}")});
    } else {
      h.x.push_back(t - t0), h.y.push_back(horizontal);
      v.x.push_back(t - t0), v.y.push_back(1e3 * std::abs(e[2].get<double>()));
    }
  }
  if (!h.x.empty() || !rejected.x.empty()) {
    h.points = v.points = rejected.points = true;
    report::Plot plot{"The GNSS priors' residuals",
                      "time since the first prior [s]",
                      "|residual| [mm]",
                      "",
                      {h, v}};
    if (!rejected.x.empty()) plot.series.push_back(rejected);
    out += report::html_plot_figure(
        plot,
        "Each prior's residual along the recording, horizontal and vertical; the "
        "rejected ones in their own colour.");
  }
  if (rows.empty()) {
    out += "<p>No prior was rejected.</p>\n";
  } else {
    out += fmt::format("<p>{} rejected prior{}:</p>\n", rows.size(), rows.size() == 1 ? "" : "s");
    out += report::html_table(
        {"stamp [s]", "pose", "residual east, north, up [mm]", "Mahalanobis distance squared"},
        rows);
  }
  return out;
}

std::string bundle_section(const json& b) {
  if (!b.is_object()) return "";
  std::string out = "<h2 id=\"bundle\">LiDAR bundle adjustment</h2>\n";
  if (b["point_plane_rms_before_m"].is_object()) {
    out += fmt::format(
        "<p>{} windows of {} keyframes in {} s. Points off their planes (RMS, median over the "
        "windows): {} mm before, {} mm after; the poses moved {} mm and {} deg (RMS) from the pose "
        "graph's.</p>\n",
        html_number(b["windows"], "{:.0f}"), html_number(b.value("keyframes", json()), "{:.0f}"),
        html_number(b["seconds"], "{:.1f}"),
        html_number(b["point_plane_rms_before_m"]["median"], "{:.2f}", 1e3),
        html_number(b["point_plane_rms_after_m"]["median"], "{:.2f}", 1e3),
        html_number(b["pose_change_from_stage1_m"]["rms"], "{:.1f}", 1e3),
        html_number(b["rotation_change_from_stage1_deg"]["rms"], "{:.3f}"));
  }
  report::PlotSeries before{"before", {}, {}, {}}, after{"after", {}, {}, {}};
  size_t k = 0;
  for (const json& w : b.value("per_window", json::array())) {
    before.x.push_back(k), after.x.push_back(k);
    before.y.push_back(1e3 * w.value("point_plane_rms_before_m", NAN));
    after.y.push_back(1e3 * w.value("point_plane_rms_after_m", NAN));
    ++k;
  }
  if (k > 0) {
    before.points = after.points = true;
    out += report::html_plot_figure(
        report::Plot{"Points off their planes, each window",
                     "window",
                     "point-to-plane RMS [mm]",
                     "",
                     {before, after}},
        "Each window's point-to-plane RMS before and after its adjustment: a "
        "window that does not come down is one whose scans did not agree.");
  }
  return out;
}

// The paper's validation of its ground truth: marker distances within 3 cm of a total station's.
constexpr double kMarkerBar_m = 0.03;

std::string markers_section(const json& m) {
  if (!m.is_object()) return "";
  std::string out = fmt::format(
      "<h2 id=\"markers\">Markers against the survey</h2>\n<p>{} of {} markers found in the map "
      "(a bright cluster assigned to a surveyed marker when every distance it takes part in is "
      "within {} mm); the distances between them against the surveyed ones: RMS {} mm, max {} mm. "
      "The bar is VBR's validation of its ground truth, &plusmn;{:.0f} mm; the 1-sigma is the "
      "distance's from the markers' centres in the map.</p>\n",
      html_number(m["found"], "{:.0f}"), html_number(m["markers"], "{:.0f}"),
      html_number(m["tolerance_m"], "{:.0f}", 1e3),
      html_number(m["distance_error_rms_m"], "{:.1f}", 1e3),
      html_number(m["distance_error_max_m"], "{:.1f}", 1e3), 1e3 * kMarkerBar_m);
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> classes;
  for (const json& p : m.value("pairs", json::array())) {
    const double error = p.value("error_m", NAN);
    const bool within = std::abs(error) <= kMarkerBar_m;
    rows.push_back({html_escape(p["a"].get<std::string>() + " - " + p["b"].get<std::string>()),
                    html_number(p["measured_m"], "{:.4f}"), html_number(p["estimated_m"], "{:.4f}"),
                    html_number(p["error_m"], "{:+.1f}", 1e3),
                    html_number(p["sigma_m"], "{:.1f}", 1e3),
                    report::html_badge(within ? "ok" : "failed")});
    classes.push_back(within ? "" : "bad");
  }
  out += report::html_table(
      {"markers", "surveyed [m]", "in the map [m]", "error [mm]", "1-sigma [mm]", "within the bar"},
      rows, classes);
  return out;
}

}  // namespace

std::string trajectory_top_svg(const PoseGraphResult& g) {
  report::PlotSeries path{"", {}, {}, {}}, rejected{"", {}, {}, {}};
  for (size_t k = 0; k < g.T_enu_lidar.size(); ++k) {
    path.x.push_back(g.T_enu_lidar.T_world_body[k].t.x());
    path.y.push_back(g.T_enu_lidar.T_world_body[k].t.y());
    path.values.push_back(k < g.covariance.size()
                              ? 1e3 * std::sqrt(g.covariance[k](3, 3) + g.covariance[k](4, 4))
                              : NAN);
  }
  for (const PriorResidual& p : g.priors) {
    if (!p.rejected || p.node >= g.T_enu_lidar.size()) continue;
    rejected.x.push_back(g.T_enu_lidar.T_world_body[p.node].t.x());
    rejected.y.push_back(g.T_enu_lidar.T_world_body[p.node].t.y());
  }
  report::Plot plot{"The ground truth from above", "east [m]", "north [m]",
                    "horizontal 1-sigma [mm]",     {path},     true};
  if (!rejected.x.empty()) {
    rejected.label = fmt::format("rejected priors ({})", rejected.x.size());
    rejected.points = true;
    plot.series.push_back(rejected);
  }
  return report::render_svg(plot);
}

std::string ground_truth_html(const json& r, const std::string& top_view_svg) {
  const json& s = r["summary"];
  std::string body = "<h1>Ground truth</h1>\n";
  body += fmt::format(
      "<p>{}; scans <code>{}</code>, GNSS <code>{}</code>, rig <code>{}</code>.</p>\n",
      html_escape(r["tool"]["version"].get<std::string>()),
      html_escape(r["inputs"].value("scans", "")), html_escape(r["inputs"].value("gnss", "")),
      html_escape(r["inputs"].value("rig", "")));
  // The verdict: the markers against their bar, then what the data leave undetermined.
  const json m = r.contains("markers") ? r["markers"] : json();
  const json& undetermined = s["undetermined"];
  std::string headline, cls = "good";
  if (m.is_object() && m["distance_error_max_m"].is_number()) {
    const bool within = m["distance_error_max_m"].get<double>() <= kMarkerBar_m;
    headline = fmt::format(
        "Markers: {} of {} found; their distances {} the survey's by at most {} mm (RMS {} mm; "
        "the bar &plusmn;{:.0f} mm)",
        html_number(m["found"], "{:.0f}"), html_number(m["markers"], "{:.0f}"),
        within ? "agree with" : "are OUTSIDE the bar against",
        html_number(m["distance_error_max_m"], "{:.1f}", 1e3),
        html_number(m["distance_error_rms_m"], "{:.1f}", 1e3), 1e3 * kMarkerBar_m);
    if (!within) cls = "bad";
    if (cls == "good" && m["found"] != m["markers"]) cls = "unsure";
  } else {
    headline = "No markers surveyed: the trajectory's accuracy is what its sigmas say";
    cls = "unsure";
  }
  if (undetermined.is_array() && !undetermined.empty()) {
    headline += fmt::format("; {} thing{} the data do not determine (below)", undetermined.size(),
                            undetermined.size() == 1 ? "" : "s");
    if (cls == "good") cls = "unsure";
  }
  body += fmt::format("<p class=\"headline {}\">{}</p>\n", cls, headline);
  if (undetermined.is_array() && !undetermined.empty()) {
    body += "<ul class=\"warning\">\n";
    for (const json& u : undetermined) {
      body += fmt::format("<li><b>{}</b>: {}</li>\n", html_escape(u["what"].get<std::string>()),
                          html_escape(u["why"].get<std::string>()));
    }
    body += "</ul>\n";
  }
  std::vector<std::vector<std::string>> rows = {
      {"poses, path", fmt::format("{} poses, {} m", html_number(s["poses"], "{:.0f}"),
                                  html_number(s["path_length_m"], "{:.1f}"))},
      {"fixes",
       fmt::format("{} ({} RTK fixed, {} not used as priors)", html_number(s["fixes"], "{:.0f}"),
                   html_number(s["fixes_rtk_fixed"], "{:.0f}"),
                   html_number(s["fixes_unused"], "{:.0f}"))},
      {"priors", fmt::format("{} ({} rejected)", html_number(s["priors"], "{:.0f}"),
                             html_number(s["priors_rejected"], "{:.0f}"))},
      {"prior residuals, horizontal / vertical RMS [mm]",
       fmt::format("{} / {}", rms(s["prior_residual_horizontal_m"]),
                   rms(s["prior_residual_vertical_m"]))},
      {"the fixes' error correlation time",
       fmt::format("{} s ({})", html_number(s["fix_correlation_s"], "{:.1f}"),
                   html_escape(s.value("fix_correlation", "")))},
      {"the fixes' errors",
       s.value("fix_white_share", 0.0) > 0
           ? fmt::format("{}, {} of their variance white", html_escape(s.value("fix_model", "")),
                         html_number(s["fix_white_share"], "{:.2g}"))
           : html_escape(s.value("fix_model", ""))},
      {"pose 1-sigma, horizontal median / max [mm]",
       median_max(s["pose_sigma_horizontal_m"], "{:.1f}", 1e3)},
      {"pose 1-sigma, vertical median / max [mm]",
       median_max(s["pose_sigma_vertical_m"], "{:.1f}", 1e3)},
      {"pose 1-sigma, yaw median / max [deg]", median_max(s["pose_sigma_yaw_deg"], "{:.3f}", 1)},
  };
  if (const json a = s.value("attitudes", json()); a.is_object()) {
    rows.push_back(
        {"GNSS/INS attitudes (priors on the rotation)",
         fmt::format("{} priors ({} rejected); 1-sigma tilt {} deg, heading {} deg, correlated "
                     "over {} s",
                     html_number(a["priors"], "{:.0f}"),
                     html_number(a["priors_rejected"], "{:.0f}"),
                     html_number(a["sigma_tilt_deg"], "{:.3g}"),
                     html_number(a["sigma_heading_deg"], "{:.3g}"),
                     html_number(a["correlation_s"], "{:.3g}"))});
    rows.push_back({"attitude residuals, tilt / heading RMS [deg]",
                    fmt::format("{} / {}", rms_deg(a["residual_tilt_deg"]),
                                rms_deg(a["residual_heading_deg"]))});
  }
  for (const json& o : s.value("outages", json::array())) {
    rows.push_back({"outage", fmt::format("{} s without a fix from {} s, bridged by the odometry",
                                          html_number(o["duration_s"], "{:.1f}"),
                                          html_escape(o["from_s"].get<std::string>()))});
  }
  body +=
      "<h2 id=\"summary\">The trajectory</h2>\n" + report::html_table({"quantity", "value"}, rows);
  if (!top_view_svg.empty()) {
    body += report::html_figure(
        report::html_inline_svg(top_view_svg),
        "The ground truth's LiDAR positions in the local ENU frame, coloured by their horizontal "
        "1-sigma: where it grows, the GNSS was out or rejected.");
  }
  if (r.contains("markers")) body += markers_section(r["markers"]);
  body += priors_section(r);
  if (r.contains("bundle_adjustment")) body += bundle_section(r["bundle_adjustment"]);
  if (!r["notes"].empty()) {
    body += "<h2 id=\"notes\">Notes</h2>\n<ul class=\"note\">\n";
    for (const json& n : r["notes"]) body += "<li>" + html_escape(n.get<std::string>()) + "</li>\n";
    body += "</ul>\n";
  }
  return report::html_page("rigcal ground-truth", body);
}

}  // namespace rigcal::gt
