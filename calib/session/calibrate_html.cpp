// The page a person reads for `rigcal calibrate` (report_html.h): the verdict first, then each
// step's numbers with their sigmas, its warnings, its figures and where its inputs came from,
// rendered from OUT/reports/ alone.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "rigcal/core/error.h"
#include "rigcal/io/files.h"
#include "rigcal/report/html.h"
#include "rigcal/report/svg_plot.h"
#include "rigcal/session/report_html.h"

namespace rigcal::session {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using report::html_escape;

using report::html_number;

// "v ± s" for each of three components, scaled (m to mm: 1e3).
std::string with_sigmas(const json& v, const json& s, const char* format, double scale) {
  std::vector<std::string> parts;
  for (int i = 0; i < 3; ++i) {
    parts.push_back(html_number(v[i], format, scale) + " ± " +
                    (s.is_array() ? html_number(s[i], format, scale) : std::string("?")));
  }
  return fmt::format("{}", fmt::join(parts, ", "));
}

// A rotation stored as {"angle_deg", "axis"} with its left-tangent sigmas about `frame`'s axes.
std::string rotation_cell(const json& axis_angle, const json& sigma_deg, std::string_view frame) {
  if (!axis_angle.is_object()) return "-";
  return fmt::format(
      "{} deg about [{}, {}, {}]; 1-sigma as small rotations about {}'s x, y, z: {}, {}, {} deg",
      html_number(axis_angle["angle_deg"], "{:.4f}"), html_number(axis_angle["axis"][0], "{:.4f}"),
      html_number(axis_angle["axis"][1], "{:.4f}"), html_number(axis_angle["axis"][2], "{:.4f}"),
      html_escape(frame), html_number(sigma_deg[0], "{:.4f}"), html_number(sigma_deg[1], "{:.4f}"),
      html_number(sigma_deg[2], "{:.4f}"));
}

// A PNG of the step's folder inline, when it is there.
std::string png_figure(const fs::path& file, const std::string& caption) {
  if (!fs::exists(file)) return "";
  return report::html_figure(
      report::html_inline_image(io::read_text_file(file), file.filename().string()), caption);
}

std::string list(const json& lines, const char* cls) {
  if (!lines.is_array() || lines.empty()) return "";
  std::string out = fmt::format("<ul class=\"{}\">\n", cls);
  for (const json& l : lines) out += "<li>" + html_escape(l.get<std::string>()) + "</li>\n";
  return out + "</ul>\n";
}

// The step's own inputs as its JSON names them.
std::string inputs_table(const json& inputs) {
  if (!inputs.is_object()) return "";
  std::vector<std::vector<std::string>> rows;
  for (const auto& [k, v] : inputs.items()) {
    if (k == "notes") continue;
    rows.push_back({html_escape(k), html_escape(v.is_string() ? v.get<std::string>() : v.dump())});
  }
  return "<details><summary>Inputs</summary>\n" + report::html_table({"input", "value"}, rows) +
         "</details>\n";
}

// ---------------------------------------------------------------------------------------------
// cameras

struct CornerRow {
  std::string camera;
  double u, v, ru, rv;
  bool outlier;
};

std::vector<CornerRow> read_residuals_csv(const fs::path& file) {
  std::vector<CornerRow> rows;
  if (!fs::exists(file)) return rows;
  std::istringstream in(io::read_text_file(file));
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) f.push_back(cell);
    if (f.size() != 8) continue;
    rows.push_back(
        {f[0], std::stod(f[3]), std::stod(f[4]), std::stod(f[5]), std::stod(f[6]), f[7] == "1"});
  }
  return rows;
}

