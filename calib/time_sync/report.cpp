#include "rigcal/time_sync/report.h"

#include <fmt/format.h>

#include <cmath>

#include "rigcal/core/se3.h"
#include "rigcal/core/version.h"
#include "rigcal/report/json.h"
#include "rigcal/report/rotation.h"
#include "rigcal/report/svg_plot.h"

namespace rigcal::time_sync {

nlohmann::json time_sync_json(const TimeSyncResult& r, const TimeSyncOptions& o,
                              const TimeSyncInputs& in) {
  nlohmann::json j;
  j["tool_version"] = version_string();
  j["definition"] =
      "t_reference = t_other + offset_s + drift_ppm * 1e-6 * (t_other - epoch); offset_s is what "
      "is added to the other stream's stamps to put them on the reference clock";
  j["inputs"] = {{"reference", in.reference},
                 {"reference_format", in.reference_format},
                 {"other", in.other},
                 {"other_format", in.other_format},
                 {"sensor", in.sensor},
                 {"reference_sensor", in.reference_sensor},
                 {"reference_time_offset_s", in.reference_time_offset_s},
                 {"notes", in.notes}};
  j["verdict"] = r.verdict;
  j["reason"] = r.reason;
  j["offset_s"] = report::finite_or_null(r.offset_s);
  j["sigma_s"] = report::finite_or_null(r.sigma_s);
  j["epoch_other_s"] = to_seconds_text(r.epoch);
  if (!in.sensor.empty() && r.verdict == "ok") {
    j["sensor_time_offset_s"] = in.reference_time_offset_s + r.offset_s;
  }
  j["sigma_detail"] = {{"formal_s", report::finite_or_null(r.sigma_formal_s)},
                       {"windows_s", report::finite_or_null(r.sigma_windows_s)},
                       {"explanation",
                        "formal: from the residuals at the optimum and their slope in the offset, "
                        "inflated for residuals correlated in time; windows: spread of the "
                        "windowed offsets; sigma_s is the larger (or the drift fit's when drift "
                        "is significant)"}};
  j["stages_s"] = {{"coarse_fft", r.coarse_offset_s},
                   {"integer_fine", report::finite_or_null(r.integer_offset_s)},
                   {"parabolic", report::finite_or_null(r.parabolic_offset_s)},
                   {"norm_continuous", report::finite_or_null(r.norm_offset_s)},
                   {"final", report::finite_or_null(r.offset_s)}};
  j["peak"] = {{"ncc", r.peak_ncc},
               {"second_peak_ncc", r.second_peak_ncc},
               {"second_peak_offset_s", r.second_peak_offset_s},
               {"ratio", r.peak_ratio},
               {"max_ratio", o.max_peak_ratio},
               {"min_ncc", o.min_peak_ncc}};
  j["excitation"] = {{"reference_norm_std_rad_s", r.excitation_reference_rad_s},
                     {"other_norm_std_rad_s", r.excitation_other_rad_s},
                     {"minimum_rad_s", o.min_excitation_rad_s}};
  j["rates_hz"] = {{"reference", r.reference_rate_hz},
                   {"other", r.other_rate_hz},
                   {"fine_grid", r.grid_hz},
                   {"coarse_grid", r.coarse_hz}};
  j["overlap_s"] = r.overlap_s;
  j["search"] = {{"max_offset_s", std::isfinite(o.max_offset_s) ? nlohmann::json(o.max_offset_s)
                                                                : nlohmann::json("all")},
                 {"min_overlap", o.min_overlap}};
  if (r.verdict == "ok") {
    nlohmann::json R = nlohmann::json::array();
    for (int i = 0; i < 3; ++i)
      R.push_back(
          {r.R_reference_other(i, 0), r.R_reference_other(i, 1), r.R_reference_other(i, 2)});
    const Eigen::Vector3d rpy = roll_pitch_yaw(r.R_reference_other) * 180.0 / M_PI;
    j["three_axis"] = {{"enabled", r.three_axis},
                       {"model", "w_reference = R_reference_other * w_other + bias_difference"},
                       {"R_reference_other", R},
                       {"axis_angle", report::axis_angle_json(r.R_reference_other)},
                       {"roll_pitch_yaw_deg", {rpy.x(), rpy.y(), rpy.z()}},
                       {"bias_difference_rad_s",
                        {r.bias_difference.x(), r.bias_difference.y(), r.bias_difference.z()}},
                       {"residual_rms_rad_s", r.residual_rms_rad_s},
                       {"samples", r.samples_used}};
    nlohmann::json windows = nlohmann::json::array();
    for (const WindowOffset& w : r.windows) {
      windows.push_back({{"t_other_s", w.t_other_s},
                         {"offset_s", report::finite_or_null(w.offset_s)},
                         {"sigma_s", report::finite_or_null(w.sigma_s)},
                         {"ncc", report::finite_or_null(w.ncc)},
                         {"used", w.used},
                         {"note", w.note}});
    }
    j["drift"] = {
        {"estimated", r.drift_estimated},
        {"significant", r.drift_significant},
        {"significance_sigmas", report::finite_or_null(r.drift_significance_sigma)},
        {"drift_ppm", r.drift_estimated ? report::finite_or_null(r.drift_ppm) : nlohmann::json()},
        {"sigma_ppm",
         r.drift_estimated ? report::finite_or_null(r.drift_sigma_ppm) : nlohmann::json()},
        {"rule", "significant when |drift| > 3 sigma (at least 4 usable windows)"},
        {"window_s", r.window_s},
        {"window_residual_rms_s", report::finite_or_null(r.window_residual_rms_s)},
        {"mean_offset_s", report::finite_or_null(r.mean_offset_s)},
        {"windows", windows}};
  }
  return j;
}

std::vector<io::OutputFile> time_sync_report_files(
    const std::filesystem::path& dir, const TimeSyncResult& r, const TimeSyncOptions& o,
    const TimeSyncInputs& in, const AngularRates& reference, const AngularRates& other) {
  std::vector<io::OutputFile> files;
  files.push_back({dir / "time_sync.json", report::json_text(time_sync_json(r, o, in))});
  {
    report::Plot p;
    p.title = "Normalized correlation of |w| against the offset";
    p.x_label = "offset (s): t_reference = t_other + offset";
    p.y_label = "NCC";
    report::PlotSeries coarse{"coarse (FFT)", {}, {}, {}}, fine{"fine grid", {}, {}, {}};
    for (const auto& c : r.coarse_curve) coarse.x.push_back(c.offset_s), coarse.y.push_back(c.ncc);
    for (const auto& c : r.fine_curve) fine.x.push_back(c.offset_s), fine.y.push_back(c.ncc);
    // Around the peak: +-10 x the fine range, or everything when the search was small.
    if (!fine.x.empty()) {
      const double half = 10 * (fine.x.back() - fine.x.front());
      report::PlotSeries near{"coarse (FFT)", {}, {}, {}};
      for (size_t i = 0; i < coarse.x.size(); ++i) {
        if (std::abs(coarse.x[i] - r.coarse_offset_s) <= half)
          near.x.push_back(coarse.x[i]), near.y.push_back(coarse.y[i]);
      }
      coarse = near;
    }
    p.series = {coarse, fine};
    if (r.verdict == "ok") {
      // The chosen peak marked, labelled with the offset it gives.
      report::PlotSeries peak{fmt::format("peak {:+.2f} ms", 1e3 * r.offset_s), {}, {}, {}};
      peak.x = {r.offset_s}, peak.y = {r.peak_ncc};
      peak.points = true;
      p.series.push_back(peak);
    }
    files.push_back({dir / "correlation.png", report::render_png(p)});
  }
  if (r.verdict == "ok") {
    // 20 s in the middle of the overlap, on the reference clock.
    const double t_ref0 = reference.stamps.front().seconds();
    auto ref_time = [&](Time t_other) {
      const double dt = (t_other - r.epoch).seconds();
      const double drift = r.drift_significant ? r.drift_ppm * 1e-6 * dt : 0.0;
      return (t_other - reference.stamps.front()).seconds() + r.offset_s + drift;
    };
    const double a = std::max(0.0, ref_time(other.stamps.front()));
    const double b = std::min((reference.stamps.back() - reference.stamps.front()).seconds(),
                              ref_time(other.stamps.back()));
    const double mid = 0.5 * (a + b), lo = std::max(a, mid - 10), hi = std::min(b, mid + 10);
    report::Plot p;
    p.title = "|w| after alignment (20 s in the middle of the overlap)";
    p.x_label = fmt::format("reference time (s since {:.3f})", t_ref0);
    p.y_label = "|w| (rad/s)";
    report::PlotSeries sr{"reference", {}, {}, {}}, so{"other, shifted", {}, {}, {}};
    for (size_t i = 0; i < reference.stamps.size(); ++i) {
      const double t = (reference.stamps[i] - reference.stamps.front()).seconds();
      if (t >= lo && t <= hi) sr.x.push_back(t), sr.y.push_back(reference.rates[i].norm());
    }
    for (size_t i = 0; i < other.stamps.size(); ++i) {
      const double t = ref_time(other.stamps[i]);
      if (t >= lo && t <= hi) so.x.push_back(t), so.y.push_back(other.rates[i].norm());
    }
    p.series = {sr, so};
    files.push_back({dir / "aligned.png", report::render_png(p)});
    if (!r.windows.empty()) {
      report::Plot w;
      w.title = r.drift_estimated
                    ? fmt::format("Windowed offsets; drift {:.2f} +- {:.2f} ppm ({})", r.drift_ppm,
                                  r.drift_sigma_ppm,
                                  r.drift_significant ? "significant" : "not significant")
                    : "Windowed offsets (too few for a drift fit)";
      w.x_label = "other clock (s since the epoch)";
      w.y_label = "offset - final offset (ms)";
      report::PlotSeries used{"used", {}, {}, {}}, fit{"drift fit", {}, {}, {}},
          rejected{"outliers", {}, {}, {}};
      for (const WindowOffset& x : r.windows) {
        if (!x.used) {
          if (std::isfinite(x.offset_s)) {
            rejected.x.push_back(x.t_other_s);
            rejected.y.push_back(1e3 * (x.offset_s - r.offset_s));
          }
          continue;
        }
        used.x.push_back(x.t_other_s);
        used.y.push_back(1e3 * (x.offset_s - r.offset_s));
        if (r.drift_significant) {
          fit.x.push_back(x.t_other_s);
          fit.y.push_back(1e3 * r.drift_ppm * 1e-6 * x.t_other_s);
        }
      }
      used.values.assign(used.x.size(), 0.0);  // points
      rejected.values.assign(rejected.x.size(), 0.0);
      w.series = {used};
      if (!fit.x.empty()) w.series.push_back(fit);
      if (!rejected.x.empty()) w.series.push_back(rejected);
      files.push_back({dir / "windows.png", report::render_png(w)});
    }
  }
  return files;
}

}  // namespace rigcal::time_sync
