#pragma once
// What the step commands share: progress on the terminal, and a step's result printed and
// written (the report folder and the calibration YAML together, all or nothing).
#include <fmt/format.h>
#include <unistd.h>

#include <filesystem>
#include <memory>
#include <string>

#include "cli.h"
#include "rigcal/io/files.h"
#include "rigcal/report/step.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/session/calibrate.h"
#include "rigcal/session/report_html.h"

namespace rigcal::cli {

// On a terminal, one line updated in place; elsewhere (a log), whole lines, about ten per task.
inline report::Progress console_progress() {
  const bool tty = ::isatty(2);
  auto last = std::make_shared<std::pair<std::string, size_t>>();
  return [tty, last](std::string_view what, size_t done, size_t total) {
    if (total == 0) return;
    if (tty) {
      fmt::print(stderr, "\r{} {}/{}\033[K", what, done, total);
      if (done >= total) fmt::print(stderr, "\r\033[K");
      return;
    }
    const size_t tenth = done * 10 / total;
    if (last->first == what && last->second == tenth && done < total) return;
    *last = {std::string(what), tenth};
    fmt::print(stderr, "{} {}/{}\n", what, done, total);
  };
}

// Refuses any output that is one of the step's inputs (the rig it updates may be written in
// place: that is not among them). Prints the summary and notes;
// writes the report into `report_dir` (when given: the step's files, run.json and report.html,
// the page) and, when the
// step is ok, the rig into `out` (when given), then the warnings. Undetermined: the report is
// written, the reason and the remedy go to stderr, and the command exits 3 with `out` not written.
inline void finish_step(const report::StepResult& r, const std::string& out,
                        const std::string& report_dir) {
  std::vector<io::OutputFile> files;
  if (!report_dir.empty()) {
    files = report::report_files_in(r, report_dir);
    files.push_back(session::step_run_file(r, report_dir));
  }
  // The page a person reads, rendered from those files once they are written.
  const auto write_page = [&] {
    if (report_dir.empty()) return;
    const io::OutputFile page = session::render_report(report_dir);
    io::write_file_atomic(page.path, page.content);
  };
  std::vector<std::pair<std::string, std::filesystem::path>> inputs;
  for (const report::Input& in : r.inputs) inputs.emplace_back(in.role, in.path);
  std::vector<io::OutputFile> all = files;
  if (!out.empty()) all.push_back({out, ""});
  io::refuse_outputs_over_inputs(all, inputs);
  if (r.status != report::StepStatus::ok) {
    io::write_files_atomic(files);
    write_page();
    for (const std::string& line : r.summary) fmt::print("{}\n", line);
    fmt::print(stderr, "rigcal: {}{}\n", r.reason,
               out.empty() ? "" : fmt::format(" ({} not written)", out));
    if (!r.remedy.empty()) fmt::print(stderr, "rigcal: what would settle it: {}\n", r.remedy);
    throw Exit{3};
  }
  if (!out.empty()) files.push_back({out, rig::rig_to_yaml(r.rig)});
  io::write_files_atomic(files);
  write_page();
  for (const std::string& line : r.summary) fmt::print("{}\n", line);
  for (const std::string& n : r.notes) fmt::print("note: {}\n", n);
  for (const std::string& w : r.warnings) fmt::print("warning: {}\n", w);
}

}  // namespace rigcal::cli