std::string camera_figures(const std::string& name, const json& cam,
                           const std::vector<CornerRow>& corners, const fs::path& dir) {
  const double w = cam["model"]["resolution"][0], h = cam["model"]["resolution"][1];
  report::PlotSeries inliers{"", {}, {}, {}}, outliers{"", {}, {}, {}};
  report::PlotSeries vectors{"inlier corners", {}, {}, {}}, far{"outliers", {}, {}, {}};
  std::vector<double> norms;
  double ss = 0;
  for (const CornerRow& c : corners) {
    if (c.camera != name) continue;
    const double n = std::hypot(c.ru, c.rv);
    report::PlotSeries& at = c.outlier ? outliers : inliers;
    at.x.push_back(c.u), at.y.push_back(c.v);
    if (!c.outlier) at.values.push_back(n), norms.push_back(n), ss += n * n;
    report::PlotSeries& vec = c.outlier ? far : vectors;
    vec.x.push_back(c.ru), vec.y.push_back(c.rv);
  }
  if (norms.empty()) return "";
  const double rms = std::sqrt(ss / norms.size());
  std::string out;
  outliers.label = fmt::format("outliers ({})", outliers.x.size());
  outliers.points = true;
  report::Plot over{fmt::format("{}: inlier corners' |residual|, RMS {:.3f} px ({} corners)", name,
                                rms, norms.size()),
                    "u [px]",
                    "v [px]",
                    "|residual| [px]",
                    {inliers},
                    true,
                    false,
                    true,
                    {0, w, 0, h}};
  if (!outliers.x.empty()) over.series.push_back(outliers);
  out += report::html_plot_figure(
      over, fmt::format("Every detected corner where it lies in {}'s image ({:g} x {:g} px), "
                        "coloured by its residual (projected less observed). Parts of the image "
                        "without corners are where the lens model is extrapolated.",
                        html_escape(name), w, h));
  // The residual vectors, with the RMS as a reference circle.
  report::PlotSeries circle{fmt::format("RMS {:.3f} px", rms), {}, {}, {}};
  for (int k = 0; k <= 64; ++k) {
    circle.x.push_back(rms * std::cos(2 * M_PI * k / 64));
    circle.y.push_back(rms * std::sin(2 * M_PI * k / 64));
  }
  vectors.points = far.points = true;
  report::Plot scatter{fmt::format("{}: residual vectors", name),
                       "x residual [px]",
                       "y residual [px]",
                       "",
                       {vectors, circle},
                       true};
  if (!far.x.empty()) scatter.series.push_back(far);
  out += report::html_plot_figure(
      scatter, fmt::format("{}'s residuals (projected less observed), one point a corner, "
                           "the circle at their RMS: a round cloud centred at zero is noise; "
                           "a shape or an offset is a model error.",
                           html_escape(name)));
  // The histogram of |residual| against the Rayleigh density the RMS implies for isotropic
  // Gaussian noise.
  const double top = *std::max_element(norms.begin(), norms.end());
  const int bins = 30;
  const double width = std::max(top, 1e-9) / bins;
  report::PlotSeries hist{"corners", {}, {}, {}},
      model{"isotropic Gaussian of this RMS", {}, {}, {}};
  std::vector<double> counts(bins + 1, 0.0);
  for (double n : norms) counts[std::min(bins - 1, static_cast<int>(n / width))] += 1;
  for (int b = 0; b <= bins; ++b) hist.x.push_back(b * width), hist.y.push_back(counts[b]);
  const double s2 = rms * rms / 2;  // per-coordinate variance
  for (int b = 0; b <= 4 * bins; ++b) {
    const double r = (b + 0.5) * width / 4;
    model.x.push_back(r);
    model.y.push_back(norms.size() * width * r / s2 * std::exp(-r * r / (2 * s2)));
  }
  report::Plot histogram{fmt::format("{}: |residual| of the inlier corners", name),
                         "|residual| [px]",
                         "corners a bin",
                         "",
                         {hist, model}};
  histogram.step = true;
  out += report::html_plot_figure(
      histogram,
      "Counts of |residual| in 30 bins, and the Rayleigh curve that isotropic "
      "Gaussian noise of the same RMS gives: a heavier tail is outliers the "
      "rejection kept or a lens the model does not fit.");
  const json& u = cam["projection_uncertainty"];
  if (u.is_object() && u.contains("grid")) {
    const json& g = u["grid"];
    report::PlotGrid grid;
    grid.cols = g["cols"], grid.rows = g["rows"], grid.cell = g["cell_px"];
    grid.values = g["sigma_px"].get<std::vector<double>>();
    // Contours at 1-2-5 steps inside the map's range.
    const auto [lo, hi] = std::minmax_element(grid.values.begin(), grid.values.end());
    for (double decade = 1e-3; decade < 1e3; decade *= 10) {
      for (const double m : {1.0, 2.0, 5.0}) {
        if (m * decade > *lo && m * decade < *hi) grid.contours.push_back(m * decade);
      }
    }
    report::Plot map{
        fmt::format("{}: projection 1-sigma at {} m", name, html_number(u["distance_m"], "{:.2f}")),
        "u [px]",
        "v [px]",
        "1-sigma [px]",
        {},
        true,
        false,
        true,
        {0, w, 0, h}};
    map.grid = grid;
    map.series.push_back(inliers);
    map.series.back().values.clear();
    map.series.back().label = "corners";
    map.series.back().points = true;
    out += report::html_plot_figure(
        map, fmt::format("{}: the 1-sigma of a pixel's projection over the image (mrcal's "
                         "definition: the whole covariance, the boards' poses included, for a "
                         "point at the boards' median distance), contours at 1-2-5 steps, the "
                         "corners over it: it is small where the boards were.",
                         html_escape(name)));
  } else {
    out += png_figure(dir / (name + "_uncertainty.png"),
                      fmt::format("{}: projection 1-sigma over the image (mrcal's definition, at "
                                  "the boards' median distance), yellow the largest.",
                                  html_escape(name)));
  }
  out +=
      png_figure(dir / (name + "_corners.png"),
                 fmt::format("{}: the corners detected on the first image that shows the target.",
                             html_escape(name)));
  return out;
}

