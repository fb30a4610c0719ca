#include "rigcal/bench/report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "rigcal/core/error.h"
#include "rigcal/core/time.h"
#include "rigcal/core/version.h"
#include "rigcal/io/files.h"
#include "rigcal/report/json.h"
#include "rigcal/report/svg_plot.h"

namespace rigcal::bench {
namespace fs = std::filesystem;

namespace {

nlohmann::json stats_json(const Stats& s) {
  return {{"n", s.n},     {"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median},
          {"std", s.std}, {"min", s.min},   {"max", s.max},   {"sse", s.sse}};
}

nlohmann::json distribution_json(const Distribution& d) {
  return {{"n", d.n},
          {"q1", d.q1},
          {"median", d.median},
          {"q3", d.q3},
          {"whisker_low", d.whisker_low},
          {"whisker_high", d.whisker_high},
          {"bin_low", d.bin_low},
          {"bin_width", d.bin_width},
          {"counts", d.counts}};
}

// JSON has no infinity: failed entries become null.
nlohmann::json number_or_null(bool ok, double v) {
  return ok && std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

}  // namespace

PlotMode plot_mode_from_string(std::string_view name) {
  for (PlotMode m : {PlotMode::automatic, PlotMode::xy, PlotMode::xz, PlotMode::yz}) {
    if (name == to_string(m)) return m;
  }
  throw Error(fmt::format("--plot-mode: expected auto, xy, xz or yz, got '{}'", name));
}

std::string_view to_string(PlotMode mode) {
  switch (mode) {
    case PlotMode::automatic:
      return "auto";
    case PlotMode::xy:
      return "xy";
    case PlotMode::xz:
      return "xz";
    case PlotMode::yz:
      return "yz";
  }
  return "?";
}

PlotMode dominant_plane(const std::vector<Eigen::Vector3d>& positions) {
  if (positions.empty()) return PlotMode::xy;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero(), var = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : positions) mean += p;
  mean /= static_cast<double>(positions.size());
  for (const Eigen::Vector3d& p : positions) var += (p - mean).cwiseAbs2();
  // Leave out the axis of least spread.
  Eigen::Index least = 0;
  var.minCoeff(&least);
  return least == 0 ? PlotMode::yz : least == 1 ? PlotMode::xz : PlotMode::xy;
}

std::pair<int, int> plane_axes(PlotMode mode) {
  switch (mode) {
    case PlotMode::xz:
      return {0, 2};
    case PlotMode::yz:
      return {1, 2};
    default:
      return {0, 1};
  }
}

nlohmann::json bench_json(const EvalResult& r, const std::map<std::string, std::string>& inputs) {
  nlohmann::json j;
  j["tool_version"] = version_string();
  j["convention"] = to_string(r.convention);
  j["inputs"] = inputs;
  j["association"] = to_string(r.association);
  j["n_gt"] = r.n_gt;
  j["n_est"] = r.n_est;
  j["n_pairs"] = r.n_pairs;
  j["gt_length_m"] = r.gt_length;
  const Eigen::Matrix4d T = r.alignment.T_gt_est.matrix();
  nlohmann::json rows = nlohmann::json::array();
  for (int i = 0; i < 4; ++i) rows.push_back({T(i, 0), T(i, 1), T(i, 2), T(i, 3)});
  j["align"] = {{"method", to_string(r.alignment.method)},
                {"T", rows},
                {"scale", r.alignment.scale},
                {"n_used", r.alignment.n_used}};
  j["ate"]["trans"] = stats_json(r.ate_trans);
  j["ate"]["rot"] = stats_json(r.ate_rot_deg);
  if (!r.ate_trans_errors.empty())
    j["ate"]["trans"]["distribution"] = distribution_json(distribution(r.ate_trans_errors));
  if (r.vbr_ate_trans) {
    j["ate"]["trans"]["vbr_sqrt_mean"] = *r.vbr_ate_trans;
    j["ate"]["rot"]["vbr_sqrt_mean"] = *r.vbr_ate_rot;
  }
  for (const RpeResult& rpe : r.rpe) {
    nlohmann::json k;
    k["definition"] = rpe.definition;
    k["n_segments"] = rpe.drift.n_segments;
    if (rpe.kind != "delta") {
      k["trans_pct"] = rpe.drift.trans_pct;
      k["rot_deg_per_m"] = rpe.drift.rot_deg_per_m;
      k["rot_rad_per_m"] = rpe.drift.rot_deg_per_m * M_PI / 180.0;
    }
    if (rpe.trans.n > 0) {
      k["trans"] = stats_json(rpe.trans);
      k["rot"] = stats_json(rpe.rot_deg);
    }
    if (rpe.kind == "delta" && !rpe.segments.empty()) {
      std::vector<double> trans;
      trans.reserve(rpe.segments.size());
      for (const Segment& seg : rpe.segments) trans.push_back(seg.trans);
      k["trans"]["distribution"] = distribution_json(distribution(std::move(trans)));
    }
    j["rpe"][rpe.kind] = k;
  }
  j["notes"] = r.notes;
  return j;
}

namespace {

// Horizontal lines at a statistic's rmse, mean, median and mean +- std (evo's error plots).
void add_statistics_lines(report::Plot& plot, const Stats& s, double x0, double x1,
                          std::string_view unit) {
  auto line = [&](std::string label, double y) {
    plot.series.push_back({std::move(label), {x0, x1}, {y, y}, {}});
  };
  line(fmt::format("rmse {:.4g} {}", s.rmse, unit), s.rmse);
  line(fmt::format("mean {:.4g} {}", s.mean, unit), s.mean);
  line(fmt::format("median {:.4g} {}", s.median, unit), s.median);
  line(fmt::format("mean - std ({:.4g} {})", s.std, unit), s.mean - s.std);
  line(fmt::format("mean + std ({:.4g} {})", s.std, unit), s.mean + s.std);
}

std::string per_pose_csv(const EvalResult& r) {
  fmt::memory_buffer out;
  fmt::format_to(std::back_inserter(out),
                 "{},gt_x,gt_y,gt_z,est_x,est_y,est_z,ate_trans_m,ate_rot_deg\n",
                 r.has_stamps ? "stamp_s" : "index");
  for (size_t i = 0; i < r.p_gt.size(); ++i) {
    const Eigen::Vector3d& g = r.p_gt[i];
    const Eigen::Vector3d& e = r.p_est_aligned[i];
    if (r.has_stamps) {
      fmt::format_to(std::back_inserter(out), "{},", to_seconds_text(r.stamps[i]));
    } else {
      fmt::format_to(std::back_inserter(out), "{},", i);
    }
    fmt::format_to(std::back_inserter(out), "{},{},{},{},{},{},{},{}\n", g.x(), g.y(), g.z(), e.x(),
                   e.y(), e.z(), r.ate_trans_errors[i], r.ate_rot_errors_deg[i]);
  }
  return fmt::to_string(out);
}

std::string segments_csv(const RpeResult& rpe) {
  fmt::memory_buffer out;
  fmt::format_to(std::back_inserter(out), "first,last,length_m,trans_m,rot_deg\n");
  for (const Segment& s : rpe.segments) {
    fmt::format_to(std::back_inserter(out), "{},{},{},{},{}\n", s.first, s.last, s.length, s.trans,
                   s.rot_deg);
  }
  return fmt::to_string(out);
}

}  // namespace

void write_bench_report(const EvalResult& r, const fs::path& dir,
                        const std::map<std::string, std::string>& inputs,
                        const ReportOptions& options) {
  const PlotMode mode =
      options.plot_mode == PlotMode::automatic ? dominant_plane(r.p_gt) : options.plot_mode;
  const auto [a, b] = plane_axes(mode);
  const char* axis_names = "xyz";
  report::Plot top;
  top.title =
      fmt::format("Trajectories in the {} plane (estimate coloured by ATE)", to_string(mode));
  top.x_label = fmt::format("{} [m]", axis_names[a]);
  top.y_label = fmt::format("{} [m]", axis_names[b]);
  top.value_label = "ATE [m]";
  top.equal_axes = true;
  report::PlotSeries gt{"ground truth", {}, {}, {}}, est{"estimate", {}, {}, r.ate_trans_errors};
  for (size_t i = 0; i < r.p_gt.size(); ++i) {
    gt.x.push_back(r.p_gt[i][a]), gt.y.push_back(r.p_gt[i][b]);
    est.x.push_back(r.p_est_aligned[i][a]), est.y.push_back(r.p_est_aligned[i][b]);
  }
  top.series = {std::move(gt), std::move(est)};

  // Time since the first pair, or the pose index for files without stamps.
  auto along_x = [&](size_t i) {
    return r.has_stamps ? (r.stamps[i] - r.stamps.front()).seconds() : static_cast<double>(i);
  };
  const std::string x_label = r.has_stamps ? "time since the first pair [s]" : "pose index";
  report::Plot ate;
  ate.title = "ATE along the trajectory (translation)";
  ate.x_label = x_label;
  ate.y_label = "translation error [m]";
  report::PlotSeries e{"ATE", {}, r.ate_trans_errors, {}};
  e.x.reserve(r.stamps.size());
  for (size_t i = 0; i < r.stamps.size(); ++i) e.x.push_back(along_x(i));
  const double x_end = e.x.empty() ? 1.0 : e.x.back();
  ate.series = {std::move(e)};
  add_statistics_lines(ate, r.ate_trans, 0.0, x_end, "m");

  report::Plot rpe_plot;
  const RpeResult* delta = find_rpe(r, "delta");
  rpe_plot.title = delta ? fmt::format("RPE, {} (translation)", delta->definition) : "RPE";
  rpe_plot.x_label = fmt::format("{} (the pair's first pose)", x_label);
  rpe_plot.y_label = "translation error [m]";
  if (delta && !delta->segments.empty()) {
    report::PlotSeries d{"RPE", {}, {}, {}};
    d.x.reserve(delta->segments.size()), d.y.reserve(delta->segments.size());
    for (const Segment& s : delta->segments)
      d.x.push_back(along_x(s.first)), d.y.push_back(s.trans);
    rpe_plot.series = {std::move(d)};
    add_statistics_lines(rpe_plot, delta->trans, 0.0, x_end, "m");
  }

  nlohmann::json summary = bench_json(r, inputs);
  summary["plots"] = {{"plane", to_string(mode)},
                      {"along", r.has_stamps ? "time" : "pose index"},
                      {"files", {"trajectory.svg", "ate.svg", "rpe.svg"}}};
  std::vector<io::OutputFile> files;
  if (options.per_pose) {
    std::vector<std::string> names = {"per_pose.csv"};
    files.push_back({dir / "per_pose.csv", per_pose_csv(r)});
    for (const RpeResult& k : r.rpe) {
      if (k.segments.empty()) continue;
      names.push_back(fmt::format("segments_{}.csv", k.kind));
      files.push_back({dir / names.back(), segments_csv(k)});
    }
    summary["per_pose_files"] = names;
  }
  files.push_back({dir / "bench.json", report::json_text(summary)});
  files.push_back({dir / "trajectory.svg", report::render_svg(top)});
  files.push_back({dir / "ate.svg", report::render_svg(ate)});
  files.push_back({dir / "rpe.svg", report::render_svg(rpe_plot)});
  io::write_files_atomic(files);
}

LeaderboardInput load_leaderboard_input(const fs::path& gt_dir, const fs::path& est_dir,
                                        const std::string& methods,
                                        const io::TrajectoryReadOptions& read_options,
                                        LeaderboardInput in) {
  std::error_code ec;
  if (!fs::is_directory(gt_dir, ec)) throw Error(fmt::format("{}: not a folder", gt_dir.string()));
  if (!fs::is_directory(est_dir, ec))
    throw Error(fmt::format("{}: not a folder", est_dir.string()));
  for (const auto& entry : fs::directory_iterator(gt_dir)) {
    const std::string name = entry.path().filename().string();
    const std::string suffix = "_gt.txt";
    if (name.size() > suffix.size() && name.substr(name.size() - suffix.size()) == suffix) {
      in.sequences.push_back(name.substr(0, name.size() - suffix.size()));
    }
  }
  std::sort(in.sequences.begin(), in.sequences.end());
  if (in.sequences.empty())
    throw Error(fmt::format("{}: no <sequence>_gt.txt files", gt_dir.string()));
  for (const std::string& seq : in.sequences) {
    in.ground_truths.push_back(
        io::read_trajectory(gt_dir / (seq + "_gt.txt"), read_options).trajectory);
  }
  std::vector<fs::path> folders;
  if (methods.empty()) {
    in.methods = {est_dir.filename().string()};
    folders = {est_dir};
  } else {
    size_t start = 0;
    while (start <= methods.size()) {
      const size_t comma = std::min(methods.find(',', start), methods.size());
      const std::string m = methods.substr(start, comma - start);
      if (!m.empty()) {
        in.methods.push_back(m);
        folders.push_back(est_dir / m);
      }
      start = comma + 1;
    }
  }
  for (const fs::path& folder : folders) {
    in.estimates.emplace_back();
    in.problems.emplace_back();
    for (const std::string& seq : in.sequences) {
      const fs::path file = folder / (seq + "_es.txt");
      try {
        if (!fs::exists(file)) throw Error(fmt::format("missing {}", file.string()));
        in.estimates.back().push_back(io::read_trajectory(file, read_options).trajectory);
        in.problems.back().emplace_back();
      } catch (const Error& e) {
        in.estimates.back().emplace_back(std::nullopt);
        in.problems.back().push_back(e.what());
      }
    }
  }
  return in;
}

std::string leaderboard_markdown(const Leaderboard& b) {
  std::string out = fmt::format(
      "| rank | method | RPE rank | ATE rank | failed |{}\n|---|---|---|---|---|{}\n",
      fmt::format("{}", fmt::join(b.sequences, " RPE % / ATE m |")) +
          (b.sequences.empty() ? "" : " RPE % / ATE m |"),
      std::string(b.sequences.size() * 4, '-').empty() ? "" : [&] {
        std::string s;
        for (size_t i = 0; i < b.sequences.size(); ++i) s += "---|";
        return s;
      }());
  for (size_t i = 0; i < b.rows.size(); ++i) {
    const MethodRow& row = b.rows[i];
    out += fmt::format("| {} | {} | {:.4f} | {:.4f} | {} |", i + 1, row.method, row.rpe_rank,
                       row.ate_rank, row.n_failed);
    for (const Entry& e : row.entries) {
      out += e.ok ? fmt::format(" {:.4f} / {:.4f} |", e.rpe_pct, e.ate) : " failed |";
    }
    out += "\n";
  }
  out += fmt::format(
      "\nConvention {}. RPE: {}; ATE: {}. Rank = sum over sequences of max(0, threshold - error) "
      "(RPE threshold {} %, ATE threshold {} m): the area under the cumulative curve up to the "
      "threshold. Failed or missing sequences add 0.\n",
      to_string(b.convention), b.rpe_definition, b.ate_definition, b.rpe_max, b.ate_max);
  return out;
}

std::string leaderboard_csv(const Leaderboard& b) {
  std::string out = "method,sequence,ok,rpe_trans_pct,rpe_rot_deg_per_m,ate_m,problem\n";
  for (const MethodRow& row : b.rows) {
    for (size_t s = 0; s < b.sequences.size(); ++s) {
      const Entry& e = row.entries[s];
      std::string problem = e.problem;
      std::replace(problem.begin(), problem.end(), '"', '\'');
      out += fmt::format("{},{},{},{},{},{},\"{}\"\n", row.method, b.sequences[s], e.ok ? 1 : 0,
                         e.ok ? fmt::format("{}", e.rpe_pct) : "",
                         e.ok ? fmt::format("{}", e.rpe_rot) : "",
                         e.ok ? fmt::format("{}", e.ate) : "", problem);
    }
  }
  return out;
}

nlohmann::json leaderboard_json(const Leaderboard& b) {
  nlohmann::json j;
  j["tool_version"] = version_string();
  j["convention"] = to_string(b.convention);
  j["sequences"] = b.sequences;
  j["rpe_definition"] = b.rpe_definition;
  j["ate_definition"] = b.ate_definition;
  j["rpe_threshold_pct"] = b.rpe_max;
  j["ate_threshold_m"] = b.ate_max;
  for (const MethodRow& row : b.rows) {
    nlohmann::json m{{"method", row.method},
                     {"rpe_rank", row.rpe_rank},
                     {"ate_rank", row.ate_rank},
                     {"n_failed", row.n_failed}};
    for (size_t s = 0; s < b.sequences.size(); ++s) {
      const Entry& e = row.entries[s];
      m["sequences"][b.sequences[s]] = {{"ok", e.ok},
                                        {"rpe_trans_pct", number_or_null(e.ok, e.rpe_pct)},
                                        {"rpe_rot_deg_per_m", number_or_null(e.ok, e.rpe_rot)},
                                        {"ate_m", number_or_null(e.ok, e.ate)},
                                        {"problem", e.problem}};
    }
    j["methods"].push_back(m);
  }
  return j;
}

void write_leaderboard_report(const Leaderboard& b, const fs::path& dir) {
  report::Plot ate, rpe;
  ate.title = "Cumulative ATE: fraction of sequences under an error";
  ate.x_label = "ATE [m]";
  rpe.title = "Cumulative RPE: fraction of sequences under an error";
  rpe.x_label = "RPE [%]";
  ate.y_label = rpe.y_label = "fraction of sequences";
  ate.step = rpe.step = true;
  for (const MethodRow& row : b.rows) {
    std::vector<double> a, r;
    for (const Entry& e : row.entries) {
      a.push_back(e.ok ? e.ate : INFINITY);
      r.push_back(e.ok ? e.rpe_pct : INFINITY);
    }
    report::PlotSeries sa{row.method, {}, {}, {}}, sr{row.method, {}, {}, {}};
    for (const auto& [x, y] : cumulative_curve(a, b.ate_max)) sa.x.push_back(x), sa.y.push_back(y);
    for (const auto& [x, y] : cumulative_curve(r, b.rpe_max)) sr.x.push_back(x), sr.y.push_back(y);
    ate.series.push_back(sa);
    rpe.series.push_back(sr);
  }
  io::write_files_atomic({{dir / "leaderboard.md", leaderboard_markdown(b)},
                          {dir / "leaderboard.csv", leaderboard_csv(b)},
                          {dir / "leaderboard.json", report::json_text(leaderboard_json(b))},
                          {dir / "cumulative_ate.svg", report::render_svg(ate)},
                          {dir / "cumulative_rpe.svg", report::render_svg(rpe)}});
}

}  // namespace rigcal::bench
