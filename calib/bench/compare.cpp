#include "rigcal/bench/compare.h"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <set>

#include "rigcal/core/error.h"
#include "rigcal/io/files.h"
#include "rigcal/report/json.h"
#include "rigcal/report/svg_plot.h"

namespace rigcal::bench {
namespace fs = std::filesystem;

namespace {

// A column of the table: its header and where its number is in a bench.json.
struct Column {
  std::string header;
  std::vector<std::string> path;
};

std::vector<Column> columns(const std::vector<NamedResult>& results) {
  std::vector<Column> out = {{"ATE rmse [m]", {"ate", "trans", "rmse"}},
                             {"ATE mean [m]", {"ate", "trans", "mean"}},
                             {"ATE median [m]", {"ate", "trans", "median"}},
                             {"ATE std [m]", {"ate", "trans", "std"}},
                             {"ATE max [m]", {"ate", "trans", "max"}},
                             {"ATE rot rmse [deg]", {"ate", "rot", "rmse"}}};
  // The RPE kinds any result has, in a fixed order.
  std::set<std::string> kinds;
  for (const NamedResult& r : results) {
    if (r.summary.contains("rpe")) {
      for (const auto& [kind, value] : r.summary["rpe"].items()) kinds.insert(kind);
    }
  }
  for (const char* kind : {"kitti", "vbr"}) {
    if (kinds.count(kind))
      out.push_back({fmt::format("RPE {} [%]", kind), {"rpe", kind, "trans_pct"}});
  }
  if (kinds.count("delta"))
    out.push_back({"RPE delta rmse [m]", {"rpe", "delta", "trans", "rmse"}});
  return out;
}

// A node of a summary by its path, or null.
const nlohmann::json* node_at(const nlohmann::json& j, const std::vector<std::string>& path) {
  const nlohmann::json* node = &j;
  for (const std::string& key : path) {
    if (!node->is_object() || !node->contains(key)) return nullptr;
    node = &(*node)[key];
  }
  return node;
}

// A number of a summary by its path, or null.
const nlohmann::json* at(const nlohmann::json& j, const std::vector<std::string>& path) {
  const nlohmann::json* node = node_at(j, path);
  return node && node->is_number() ? node : nullptr;
}

std::string cell(const nlohmann::json& summary, const Column& c) {
  const nlohmann::json* v = at(summary, c.path);
  return v ? fmt::format("{:.6g}", v->get<double>()) : "-";
}

std::string convention_of(const NamedResult& r) {
  return r.summary.value("convention", std::string("?"));
}

}  // namespace

NamedResult read_result(const fs::path& path) {
  std::error_code ec;
  const fs::path file = fs::is_directory(path, ec) ? path / "bench.json" : path;
  if (!fs::exists(file, ec)) throw Error(fmt::format("{}: no such file", file.string()));
  NamedResult r;
  try {
    r.summary = nlohmann::json::parse(io::read_text_file(file));
  } catch (const nlohmann::json::exception& e) {
    throw Error(fmt::format("{}: not JSON: {}", file.string(), e.what()));
  }
  if (!r.summary.is_object() || !r.summary.contains("convention") || !r.summary.contains("ate") ||
      !r.summary.contains("rpe")) {
    throw Error(fmt::format(
        "{}: not a rigcal bench result (no convention, ate or rpe; `rigcal bench --report DIR` "
        "writes DIR/bench.json)",
        file.string()));
  }
  const fs::path folder = file.parent_path();
  r.name = folder.empty() ? file.stem().string() : folder.filename().string();
  return r;
}

void make_names_unique(std::vector<NamedResult>& results) {
  std::map<std::string, int> seen;
  for (NamedResult& r : results) {
    const int n = ++seen[r.name];
    if (n > 1) r.name += fmt::format(" ({})", n);
  }
}

std::string compare_markdown(const std::vector<NamedResult>& results) {
  const std::vector<Column> cols = columns(results);
  std::string out = "| result | convention | pairs |";
  std::string rule = "|---|---|---|";
  for (const Column& c : cols) out += fmt::format(" {} |", c.header), rule += "---|";
  out += fmt::format("\n{}\n", rule);
  for (const NamedResult& r : results) {
    out += fmt::format("| {} | {} | {} |", r.name, convention_of(r),
                       r.summary.contains("n_pairs") ? r.summary["n_pairs"].dump() : "-");
    for (const Column& c : cols) out += fmt::format(" {} |", cell(r.summary, c));
    out += "\n";
  }
  std::set<std::string> conventions;
  for (const NamedResult& r : results) conventions.insert(convention_of(r));
  if (conventions.size() > 1) {
    out +=
        "\nnote: the results were computed under different conventions; their figures are "
        "not defined alike (doc/bench.md)\n";
  }
  return out;
}

std::string compare_csv(const std::vector<NamedResult>& results) {
  const std::vector<Column> cols = columns(results);
  std::string out = "result,convention,pairs";
  for (const Column& c : cols) out += fmt::format(",\"{}\"", c.header);
  out += "\n";
  for (const NamedResult& r : results) {
    std::string name = r.name;
    std::replace(name.begin(), name.end(), '"', '\'');
    out += fmt::format("\"{}\",{},{}", name, convention_of(r),
                       r.summary.contains("n_pairs") ? r.summary["n_pairs"].dump() : "");
    for (const Column& c : cols) {
      const nlohmann::json* v = at(r.summary, c.path);
      out += v ? fmt::format(",{}", v->get<double>()) : ",";
    }
    out += "\n";
  }
  return out;
}

nlohmann::json compare_json(const std::vector<NamedResult>& results) {
  nlohmann::json j;
  j["columns"] = nlohmann::json::array();
  const std::vector<Column> cols = columns(results);
  for (const Column& c : cols) j["columns"].push_back({{"header", c.header}, {"path", c.path}});
  for (const NamedResult& r : results) {
    nlohmann::json row{{"result", r.name}, {"convention", convention_of(r)}};
    for (const Column& c : cols) {
      const nlohmann::json* v = at(r.summary, c.path);
      row["values"].push_back(v ? *v : nlohmann::json());
    }
    j["results"].push_back(row);
  }
  return j;
}

namespace {

// evo_res's three views of one metric across the results, from their summaries: the statistics
// as grouped bars, and, for the results whose summary holds the distribution (written with the
// report), box plots and density histograms. Files named <prefix>_{stats,box,histogram}.svg.
std::vector<io::OutputFile> metric_plots(const std::vector<NamedResult>& results,
                                         const std::vector<std::string>& path,
                                         const std::string& metric, const fs::path& prefix) {
  std::vector<io::OutputFile> files;
  const char* stat_names[] = {"rmse", "mean", "median", "std", "min", "max"};
  const double group = 1.0, bar = 0.8 * group / static_cast<double>(results.size());
  report::Plot stats;
  stats.title = fmt::format("{}: statistics of each result", metric);
  stats.y_label = metric;
  for (size_t s = 0; s < std::size(stat_names); ++s)
    stats.x_ticks.emplace_back(static_cast<double>(s), stat_names[s]);
  report::Plot box;
  box.title = fmt::format("{}: quartiles, whiskers at 1.5 IQR", metric);
  box.y_label = metric;
  report::Plot hist;
  hist.title = fmt::format("{}: distribution of each result", metric);
  hist.x_label = metric;
  hist.y_label = "density";
  bool any_stats = false, any_distribution = false;
  for (size_t k = 0; k < results.size(); ++k) {
    const nlohmann::json* node = node_at(results[k].summary, path);
    report::PlotSeries bars{results[k].name, {}, {}, {}};
    bars.bars = true;
    bars.width = bar;
    for (size_t s = 0; node && s < std::size(stat_names); ++s) {
      if (!node->contains(stat_names[s]) || !(*node)[stat_names[s]].is_number()) continue;
      bars.x.push_back(static_cast<double>(s) - 0.4 * group + (static_cast<double>(k) + 0.5) * bar);
      bars.y.push_back((*node)[stat_names[s]].get<double>());
    }
    any_stats = any_stats || !bars.x.empty();
    stats.series.push_back(std::move(bars));
    box.x_ticks.emplace_back(static_cast<double>(k), results[k].name);
    report::PlotSeries b{results[k].name, {}, {}, {}}, h{results[k].name, {}, {}, {}};
    b.width = 0.5;
    h.bars = true;
    const nlohmann::json* d = node ? node_at(*node, {"distribution"}) : nullptr;
    if (d && d->contains("counts") && d->value("n", 0) > 0) {
      any_distribution = true;
      b.x.push_back(static_cast<double>(k));
      b.boxes.push_back({d->value("whisker_low", 0.0), d->value("q1", 0.0), d->value("median", 0.0),
                         d->value("q3", 0.0), d->value("whisker_high", 0.0)});
      const double low = d->value("bin_low", 0.0), width = d->value("bin_width", 1.0);
      const double n = d->value("n", 1.0);
      h.width = width;
      const std::vector<double> counts = (*d)["counts"].get<std::vector<double>>();
      for (size_t i = 0; i < counts.size(); ++i) {
        h.x.push_back(low + (static_cast<double>(i) + 0.5) * width);
        h.y.push_back(counts[i] / (n * width));
      }
    }
    box.series.push_back(std::move(b));
    hist.series.push_back(std::move(h));
  }
  if (!any_stats) return files;
  files.push_back({fs::path(prefix.string() + "_stats.svg"), report::render_svg(stats)});
  if (any_distribution) {
    files.push_back({fs::path(prefix.string() + "_box.svg"), report::render_svg(box)});
    files.push_back({fs::path(prefix.string() + "_histogram.svg"), report::render_svg(hist)});
  }
  return files;
}

}  // namespace

std::vector<std::string> write_compare_report(const std::vector<NamedResult>& results,
                                              const fs::path& dir) {
  std::vector<io::OutputFile> files = {
      {dir / "compare.md", compare_markdown(results)},
      {dir / "compare.csv", compare_csv(results)},
      {dir / "compare.json", report::json_text(compare_json(results))}};
  for (auto& f :
       metric_plots(results, {"ate", "trans"}, "ATE translation [m]", dir / "compare_ate"))
    files.push_back(std::move(f));
  for (auto& f : metric_plots(results, {"rpe", "delta", "trans"},
                              "RPE (delta pairs) translation [m]", dir / "compare_rpe"))
    files.push_back(std::move(f));
  io::write_files_atomic(files);
  std::vector<std::string> names;
  for (const io::OutputFile& f : files) names.push_back(f.path.filename().string());
  return names;
}

void write_overlay_plots(const std::vector<const EvalResult*>& results,
                         const std::vector<std::string>& names, const fs::path& dir,
                         PlotMode mode) {
  if (results.empty()) return;
  const EvalResult& first = *results.front();
  if (mode == PlotMode::automatic) mode = dominant_plane(first.p_gt);
  const auto [a, b] = plane_axes(mode);
  const char* axis = "xyz";
  report::Plot top;
  top.title = fmt::format("Trajectories in the {} plane (each estimate aligned)", to_string(mode));
  top.x_label = fmt::format("{} [m]", axis[a]);
  top.y_label = fmt::format("{} [m]", axis[b]);
  top.equal_axes = true;
  report::Plot ate;
  ate.title = "ATE along the trajectory (translation), each estimate";
  ate.x_label = first.has_stamps ? "time since the first pair [s]" : "pose index";
  ate.y_label = "translation error [m]";
  // The ground truth as the first estimate's pairs saw it.
  report::PlotSeries gt{"ground truth", {}, {}, {}};
  for (const Eigen::Vector3d& p : first.p_gt) gt.x.push_back(p[a]), gt.y.push_back(p[b]);
  top.series.push_back(std::move(gt));
  const Time t0 = first.stamps.empty() ? Time{} : first.stamps.front();
  for (size_t k = 0; k < results.size(); ++k) {
    const EvalResult& r = *results[k];
    report::PlotSeries line{names[k], {}, {}, {}}, err{names[k], {}, r.ate_trans_errors, {}};
    for (const Eigen::Vector3d& p : r.p_est_aligned) line.x.push_back(p[a]), line.y.push_back(p[b]);
    for (size_t i = 0; i < r.stamps.size(); ++i) {
      err.x.push_back(r.has_stamps ? (r.stamps[i] - t0).seconds() : static_cast<double>(i));
    }
    top.series.push_back(std::move(line));
    ate.series.push_back(std::move(err));
  }
  io::write_files_atomic({{dir / "trajectories.svg", report::render_svg(top)},
                          {dir / "ate.svg", report::render_svg(ate)}});
}

}  // namespace rigcal::bench