std::string cameras_section(const json& j, const fs::path& dir) {
  std::string out = fmt::format(
      "<p>{} residuals of {} parameters; RMS {} px (OpenCV's definition, 2-D), {} px a "
      "coordinate (mrcal's); noise 1-sigma {} px a coordinate; {} outlier corners left out.</p>\n",
      html_number(j["n_residuals"], "{:.0f}"), html_number(j["n_parameters"], "{:.0f}"),
      html_number(j["rms_2d_px"], "{:.4f}"), html_number(j["rms_per_coordinate_px"], "{:.4f}"),
      html_number(j["noise_sigma_px"], "{:.4f}"), html_number(j["n_outliers"], "{:.0f}"));
  std::vector<std::vector<std::string>> rows;
  for (const json& cam : j["cameras"]) {
    const json& m = cam["model"];
    const json& sd = cam["stddev"];
    std::vector<std::string> intr;
    static const char* kNames[] = {"fx", "fy", "cx", "cy"};
    for (int i = 0; i < 4; ++i) {
      intr.push_back(fmt::format("{} {} ± {}", kNames[i], html_number(m["intrinsics"][i], "{:.3f}"),
                                 html_number(sd["intrinsics"][i], "{:.3f}")));
    }
    std::vector<std::string> dist;
    for (size_t i = 0; i < m["distortion_coeffs"].size(); ++i) {
      dist.push_back(fmt::format("{} ± {}", html_number(m["distortion_coeffs"][i], "{:.5f}"),
                                 html_number(sd["distortion_coeffs"][i], "{:.5f}")));
    }
    const json& u = cam["projection_uncertainty"];
    rows.push_back(
        {html_escape(cam["name"].get<std::string>()),
         html_escape(fmt::format("{}-{}", m["camera_model"].get<std::string>(),
                                 m["distortion_model"].get<std::string>())),
         html_escape(fmt::format("{}", fmt::join(intr, ", "))),
         html_escape(fmt::format("{}", fmt::join(dist, ", "))),
         html_number(cam["n_views"], "{:.0f}") + " / " + html_number(cam["n_corners"], "{:.0f}"),
         fmt::format("{} / {} / {}", html_number(u["mean_px"], "{:.3f}"),
                     html_number(u["max_px"], "{:.3f}"), html_number(u["centre_px"], "{:.3f}"))});
  }
  out += report::html_table({"camera", "model", "intrinsics [px] ± 1-sigma", "distortion ± 1-sigma",
                             "views / corners", "projection 1-sigma mean / max / centre [px]"},
                            rows);
  if (!j["cameras"].empty() && j["cameras"][0]["projection_uncertainty"].is_object()) {
    out += fmt::format(
        "<p class=\"note\">Projection 1-sigma: the uncertainty of a pixel's projection of a point "
        "at {} m (the boards' median distance), from the covariance of every parameter, the "
        "boards' poses included (mrcal's definition).</p>\n",
        html_number(j["cameras"][0]["projection_uncertainty"]["distance_m"], "{:.2f}"));
  }
  for (const json& cam : j["cameras"]) {
    if (!cam.contains("T_cam_cam0")) continue;
    const json& T = cam["T_cam_cam0"];
    const std::string name = cam["name"], from = T["from"];
    out += fmt::format(
        "<p><b>T_{}_{}</b> (the stereo extrinsic, {} in {}): baseline {} mm; translation {} mm; "
        "rotation {}.</p>\n",
        html_escape(name), html_escape(from), html_escape(from), html_escape(name),
        html_number(T["baseline_m"], "{:.2f}", 1e3),
        with_sigmas(T["translation_m"], T["translation_stddev_m"], "{:.2f}", 1e3),
        rotation_cell(T.value("axis_angle", json()), T["rotation_stddev_deg"], name));
  }
  if (j.contains("stereo_rectification") && j["stereo_rectification"].is_object()) {
    const json& r = j["stereo_rectification"];
    out += fmt::format(
        "<p><b>Rectified</b> with this estimate, the {} corners both cameras saw lie on the same "
        "row within {} px RMS (median {} px); the corner noise alone gives about {} px{}.</p>\n",
        html_number(r["corners"], "{:.0f}"), html_number(r["row_difference_rms_px"], "{:.3f}"),
        html_number(r["row_difference_median_abs_px"], "{:.3f}"),
        html_number(r["expected_rms_px"], "{:.3f}"),
        r.value("exceeds_noise", false)
            ? ": <b>more than twice that: the stereo extrinsic or a lens does not fit these "
              "views</b>"
            : "");
    out += png_figure(
        dir / r["figure"].get<std::string>(),
        fmt::format("The view with the most shared corners ({}), rectified: left "
                    "image, then right; each green line is an epipolar line, and a "
                    "corner (red left, blue right) lies on the same line in both "
                    "halves when the calibration is right.",
                    fs::path(r["figure_view_left"].get<std::string>()).filename().string()));
  }
  const std::vector<CornerRow> corners = read_residuals_csv(dir / "residuals.csv");
  for (const json& cam : j["cameras"]) {
    out += fmt::format("<h3>{}</h3>\n", html_escape(cam["name"].get<std::string>()));
    out += camera_figures(cam["name"], cam, corners, dir);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// lidar_camera

// The depth colours of the overlays (0.5 m red to 10 m blue, log scale) as a legend.
std::string depth_legend() {
  std::string out =
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"420\" height=\"46\" "
      "font-family=\"sans-serif\" font-size=\"12\">\n<defs><linearGradient id=\"depth\">";
  for (int i = 0; i <= 8; ++i)
    out += fmt::format("<stop offset=\"{:.3f}\" stop-color=\"hsl({:.0f},100%,50%)\"/>", i / 8.0,
                       240.0 * i / 8.0);
  out +=
      "</linearGradient></defs>\n<rect x=\"10\" y=\"6\" width=\"300\" height=\"14\" "
      "fill=\"url(#depth)\"/>\n";
  for (const double d : {0.5, 1.0, 2.0, 5.0, 10.0}) {
    const double x = 10 + 300 * std::log(d / 0.5) / std::log(20.0);
    out += fmt::format("<text x=\"{:.1f}\" y=\"36\" text-anchor=\"middle\">{:g} m</text>", x, d);
  }
  out +=
      "<circle cx=\"335\" cy=\"13\" r=\"5\" fill=\"none\" stroke=\"black\"/><text x=\"345\" "
      "y=\"17\">board</text>\n</svg>";
  return out;
}

std::string lidar_camera_section(const json& j, const fs::path& dir) {
  const std::string camera = j["inputs"]["camera"];
  const json& T = j["T_camera_lidar"];
  std::string out = fmt::format(
      "<p><b>T_{}_lidar</b> (the LiDAR in {}'s frame): translation {} mm; rotation {}. Noise "
      "scale {} (the residuals' level against their model; sigmas are scaled by it when above "
      "1); the board normals' condition {} (large: the boards' tilts leave a direction "
      "weak).</p>\n",
      html_escape(camera), html_escape(camera),
      with_sigmas(T["t_m"], T["t_sigma_m"], "{:.2f}", 1e3),
      rotation_cell(T.value("axis_angle", json()), T["rotation_sigma_deg"], camera),
      html_number(j["noise_scale"], "{:.2f}"),
      html_number(j["observability"]["condition"], "{:.1f}"));
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> classes;
  report::PlotSeries in_pairs{"pairs", {}, {}, {}}, out_pairs{"outliers", {}, {}, {}},
      gate{"outlier gate: chi-square 16.3 (3 dof, p 0.001)", {}, {}, {}};
  size_t k = 0;
  for (const json& p : j["pairs"]) {
    ++k;
    const bool used = p.value("used", false), outlier = p.value("outlier", false);
    const std::string verdict = !used ? "not used" : outlier ? "outlier" : "ok";
    rows.push_back({std::to_string(k),
                    report::html_badge(verdict == "outlier" ? "failed" : verdict) +
                        (verdict == "outlier" ? " outlier" : ""),
                    html_number(p.value("board_points", json()), "{:.0f}"),
                    html_number(p.value("lidar_plane_rms_m", json()), "{:.1f}", 1e3),
                    html_number(p.value("normal_angle_deg", json()), "{:.3f}"),
                    html_number(p.value("distance_m", json()), "{:.2f}", 1e3),
                    html_number(p.value("chi2", json()), "{:.2f}"),
                    html_escape(p.value("note", std::string()))});
    classes.push_back(outlier ? "bad" : "");
    if (used && p["chi2"].is_number()) {
      (outlier ? out_pairs : in_pairs).x.push_back(k);
      (outlier ? out_pairs : in_pairs).y.push_back(p["chi2"].get<double>());
    }
  }
  out += report::html_table({"pair", "verdict", "board points", "board plane RMS [mm]",
                             "normal angle [deg]", "distance [mm]", "chi-square (3 dof)", "note"},
                            rows, classes);
  if (!in_pairs.x.empty() || !out_pairs.x.empty()) {
    gate.x = {0.5, k + 0.5}, gate.y = {16.27, 16.27};
    in_pairs.points = out_pairs.points = true;
    report::Plot chi{"Each pair's chi-square after the extrinsic",
                     "pair",
                     "chi-square (normal angle and distance over their sigmas)",
                     "",
                     {in_pairs, gate}};
    if (!out_pairs.x.empty()) chi.series.push_back(out_pairs);
    out += report::html_plot_figure(
        chi,
        "How well each board's plane in the camera agrees with its LiDAR points "
        "after the extrinsic; above the gate a pair is an outlier and left out.");
  }
  out +=
      "<p>The overlays: the scan's points projected into the image with the extrinsic, "
      "coloured by depth; the LiDAR points taken as the board ringed.</p>\n" +
      depth_legend() + "\n";
  k = 0;
  for (const json& p : j["pairs"]) {
    ++k;
    const bool used = p.value("used", false), outlier = p.value("outlier", false);
    out += png_figure(dir / fmt::format("pair_{:02d}.png", k),
                      fmt::format("pair {}: {}", k,
                                  html_escape(!used ? "not used: " + p.value("note", std::string())
                                              : outlier ? "outlier, left out"
                                                        : "used")));
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// time_sync

std::string time_sync_section(const json& j, const fs::path& dir) {
  const json& in = j["inputs"];
  std::string out = fmt::format(
      "<p>The clock of <b>{}</b> against <b>{}</b>'s: <code>{}</code>. Offset {} ms ± {} ms "
      "(1-sigma); correlation peak NCC {} (the second peak {} at {} s, ratio {}; the peak is "
      "taken when the ratio is below {}); {} s of overlap.</p>\n",
      html_escape(in["sensor"].get<std::string>()),
      html_escape(in["reference_sensor"].get<std::string>()),
      html_escape(j["definition"].get<std::string>()), html_number(j["offset_s"], "{:+.4f}", 1e3),
      html_number(j["sigma_s"], "{:.4f}", 1e3), html_number(j["peak"]["ncc"], "{:.4f}"),
      html_number(j["peak"]["second_peak_ncc"], "{:.3f}"),
      html_number(j["peak"]["second_peak_offset_s"], "{:+.3f}"),
      html_number(j["peak"]["ratio"], "{:.2f}"), html_number(j["peak"]["max_ratio"], "{:.2f}"),
      html_number(j["overlap_s"], "{:.1f}"));
  const json& d = j["drift"];
  if (d.is_object() && d.value("estimated", false)) {
    out += fmt::format(
        "<p>Drift {} ± {} ppm over windows of {} s: {}. It counts as significant when |drift| "
        "exceeds {} sigma (Student's t at the 3-sigma level for the windows' degrees of "
        "freedom).</p>\n",
        html_number(d["drift_ppm"], "{:+.3f}"), html_number(d["sigma_ppm"], "{:.3f}"),
        html_number(d["window_s"], "{:.0f}"),
        d.value("significant", false) ? "significant: the offset is given at the epoch"
                                      : "not significant: one offset holds",
        html_number(d["significance_sigmas"], "{:.2f}"));
    report::PlotSeries used{"windows (1-sigma bars)", {}, {}, {}},
        unused{"windows left out", {}, {}, {}}, est{"the estimate", {}, {}, {}};
    for (const json& w : d["windows"]) {
      report::PlotSeries& s = w.value("used", false) ? used : unused;
      s.x.push_back(w["t_other_s"].get<double>());
      s.y.push_back(1e3 * w["offset_s"].get<double>());
      s.y_error.push_back(1e3 * w["sigma_s"].get<double>());
    }
    if (!used.x.empty()) {
      // Window times count from the other stream's first stamp, the drift's epoch.
      const double drift = d.value("significant", false) ? d["drift_ppm"].get<double>() * 1e-6 : 0;
      for (const double t : {used.x.front(), used.x.back()}) {
        est.x.push_back(t);
        est.y.push_back(1e3 * (j["offset_s"].get<double>() + drift * t));
      }
      report::Plot windows{"The offset in each window",
                           "time since the other stream's start [s]",
                           "offset [ms]",
                           "",
                           {used, est}};
      if (!unused.x.empty()) windows.series.push_back(unused);
      out += report::html_plot_figure(
          windows,
          "Each window's offset with its 1-sigma; the line is the offset the step "
          "reports (with the drift when significant). Windows that scatter beyond "
          "their bars mean the sigmas are too small or the clock jitters.");
    }
  }
  if (j["three_axis"].is_object() && j["three_axis"].value("enabled", false)) {
    const json& t = j["three_axis"];
    out += fmt::format(
        "<p>The two IMUs' axes: rotation other to reference {} deg about [{}, {}, {}]; angular "
        "velocity residual RMS {} rad/s after it.</p>\n",
        html_number(t["axis_angle"]["angle_deg"], "{:.3f}"),
        html_number(t["axis_angle"]["axis"][0], "{:.4f}"),
        html_number(t["axis_angle"]["axis"][1], "{:.4f}"),
        html_number(t["axis_angle"]["axis"][2], "{:.4f}"),
        html_number(t["residual_rms_rad_s"], "{:.4f}"));
  }
  out += png_figure(dir / "correlation.png",
                    "The normalised cross-correlation of the angular speeds against the offset.");
  out += png_figure(dir / "aligned.png", "The angular speeds aligned by the offset.");
  return out;
}

// ---------------------------------------------------------------------------------------------
// hand_eye

std::string hand_eye_section(const json& j, const fs::path& dir) {
  const json& T = j["T_gnss_lidar"];
  std::string out = fmt::format(
      "<p><b>T_gnss_lidar</b> (the LiDAR in the GNSS/INS frame): translation {} mm; rotation "
      "{}.</p>\n",
      with_sigmas(T["t_m"], T["t_sigma_m"], "{:.1f}", 1e3),
      rotation_cell(T.value("axis_angle", json()), T["rotation_sigma_deg"], "gnss"));
  if (j["clock_offset"].is_object()) {
    out += fmt::format("<p>Clock: t_lidar = t_gnss + {} ms ± {} ms (1-sigma).</p>\n",
                       html_number(j["clock_offset"]["gnss_time_offset_s"], "{:+.3f}", 1e3),
                       html_number(j["clock_offset"]["sigma_s"], "{:.3f}", 1e3));
  }
  if (j["odometry_scale"].is_object()) {
    out += fmt::format(
        "<p>Odometry scale {} ± {} (the GNSS/INS distance over the LiDAR's; 1 within its sigma "
        "says the odometry's lengths are right).</p>\n",
        html_number(j["odometry_scale"]["value"], "{:.5f}"),
        html_number(j["odometry_scale"]["sigma"], "{:.5f}"));
  }
  const json& ob = j["observability"];
  if (ob.is_object() && ob["unobservable_directions"].is_array() &&
      !ob["unobservable_directions"].empty()) {
    out += "<p class=\"warning\">Directions the motion does not determine: " +
           html_escape(ob["unobservable_directions"].dump()) + "</p>\n";
  }
  std::vector<std::vector<std::string>> rows;
  for (const json& l : j["pair_noise"]["levels"]) {
    rows.push_back({html_number(l["length_s"], "{:.2f}"), html_number(l["pairs"], "{:.0f}"),
                    html_number(l["rotation_deg"], "{:.4f}"),
                    html_number(l["translation_m"], "{:.1f}", 1e3)});
  }
  out += report::html_table(
      {"pair length [s]", "inlier pairs", "rotation noise [deg]", "translation noise [mm]"}, rows);
  report::PlotSeries rot{"inlier pairs", {}, {}, {}}, rot_out{"outliers", {}, {}, {}};
  report::PlotSeries tr{"inlier pairs", {}, {}, {}}, tr_out{"outliers", {}, {}, {}};
  double t0 = NAN;
  for (const json& p : j["pairs"]) {
    const double t = std::stod(p["t0_s"].get<std::string>());
    if (std::isnan(t0)) t0 = t;
    const bool o = p.value("outlier", false);
    (o ? rot_out : rot).x.push_back(t - t0);
    (o ? rot_out : rot).y.push_back(p["rotation_residual_deg"].get<double>());
    (o ? tr_out : tr).x.push_back(t - t0);
    (o ? tr_out : tr).y.push_back(1e3 * p["translation_residual_m"].get<double>());
  }
  for (report::PlotSeries* s : {&rot, &rot_out, &tr, &tr_out}) s->points = true;
  if (!rot.x.empty()) {
    report::Plot a{
        "Each motion pair's rotation residual", "pair start [s]", "rotation [deg]", "", {rot}};
    if (!rot_out.x.empty()) a.series.push_back(rot_out);
    out += report::html_plot_figure(
        a, "|B X - X A|'s rotation for each pair of poses, after the estimate.");
    report::Plot b{
        "Each motion pair's translation residual", "pair start [s]", "translation [mm]", "", {tr}};
    if (!tr_out.x.empty()) b.series.push_back(tr_out);
    out += report::html_plot_figure(b, "The same pairs' translation residual.");
  }
  out += png_figure(dir / "trajectories.png",
                    "The LiDAR odometry and the GNSS/INS trajectory after the extrinsic.");
  return out;
}

// A step's section; `dir` holds its report (<step>.json and its figures).
std::string step_section(const json& run, const fs::path& dir) {
  const std::string step = run["step"];
  const std::string status = run["status"];
  std::string s = fmt::format(
      "<h2 id=\"step-{0}\">{0} {1}{2}</h2>\n", html_escape(step), report::html_badge(status),
      run.value("cached", false) ? " <span class=\"note\">(cached)</span>" : "");
  if (status != "ok") {
    s += fmt::format("<p><b>{}</b>: {}</p>\n", html_escape(status),
                     html_escape(run["reason"].get<std::string>()));
    if (!run["remedy"].get<std::string>().empty())
      s += "<p>What would settle it: " + html_escape(run["remedy"].get<std::string>()) + "</p>\n";
  }
  s += list(run["warnings"], "warning");
  const fs::path file = dir / (step + ".json");
  if (status == "ok" && fs::exists(file)) {
    try {
      const json j = json::parse(io::read_text_file(file));
      if (step == "cameras") s += cameras_section(j, dir);
      if (step == "lidar_camera") s += lidar_camera_section(j, dir);
      if (step == "time_sync") s += time_sync_section(j, dir);
      if (step == "hand_eye") s += hand_eye_section(j, dir);
      s += inputs_table(j["inputs"]);
    } catch (const std::exception& e) {
      s += fmt::format("<p class=\"warning\">{}: not a report this rigcal can read ({})</p>\n",
                       html_escape(file.string()), html_escape(e.what()));
    }
  }
  if (!run["summary"].empty()) {
    s += "<details><summary>The step's lines as the terminal printed them</summary>\n<pre>";
    for (const json& l : run["summary"]) s += html_escape(l.get<std::string>()) + "\n";
    s += "</pre></details>\n";
  }
  s += list(run["notes"], "note");
  return s;
}

}  // namespace

std::string calibrate_html(const fs::path& out) {
  const fs::path file = out / "reports" / "calibrate.json";
  json run;
  try {
    run = json::parse(io::read_text_file(file));
  } catch (const json::exception& e) {
    throw Error(fmt::format("{}: not a report rigcal wrote: {}", file.string(), e.what()));
  }
  const int status = run["exit_status"];
  std::string body = "<h1>Calibration of one session</h1>\n";
  body += fmt::format("<p>Session <code>{}</code>, {}.</p>\n",
                      html_escape(run["session"].get<std::string>()),
                      html_escape(run["tool_version"].get<std::string>()));
  size_t warnings = 0;
  for (const json& s : run["steps"]) warnings += s["warnings"].size();
  std::string headline;
  if (run["published"].get<bool>()) {
    headline = fmt::format("Published <code>{}</code>: every step ended ok{}",
                           html_escape(run["calibration"].get<std::string>()),
                           warnings ? fmt::format(", with {} warning{} to read below", warnings,
                                                  warnings == 1 ? "" : "s")
                                    : "");
  } else {
    headline = "Nothing published: ";
    for (const json& s : run["steps"]) {
      if (s["status"] == "ok") continue;
      headline += fmt::format("{} {} ({}); ", html_escape(s["step"].get<std::string>()),
                              html_escape(s["status"].get<std::string>()),
                              html_escape(s["reason"].get<std::string>()));
    }
    headline.resize(headline.size() - 2);
  }
  body += fmt::format("<p class=\"headline {}\">{}</p>\n",
                      status != 0                                 ? "bad"
                      : warnings || !run["published"].get<bool>() ? "unsure"
                                                                  : "good",
                      headline);
  std::vector<std::vector<std::string>> rows;
  for (const json& s : run["steps"]) {
    std::vector<std::string> figures;
    for (const json& f : s["residuals"]) {
      // (fmt, not operator+: GCC 12 warns falsely on `" " + string` here, -Wrestrict)
      const std::string unit = f["unit"];
      figures.push_back(fmt::format("{} {:.4g}{}{}", f["name"].get<std::string>(),
                                    f["value"].get<double>(), unit.empty() ? "" : " ", unit));
    }
    const std::string step = s["step"];
    rows.push_back({fmt::format("<a href=\"#step-{0}\">{0}</a>", html_escape(step)),
                    report::html_badge(s["status"].get<std::string>()),
                    s.value("cached", false) ? "cached" : html_number(s["seconds"], "{:.1f} s"),
                    html_escape(s["status"] == "ok" ? fmt::format("{}", fmt::join(figures, ", "))
                                                    : s["reason"].get<std::string>()),
                    std::to_string(s["warnings"].size())});
  }
  body +=
      "<h2 id=\"steps\">The steps</h2>\n" +
      report::html_table({"step", "status", "time", "residuals (or why not)", "warnings"}, rows);
  for (const json& s : run["steps"])
    body += step_section(s, out / "reports" / s["step"].get<std::string>());
  return report::html_page("rigcal calibrate", body);
}

std::string step_html(const fs::path& dir) {
  const fs::path file = dir / "run.json";
  json j;
  try {
    j = json::parse(io::read_text_file(file));
    const json& run = j.at("run");
    const std::string step = run.at("step"), status = run.at("status");
    const size_t warnings = run.at("warnings").size();
    std::string body = fmt::format("<h1>One calibration step: {}</h1>\n", html_escape(step));
    body += fmt::format("<p>Report folder <code>{}</code>, {}.</p>\n",
                        html_escape(fs::absolute(dir).lexically_normal().string()),
                        html_escape(j.at("tool_version").get<std::string>()));
    const std::string headline =
        status == "ok" ? fmt::format("The step ended ok{}",
                                     warnings ? fmt::format(", with {} warning{} to read below",
                                                            warnings, warnings == 1 ? "" : "s")
                                              : "; nothing to warn about")
                       : fmt::format("{}: {}", html_escape(status),
                                     html_escape(run.at("reason").get<std::string>()));
    body += fmt::format("<p class=\"headline {}\">{}</p>\n",
                        status != "ok" ? "bad"
                        : warnings     ? "unsure"
                                       : "good",
                        headline);
    body += step_section(run, dir);
    return report::html_page("rigcal " + step, body);
  } catch (const json::exception& e) {
    throw Error(fmt::format("{}: not a report rigcal wrote: {}", file.string(), e.what()));
  }
}

}  // namespace rigcal::session
