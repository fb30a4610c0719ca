// A calibration against a new session (check.h).
#include "rigcal/session/check.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <map>
#include <set>
#include <tuple>

#include "rigcal/core/error.h"
#include "rigcal/core/stats.h"
#include "rigcal/core/version.h"
#include "rigcal/report/json.h"
#include "rigcal/session/provenance.h"
#include "rigcal/session/report_html.h"

namespace rigcal::session {
namespace {

// Degrees a radian (diff.cpp's kDeg is the other way round; they share a unity batch).
constexpr double kDegPerRad = 180.0 / M_PI;

// What each step needs recorded for its quantities to be determined.
std::string what_to_record(const std::string& step) {
  if (step == "cameras")
    return "views of the board over the whole image of each camera, tilted up to 45 deg, near "
           "and far";
  if (step == "lidar_camera")
    return "board poses tilted about two axes, seen by the camera and the LiDAR together";
  if (step == "time_sync")
    return "a minute of motion with rotation about every axis (the rig turned and shaken)";
  if (step == "hand_eye")
    return "a drive or walk with turns, and rotation about two axes at least, with RTK fixes";
  return "more data for this step";
}

// The chi-square value whose upper tail is p (bisection on chi2_upper_tail).
double chi2_quantile(double p, int dof) {
  double lo = 0, hi = 1;
  while (chi2_upper_tail(hi, dof) > p) hi *= 2;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (chi2_upper_tail(mid, dof) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// A range "a-b unit" (or "a unit") of figures.
std::string span(std::vector<double> v, const char* format, const char* unit) {
  std::erase_if(v, [](double x) { return !std::isfinite(x); });
  if (v.empty()) return "";
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  const std::string a = fmt::format(fmt::runtime(format), *lo),
                    b = fmt::format(fmt::runtime(format), *hi);
  return a == b ? fmt::format("{} {}", a, unit) : fmt::format("{}-{} {}", a, b, unit);
}

// The quantities a stored step record holds sigmas of, by the prefix of their keys: a relation
// "T_a_b", a clock "<sensor>.time_", a camera's intrinsics "<camera>.f".
struct Quantity {
  std::string name, step;
  enum { pose, clock, intrinsics } kind = pose;
  std::string a, b;               // pose: T_a_b; clock, intrinsics: a is the sensor
  std::vector<std::string> keys;  // the stored sigmas' keys
};

std::vector<Quantity> quantities(const std::vector<StepRecord>& records, const rig::Rig& stored) {
  std::vector<Quantity> out;
  auto find = [&](const std::string& name) -> Quantity* {
    for (Quantity& q : out)
      if (q.name == name) return &q;
    return nullptr;
  };
  for (const StepRecord& r : records) {
    for (const report::Figure& f : r.sigmas) {
      const std::string& key = f.name;
      Quantity q;
      q.step = r.step;
      if (key.rfind("T_", 0) == 0) {
        const std::string frames = key.substr(2, key.find('.') - 2);
        const std::optional<std::pair<std::string, std::string>> ab =
            relation_sensors(frames, stored);
        if (!ab) continue;
        std::tie(q.a, q.b) = *ab;
        q.name = "T_" + frames;
        q.kind = Quantity::pose;
      } else if (const size_t dot = key.find('.'); dot != std::string::npos) {
        q.a = key.substr(0, dot);
        const std::string what = key.substr(dot + 1);
        if (!rig::find_sensor(stored, q.a)) continue;
        if (what.rfind("time_", 0) == 0) {
          q.name = q.a + " clock";
          q.kind = Quantity::clock;
        } else if (what.rfind("fx", 0) == 0 || what.rfind("fy", 0) == 0 ||
                   what.rfind("cx", 0) == 0 || what.rfind("cy", 0) == 0) {
          q.name = q.a + " intrinsics";
          q.kind = Quantity::intrinsics;
        } else {
          continue;
        }
      } else {
        continue;
      }
      Quantity* existing = find(q.name);
      if (!existing) {
        out.push_back(q);
        existing = &out.back();
      }
      existing->keys.push_back(key);
    }
  }
  return out;
}

// A residual figure of a step by its key in rigcal.steps (figure_key), NaN when absent.
double figure_value(const std::vector<report::Figure>& figures, const std::string& key) {
  for (const report::Figure& f : figures)
    if (figure_key(f) == key) return f.value;
  return NAN;
}

// The new data at the stored parameters, from the re-estimate's steps (which fitted them with
// fit_at_rig), beside the stored calibration's levels and the re-estimate's.
std::vector<ResidualLevel> residual_levels(const std::vector<StepRecord>& records,
                                           const CalibrateResult& estimate) {
  struct Row {
    const char *step, *what, *unit, *at_stored, *level;
    double scale;
  };
  static const Row kRows[] = {
      {"cameras", "corner reprojection RMS", "px", "rms_2d_at_rig_px", "rms_2d_px", 1},
      {"lidar_camera", "boards' noise scale (1: as their covariances say)", "",
       "noise_scale_at_rig", "noise_scale", 1},
      {"lidar_camera", "board normal angle RMS", "deg", "normal_angle_rms_at_rig_deg", "", 1},
      {"lidar_camera", "board distance RMS", "mm", "distance_rms_at_rig_m", "", 1e3},
      {"hand_eye", "motion pairs' median rotation residual", "deg",
       "pair_rotation_median_at_rig_deg", "pair_rotation_median_deg", 1},
      {"hand_eye", "motion pairs' median translation residual", "mm",
       "pair_translation_median_at_rig_m", "pair_translation_median_m", 1e3}};
  std::vector<ResidualLevel> out;
  for (const Row& row : kRows) {
    const auto run = std::find_if(estimate.steps.begin(), estimate.steps.end(),
                                  [&](const StepRun& s) { return s.step == row.step; });
    if (run == estimate.steps.end() || run->status != "ok") continue;
    const double at = figure_value(run->residuals, row.at_stored);
    if (!std::isfinite(at)) continue;
    ResidualLevel l{row.step, row.what, row.unit, row.scale * at, NAN, NAN};
    if (*row.level) {
      l.reestimated = row.scale * figure_value(run->residuals, row.level);
      for (const StepRecord& r : records)
        if (r.step == row.step) l.stored = row.scale * figure_value(r.residuals, row.level);
    }
    out.push_back(l);
  }
  return out;
}

}  // namespace

std::string_view to_string(VerdictKind kind) {
  switch (kind) {
    case VerdictKind::consistent:
      return "consistent";
    case VerdictKind::changed:
      return "changed";
    case VerdictKind::cannot_tell:
      return "cannot tell";
  }
  return "?";
}

CheckResult check(const rig::Rig& stored, const std::filesystem::path& stored_file,
                  const CheckOptions& options, const Progress& progress) {
  const std::vector<StepRecord> records = read_steps(stored);
  const std::vector<Quantity> stored_quantities = quantities(records, stored);
  if (stored_quantities.empty()) {
    throw Error(fmt::format(
        "{}: no step records with sigmas (rigcal.steps): nothing to check against; `rigcal "
        "calibrate` writes them (a calibration from another tool can be compared with `rigcal "
        "diff` against a new calibration)",
        stored_file.string()));
  }
  CheckResult out;
  out.calibration = stored_file;
  out.session = options.calibrate.session;
  out.alarm_p = options.alarm_p;
  CalibrateOptions run = options.calibrate;
  run.rig = stored_file;
  // The new data at the stored parameters too, beside their re-estimate.
  run.cameras.fit_at_rig = run.lidar_camera.fit_at_rig = run.hand_eye.fit_at_rig = true;
  out.estimate = calibrate(run, progress);

  // The re-estimate with its own steps' sigmas (those that ended ok) in place of the stored ones.
  rig::Rig estimate = out.estimate.rig;
  std::vector<StepRecord> new_records;
  for (const StepRun& s : out.estimate.steps) {
    if (s.status != "ok") continue;
    new_records.push_back(
        {s.step, s.status, version_string(), "", {}, s.sigmas, s.residuals, s.correlations});
  }
  auto& meta = estimate.extra_metadata;
  std::erase_if(meta, [](const auto& kv) { return kv.first == "steps"; });
  meta.emplace_back("steps", steps_yaml(new_records));
  out.difference = diff_rigs(stored, estimate);
  // The records already read: the stored calibration's and the re-estimate's.
  const std::map<std::string, double> sigmas_a = uncertainty_of(records).sigma,
                                      sigmas_b = uncertainty_of(new_records).sigma;

  for (const Quantity& q : stored_quantities) {
    Verdict v;
    v.quantity = q.name;
    v.step = q.step;
    v.sensors = q.kind == Quantity::pose ? std::vector<std::string>{q.a, q.b}
                                         : std::vector<std::string>{q.a};
    // The step's run on the new session.
    const auto run_it = std::find_if(out.estimate.steps.begin(), out.estimate.steps.end(),
                                     [&](const StepRun& s) { return s.step == q.step; });
    if (run_it == out.estimate.steps.end() || run_it->status != "ok") {
      v.kind = VerdictKind::cannot_tell;
      v.reason = run_it == out.estimate.steps.end()
                     ? fmt::format("the step {} did not run", q.step)
                     : fmt::format("{} {} on the new session{}{}; record {}", q.step,
                                   run_it->status, run_it->reason.empty() ? "" : ": ",
                                   run_it->reason, what_to_record(q.step));
      out.verdicts.push_back(v);
      continue;
    }
    // The difference and its significance.
    std::optional<Significance> sig;
    std::vector<double> sigma_a, sigma_b;
    if (q.kind == Quantity::pose) {
      for (const PoseDifference& p : out.difference.poses) {
        if (p.a != q.a || p.b != q.b) continue;
        sig = p.significance;
        v.change = fmt::format("rotation {:.4f} deg, translation {:.2f} mm",
                               p.rotation_rad.norm() * kDegPerRad, 1e3 * p.translation_m.norm());
      }
    } else if (q.kind == Quantity::clock) {
      for (const ClockDifference& c : out.difference.clocks) {
        if (c.sensor != q.a) continue;
        sig = c.significance;
        v.change = fmt::format("offset {:+.4f} ms{}", 1e3 * c.offset_s,
                               c.drift_ppm ? fmt::format(", drift {:+.3f} ppm", *c.drift_ppm) : "");
      }
    } else {
      for (const CameraDifference& c : out.difference.cameras) {
        if (c.camera != q.a) continue;
        sig = c.significance;
        v.change = fmt::format("fx {:+.3f}, fy {:+.3f}, cx {:+.3f}, cy {:+.3f} px", c.values[0],
                               c.values[1], c.values[2], c.values[3]);
        if (c.projection) {
          v.change += fmt::format("; projection {:.3f} px rms with the camera's rotation taken out",
                                  c.projection->fitted_rms_px);
        }
      }
    }
    // The new data's sigmas against the stored ones.
    std::vector<std::string> weak;
    for (const std::string& key : q.keys) {
      const auto a = sigmas_a.find(key), b = sigmas_b.find(key);
      if (b == sigmas_b.end()) {
        weak.push_back(fmt::format("{} (no sigma from the new session)", key));
      } else if (a != sigmas_a.end() && b->second > options.max_sigma_ratio * a->second) {
        weak.push_back(
            fmt::format("{} ({:.3g} against the calibration's {:.3g})", key, b->second, a->second));
      }
    }
    if (!sig || !weak.empty()) {
      v.kind = VerdictKind::cannot_tell;
      v.reason = fmt::format(
          "the new session determines {} {} times less well than the "
          "calibration did or not at all: {}; record {}",
          weak.size() == 1 ? "it" : "them", options.max_sigma_ratio, fmt::join(weak, ", "),
          what_to_record(q.step));
      out.verdicts.push_back(v);
      continue;
    }
    v.chi2 = sig->chi2, v.dof = sig->dof, v.p_value = sig->p_value;
    v.kind = sig->p_value < options.alarm_p ? VerdictKind::changed : VerdictKind::consistent;
    // The smallest change along one component the check flags.
    const double k = std::sqrt(chi2_quantile(options.alarm_p, sig->dof));
    std::vector<double> rot, trans, ms, ppm, px;
    for (size_t i = 0; i < sig->sigma.size(); ++i) {
      if (!std::isfinite(sig->conditional_sigma[i])) continue;
      const double s = k * sig->conditional_sigma[i];
      if (q.kind == Quantity::pose)
        (i < 3 ? rot : trans).push_back(i < 3 ? s * kDegPerRad : 1e3 * s);
      if (q.kind == Quantity::clock) (i == 0 ? ms : ppm).push_back(i == 0 ? 1e3 * s : s);
      if (q.kind == Quantity::intrinsics) px.push_back(s);
    }
    std::vector<std::string> parts;
    for (const std::string& p :
         {span(rot, "{:.3f}", "deg"), span(trans, "{:.2f}", "mm"), span(ms, "{:.4f}", "ms"),
          span(ppm, "{:.2f}", "ppm"), span(px, "{:.2f}", "px")})
      if (!p.empty()) parts.push_back(p);
    v.detectable = fmt::format("{}", fmt::join(parts, " or "));
    out.verdicts.push_back(v);
  }
  // The suspects. A changed relation T_a_b says a or b moved: each sensor of the changed
  // relations is tried alone, its move fitted to every judged relation at once (least squares
  // over their components in their combined sigmas), and the sensor whose move explains them
  // best is named.
  std::set<std::string> suspects;
  bool any_changed = false;
  std::set<std::string> candidates;
  for (const Verdict& v : out.verdicts) {
    if (v.kind != VerdictKind::changed) continue;
    any_changed = true;
    if (v.sensors.size() == 1) suspects.insert(v.sensors[0]);  // a clock, a camera's lens
    if (v.sensors.size() == 2) candidates.insert(v.sensors.begin(), v.sensors.end());
  }
  // The judged relations with their combined covariances (rotation rad, then translation m).
  struct Judged {
    std::string a, b;
    const Significance* significance;
  };
  std::vector<Judged> judged;
  for (const Verdict& v : out.verdicts) {
    if (v.kind == VerdictKind::cannot_tell || v.sensors.size() != 2) continue;
    for (const PoseDifference& p : out.difference.poses)
      if (p.a == v.sensors[0] && p.b == v.sensors[1] && p.significance)
        judged.push_back({p.a, p.b, &*p.significance});
  }
  // Every judged relation of a rig against the re-estimate's, whitened by its covariance.
  const auto whitened = [&](const rig::Rig& r) {
    std::vector<double> out_r;
    for (const Judged& j : judged) {
      const SE3 T_p = rig::T_a_b(r, j.a, j.b), T_e = rig::T_a_b(estimate, j.a, j.b);
      Eigen::Matrix<double, 6, 1> d;
      d << rotation_vector(T_e.R * T_p.R.transpose()), T_e.t - T_p.t;
      const std::vector<size_t>& c = j.significance->components;
      Eigen::VectorXd dc(static_cast<Eigen::Index>(c.size()));
      for (size_t i = 0; i < c.size(); ++i) dc[Eigen::Index(i)] = d[Eigen::Index(c[i])];
      const Eigen::VectorXd w = j.significance->whiten * dc;
      out_r.insert(out_r.end(), w.data(), w.data() + w.size());
    }
    return Eigen::Map<Eigen::VectorXd>(out_r.data(), Eigen::Index(out_r.size())).eval();
  };
  for (const std::string& sensor : candidates) {
    const SE3 T_base_start = rig::sensor(stored, sensor).T_base_sensor;
    // The sensor moved by (rotation, translation) in the base frame, what is attached with it.
    const auto moved = [&](const Eigen::Matrix<double, 6, 1>& x) {
      rig::Rig r = stored;
      SE3 T = T_base_start;
      T.R = rotation_from_vector(x.head<3>()) * T.R;
      T.t += x.tail<3>();
      rig::move_rigidly(r, sensor, T);
      return r;
    };
    Eigen::Matrix<double, 6, 1> x = Eigen::Matrix<double, 6, 1>::Zero();
    for (int iteration = 0; iteration < 5; ++iteration) {
      const Eigen::VectorXd r0 = whitened(moved(x));
      Eigen::MatrixXd J(r0.size(), 6);
      for (int k = 0; k < 6; ++k) {
        Eigen::Matrix<double, 6, 1> xk = x;
        xk[k] += 1e-7;
        J.col(k) = (whitened(moved(xk)) - r0) / 1e-7;
      }
      // Directions no judged relation sees stay where they are (a small damping).
      const Eigen::Matrix<double, 6, 6> H =
          J.transpose() * J + 1e-9 * Eigen::Matrix<double, 6, 6>::Identity();
      const Eigen::Matrix<double, 6, 1> step = -H.ldlt().solve(J.transpose() * r0);
      x += step;
      if (step.norm() < 1e-12) break;
    }
    const Eigen::VectorXd r = whitened(moved(x));
    Hypothesis h;
    h.sensor = sensor;
    h.chi2 = r.squaredNorm();
    h.dof = std::max(1, int(r.size()) - 6);  // the 6 of the move fitted
    h.p_value = chi2_upper_tail(h.chi2, h.dof);
    out.hypotheses.push_back(h);
  }
  std::sort(out.hypotheses.begin(), out.hypotheses.end(),
            [](const Hypothesis& x, const Hypothesis& y) { return x.chi2 < y.chi2; });
  if (!out.hypotheses.empty()) {
    suspects.insert(out.hypotheses.front().sensor);
    out.likelihood_ratio = out.hypotheses.size() == 1
                               ? std::numeric_limits<double>::infinity()
                               : std::exp(0.5 * (out.hypotheses[1].chi2 - out.hypotheses[0].chi2));
  }
  out.suspects.assign(suspects.begin(), suspects.end());
  const int run_status = out.estimate.exit_status;
  out.exit_status = any_changed ? 3 : (run_status == 1 || run_status == 2) ? run_status : 0;
  out.residual_levels = residual_levels(records, out.estimate);
  return out;
}

nlohmann::json check_json(const CheckResult& r) {
  nlohmann::json verdicts = nlohmann::json::array(), steps = nlohmann::json::array();
  for (const Verdict& v : r.verdicts) {
    verdicts.push_back({{"quantity", v.quantity},
                        {"step", v.step},
                        {"sensors", v.sensors},
                        {"verdict", to_string(v.kind)},
                        {"change", v.change},
                        {"detectable", v.detectable},
                        {"chi2", v.chi2},
                        {"dof", v.dof},
                        {"p_value", v.p_value},
                        {"reason", v.reason}});
  }
  for (const StepRun& s : r.estimate.steps) {
    steps.push_back({{"step", s.step},
                     {"status", s.status},
                     {"cached", s.cached},
                     {"reason", s.reason},
                     {"remedy", s.remedy}});
  }
  nlohmann::json levels = nlohmann::json::array();
  for (const ResidualLevel& l : r.residual_levels) {
    levels.push_back({{"step", l.step},
                      {"what", l.what},
                      {"unit", l.unit},
                      {"at_stored", report::finite_or_null(l.at_stored)},
                      {"stored", report::finite_or_null(l.stored)},
                      {"reestimated", report::finite_or_null(l.reestimated)}});
  }
  nlohmann::json hypotheses = nlohmann::json::array();
  for (const Hypothesis& h : r.hypotheses) {
    hypotheses.push_back(
        {{"sensor", h.sensor}, {"chi2", h.chi2}, {"dof", h.dof}, {"p_value", h.p_value}});
  }
  return {{"calibration", r.calibration.string()},
          {"session", r.session.string()},
          {"tool_version", version_string()},
          {"alarm_p", r.alarm_p},
          {"verdicts", verdicts},
          {"residual_levels", levels},
          {"hypotheses", hypotheses},
          {"suspects", r.suspects},
          {"likelihood_ratio",
           std::isfinite(r.likelihood_ratio) ? nlohmann::json(r.likelihood_ratio) : nullptr},
          {"exit_status", r.exit_status},
          {"steps", steps},
          {"difference", diff_json(r.difference)}};
}

std::vector<std::string> check_lines(const CheckResult& r) {
  std::vector<std::string> out;
  out.push_back("Each quantity against its re-estimate on the new session:");
  for (const Verdict& v : r.verdicts) {
    std::string line = fmt::format("  {:<12} {:<18} ({}) ", to_string(v.kind), v.quantity, v.step);
    if (v.kind == VerdictKind::cannot_tell) {
      line += v.reason;
    } else {
      line += fmt::format("{}; chi-square {:.2f} over {}, p {:.3g}; flags {} along one axis",
                          v.change, v.chi2, v.dof, v.p_value, v.detectable);
    }
    out.push_back(line);
  }
  if (!r.residual_levels.empty()) {
    out.push_back("The new data at the stored calibration (only the boards' poses free):");
    auto value = [](double v, const std::string& unit) {
      return std::isfinite(v) ? fmt::format("{:.4g}{}", v, unit.empty() ? "" : " " + unit) : "-";
    };
    for (const ResidualLevel& l : r.residual_levels) {
      out.push_back(fmt::format("  {:<12} {}: {} (the calibration's own {}, re-estimated {})",
                                l.step, l.what, value(l.at_stored, l.unit), value(l.stored, l.unit),
                                value(l.reestimated, l.unit)));
    }
  }
  if (!r.hypotheses.empty()) {
    std::vector<std::string> tried;
    for (const Hypothesis& h : r.hypotheses) {
      tried.push_back(fmt::format("{} chi-square {:.1f} over {} (p {:.3g})", h.sensor, h.chi2,
                                  h.dof, h.p_value));
    }
    out.push_back(fmt::format(
        "Which sensor moved: each sensor of the changed relations moved alone, every relation "
        "against the re-estimate: {}",
        fmt::join(tried, "; ")));
    if (r.hypotheses.size() > 1) {
      out.push_back(
          fmt::format("  {} moving alone is {:.3g} times as likely as {} moving alone{}",
                      r.hypotheses[0].sensor, r.likelihood_ratio, r.hypotheses[1].sensor,
                      r.likelihood_ratio < 20 ? ": the data barely tell them apart" : ""));
    }
    if (r.hypotheses.front().p_value < 1e-3) {
      out.push_back(
          fmt::format("  no single sensor moving explains the changes ({} does best): "
                      "more than one moved",
                      r.hypotheses.front().sensor));
    }
  }
  if (!r.suspects.empty()) out.push_back(fmt::format("Changed: {}", fmt::join(r.suspects, ", ")));
  out.push_back(r.exit_status == 3   ? "Verdict: something changed (exit 3)"
                : r.exit_status == 0 ? "Verdict: consistent where the new data can tell (exit 0)"
                                     : "Verdict: a step failed on the new session (see above)");
  return out;
}

std::vector<io::OutputFile> check_report_files(const CheckResult& r,
                                               const std::filesystem::path& dir) {
  const nlohmann::json check = check_json(r);
  const std::vector<std::pair<std::string, std::string>> maps = projection_maps(r.difference);
  std::vector<io::OutputFile> files{{dir / "check.json", check.dump(2) + "\n"},
                                    {dir / "diff.json", check["difference"].dump(2) + "\n"},
                                    {dir / "report.html", check_html(check, maps)}};
  for (const auto& [name, svg] : maps) files.push_back({dir / name, svg});
  return files;
}

}  // namespace rigcal::session
