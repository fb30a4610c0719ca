// The pages a person reads for `rigcal diff` and `rigcal check` (diff.h, check.h), rendered from
// their stored JSON: every number with its unit and what it means, the verdicts first.
#include "rigcal/gt/report_html.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "rigcal/core/error.h"
#include "rigcal/io/files.h"
#include "rigcal/report/html.h"
#include "rigcal/session/check.h"
#include "rigcal/session/diff.h"
#include "rigcal/session/report_html.h"

namespace rigcal::session {
namespace {

using report::html_escape;
using Figures = NamedFigures;

using report::html_number;

// "x, y, z" of a 3-vector.
std::string triple(const nlohmann::json& v, const char* format) {
  return fmt::format("{}, {}, {}", html_number(v[0], format), html_number(v[1], format),
                     html_number(v[2], format));
}

std::string significance_text(const nlohmann::json& s) {
  if (s.is_null()) return "<span class=\"note\">no sigmas stored</span>";
  const double p = s["p_value"];
  return fmt::format("&chi;&sup2; {:.2f} over {}, p {:.3g}{}", s["chi2"].get<double>(),
                     s["dof"].get<int>(), p, p < 1e-3 ? " " + report::html_badge("changed") : "");
}

}  // namespace

std::string diff_html_sections(const nlohmann::json& d, const Figures& figures) {
  std::string out;
  out += fmt::format(
      "<h2 id=\"poses\">Poses</h2>\n<p>Each relation <code>T_a_b</code> (frame b in frame a): the "
      "rotation <code>Log(R_B R_A')</code> about a's axes in degrees, the translation "
      "<code>t_B - t_A</code> in a, in millimetres; the sensors' poses compared in "
      "<b>{}</b>. Where the calibrations store sigmas, the chi-square of the components over "
      "the combined sigmas and its probability if nothing changed (p &lt; 0.001: "
      "changed).</p>\n",
      html_escape(d["base_frame"].get<std::string>()));
  std::vector<std::vector<std::string>> rows;
  for (const nlohmann::json& p : d["poses"]) {
    rows.push_back(
        {"<code>" + html_escape(p["relation"].get<std::string>()) + "</code>",
         triple(p["rotation_deg"], "{:.4f}"), html_number(p["rotation_angle_deg"], "{:.4f}"),
         triple(p["translation_mm"], "{:.2f}"), html_number(p["translation_norm_mm"], "{:.2f}"),
         significance_text(p["significance"])});
  }
  out += report::html_table({"relation", "rotation x, y, z [deg]", "angle [deg]",
                             "translation x, y, z [mm]", "norm [mm]", "significance"},
                            rows);
  out +=
      "<h2 id=\"clocks\">Clocks</h2>\n<p>Each sensor's clock against the reference sensor's "
      "(its time offset less the reference's; B's less A's), in milliseconds; the drift in "
      "ppm.</p>\n";
  rows.clear();
  for (const nlohmann::json& c : d["clocks"]) {
    rows.push_back({html_escape(c["sensor"].get<std::string>()),
                    html_number(c["offset_ms"], "{:+.4f}"), html_number(c["drift_ppm"], "{:+.3f}"),
                    significance_text(c["significance"])});
  }
  out += report::html_table({"sensor", "offset [ms]", "drift [ppm]", "significance"}, rows);
  out +=
      "<h2 id=\"cameras\">Cameras</h2>\n<p>The intrinsics' differences (B - A, px; distortion "
      "unitless), and the projection difference: each pixel's ray by A's lens projected by "
      "B's, over a grid of the image, raw and with the best rotation of the camera taken out "
      "(what re-estimating the camera's pose absorbs).</p>\n";
  for (const nlohmann::json& c : d["cameras"]) {
    const std::string name = c["camera"];
    std::vector<std::string> parts;
    for (const auto& [k, v] : c["intrinsics_b_minus_a"].items())
      parts.push_back(fmt::format("{} {:+.4g}", k, v.get<double>()));
    out += fmt::format("<h3>{}</h3>\n<p>{}; {}</p>\n", html_escape(name),
                       html_escape(fmt::format("{}", fmt::join(parts, ", "))),
                       significance_text(c["significance"]));
    const nlohmann::json& p = c["projection"];
    if (p.is_null()) {
      out += "<p class=\"note\">" + html_escape(c["note"].get<std::string>()) + "</p>\n";
      continue;
    }
    out += report::html_table(
        {"projection difference", "rms [px]", "max [px]"},
        {{"raw (the same rays)", html_number(p["raw_rms_px"], "{:.3f}"),
          html_number(p["raw_max_px"], "{:.3f}")},
         {fmt::format("the camera's rotation taken out ({:.4f} deg)",
                      p["fitted_rotation_deg"].get<double>()),
          html_number(p["fitted_rms_px"], "{:.3f}"), html_number(p["fitted_max_px"], "{:.3f}")}});
    const std::string file = fmt::format("projection_diff_{}.svg", name);
    for (const auto& [figure, svg] : figures) {
      if (figure != file) continue;
      out += report::html_figure(
          report::html_inline_svg(svg),
          fmt::format("{}: |projection difference| over the image, every {:g} px, with the "
                      "camera's rotation taken out (colour bar in px)",
                      html_escape(name), p["grid_step_px"].get<double>()));
    }
  }
  for (const char* side : {"only_in_a", "only_in_b"}) {
    if (d[side].empty()) continue;
    out += fmt::format("<p>Sensors {}: {}</p>\n",
                       std::string_view(side) == "only_in_a" ? "only in A" : "only in B",
                       html_escape(fmt::format("{}", fmt::join(d[side], ", "))));
  }
  for (const nlohmann::json& n : d["notes"])
    out += "<p class=\"note\">Note: " + html_escape(n.get<std::string>()) + "</p>\n";
  out += "<p class=\"note\">" + html_escape(d["significance_note"].get<std::string>()) + "</p>\n";
  return out;
}

std::string diff_html(const nlohmann::json& d, const Figures& figures) {
  return report::html_page("rigcal diff",
                           "<h1>Two calibrations compared</h1>\n" + diff_html_sections(d, figures));
}

std::string check_html(const nlohmann::json& c, const Figures& figures) {
  const int status = c["exit_status"];
  std::string body = "<h1>Does the calibration still fit?</h1>\n";
  body += fmt::format(
      "<p>Calibration <code>{}</code> checked against the session <code>{}</code> "
      "({}).</p>\n",
      html_escape(c["calibration"].get<std::string>()),
      html_escape(c["session"].get<std::string>()),
      html_escape(c["tool_version"].get<std::string>()));
  const std::vector<std::string> suspects = c["suspects"];
  body += fmt::format(
      "<p class=\"headline {}\">{}</p>\n",
      status == 3   ? "bad"
      : status == 0 ? "good"
                    : "unsure",
      status == 3 ? html_escape(fmt::format("Something changed: {}", fmt::join(suspects, ", ")))
      : status == 0
          ? "Consistent: nothing changed where the new data can tell"
          : "A step failed on the new session: the verdicts below are what it could tell");
  body += fmt::format(
      "<h2 id=\"verdicts\">Each quantity</h2>\n<p>Each quantity a calibration step estimated, "
      "re-estimated on the new session and compared with the stored value through both sigmas. "
      "<b>changed</b>: the chi-square's probability below {:g}; <b>cannot tell</b>: the new data "
      "do not determine it. The last column is the smallest change along one component this "
      "check flags.</p>\n",
      c["alarm_p"].get<double>());
  std::vector<std::vector<std::string>> rows;
  for (const nlohmann::json& v : c["verdicts"]) {
    const std::string verdict = v["verdict"];
    rows.push_back({html_escape(v["quantity"].get<std::string>()),
                    html_escape(v["step"].get<std::string>()), report::html_badge(verdict),
                    html_escape(verdict == "cannot tell" ? v["reason"].get<std::string>()
                                                         : v["change"].get<std::string>()),
                    verdict == "cannot tell"
                        ? "-"
                        : fmt::format("{:.2f} / {}", v["chi2"].get<double>(), v["dof"].get<int>()),
                    verdict == "cannot tell" ? "-" : html_number(v["p_value"], "{:.3g}"),
                    html_escape(v["detectable"].get<std::string>())});
  }
  body += report::html_table({"quantity", "step", "verdict", "change (or why not)", "chi² / dof",
                              "p", "smallest change flagged"},
                             rows);
  if (c.contains("residual_levels") && !c["residual_levels"].empty()) {
    body +=
        "<h2 id=\"levels\">The new data at the stored calibration</h2>\n<p>The new session's "
        "boards fitted with the stored parameters held (only the boards' poses free), beside the "
        "level the calibration reached on its own data and the level the re-estimate reaches on "
        "the new data. A bumped lens or a moved sensor shows as a level at the stored "
        "calibration above both.</p>\n";
    rows.clear();
    for (const nlohmann::json& l : c["residual_levels"]) {
      const std::string unit = l["unit"];
      rows.push_back(
          {html_escape(l["step"].get<std::string>()),
           html_escape(l["what"].get<std::string>() + (unit.empty() ? "" : " [" + unit + "]")),
           html_number(l["at_stored"], "{:.4g}"), html_number(l["stored"], "{:.4g}"),
           html_number(l["reestimated"], "{:.4g}")});
    }
    body += report::html_table({"step", "residual", "at the stored calibration",
                                "the calibration's own", "re-estimated on the new data"},
                               rows);
  }
  if (!c["hypotheses"].empty()) {
    body +=
        "<h2 id=\"which\">Which sensor moved</h2>\n<p>Each sensor of the changed relations "
        "moved alone (the stored rig with that sensor moved by the rotation and translation "
        "that best explain every judged relation of the re-estimate): what is left is its "
        "chi-square; the lowest names the sensor.</p>\n";
    rows.clear();
    for (const nlohmann::json& h : c["hypotheses"]) {
      rows.push_back({html_escape(h["sensor"].get<std::string>()),
                      fmt::format("{:.2f} / {}", h["chi2"].get<double>(), h["dof"].get<int>()),
                      html_number(h["p_value"], "{:.3g}")});
    }
    body += report::html_table({"moved alone", "chi² / dof", "p"}, rows);
    if (c["hypotheses"].size() > 1 && c["likelihood_ratio"].is_number()) {
      const double ratio = c["likelihood_ratio"];
      body +=
          fmt::format("<p>{} moving alone is {:.3g} times as likely as {} moving alone{}.</p>\n",
                      html_escape(c["hypotheses"][0]["sensor"].get<std::string>()), ratio,
                      html_escape(c["hypotheses"][1]["sensor"].get<std::string>()),
                      ratio < 20 ? ": the data barely tell them apart" : "");
    }
  }
  body += "<h2 id=\"steps\">The steps on the new session</h2>\n";
  rows.clear();
  for (const nlohmann::json& s : c["steps"]) {
    rows.push_back({html_escape(s["step"].get<std::string>()),
                    report::html_badge(s["status"].get<std::string>()),
                    html_escape(s["reason"].get<std::string>()),
                    html_escape(s["remedy"].get<std::string>())});
  }
  body += report::html_table({"step", "status", "reason", "what would settle it"}, rows);
  body += diff_html_sections(c["difference"], figures);
  return report::html_page("rigcal check", body);
}

io::OutputFile render_report(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  Figures figures;
  if (fs::is_directory(dir)) {
    for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
      const std::string name = e.path().filename().string();
      if (name.rfind("projection_diff_", 0) == 0 && e.path().extension() == ".svg")
        figures.emplace_back(name, io::read_text_file(e.path()));
    }
  }
  std::sort(figures.begin(), figures.end());
  if (fs::exists(dir / "reports" / "calibrate.json"))
    return {dir / "report.html", calibrate_html(dir)};
  if (fs::exists(dir / "run.json")) return {dir / "report.html", step_html(dir)};
  if (fs::exists(dir / "ground_truth.json")) {
    const fs::path top = dir / "trajectory_top.svg";
    try {
      return {dir / "report.html",
              gt::ground_truth_html(
                  nlohmann::json::parse(io::read_text_file(dir / "ground_truth.json")),
                  fs::exists(top) ? io::read_text_file(top) : "")};
    } catch (const nlohmann::json::exception& e) {
      throw Error(fmt::format("{}: not a report rigcal wrote: {}",
                              (dir / "ground_truth.json").string(), e.what()));
    }
  }
  for (const char* name : {"check.json", "diff.json"}) {
    const fs::path json = dir / name;
    if (!fs::exists(json)) continue;
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(io::read_text_file(json));
      return {dir / "report.html",
              std::string(name) == "check.json" ? check_html(j, figures) : diff_html(j, figures)};
    } catch (const nlohmann::json::exception& e) {
      throw Error(fmt::format("{}: not a report rigcal wrote: {}", json.string(), e.what()));
    }
  }
  throw Error(
      fmt::format("{}: no reports/calibrate.json, run.json, ground_truth.json, check.json or "
                  "diff.json to render (rigcal calibrate writes the first in its --out folder; "
                  "the step commands, ground-truth, check and diff the others with --report)",
                  dir.string()));
}

}  // namespace rigcal::session
