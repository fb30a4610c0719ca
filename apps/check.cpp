// rigcal check --rig CALIB.yaml --session NEW: does a calibration still fit new data?
// (doc/check.md)
#include "rigcal/session/check.h"

#include <fmt/format.h>
#include <unistd.h>

#include <memory>

#include "cli.h"
#include "rigcal/rig/rig_yaml.h"
#include "step_output.h"

namespace rigcal::cli {
namespace check_command {

struct Options {
  std::string rig, session, report;
  double alarm_p = 1e-3;
};

void run(const Options& o) {
  namespace fs = std::filesystem;
  session::CheckOptions options;
  options.alarm_p = o.alarm_p;
  options.calibrate.session = o.session;
  // The re-estimate's reports and cache: in the report folder, or a temporary one removed after.
  const bool keep = !o.report.empty();
  const fs::path work =
      keep ? fs::path(o.report) / "estimate"
           : fs::temp_directory_path() / fmt::format("rigcal_check_{}", ::getpid());
  options.calibrate.out = work;
  const rig::Rig stored = rig::read_rig_file(o.rig);
  session::CheckResult r;
  try {
    r = session::check(stored, o.rig, options, console_progress());
  } catch (...) {
    if (!keep) fs::remove_all(work);
    throw;
  }
  if (!keep) fs::remove_all(work);
  for (const session::StepRun& s : r.estimate.steps) {
    fmt::print("== {} on {}: {}{}\n", s.step, o.session, s.status, s.cached ? " (cached)" : "");
    for (const std::string& n : s.notes) fmt::print("note: {}\n", n);
    for (const std::string& w : s.warnings) fmt::print("warning: {}\n", w);
  }
  for (const std::string& line : session::check_lines(r)) fmt::print("{}\n", line);
  if (keep) {
    const std::vector<io::OutputFile> files = session::check_report_files(r, o.report);
    io::refuse_outputs_over_inputs(files, {{"the calibration", o.rig}, {"the session", o.session}});
    io::write_files_atomic(files);
    fmt::print("report: {0}/report.html, {0}/check.json (the re-estimate's own reports in {1})\n",
               o.report, work.string());
  }
  if (r.exit_status != 0) throw Exit{r.exit_status};
}

}  // namespace check_command

void add_check(CLI::App& app) {
  using namespace check_command;
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "check",
      "Does a calibration still fit new data? (doc/check.md) Runs the calibration steps on the\n"
      "new session, starting from the stored calibration, and compares each quantity a step\n"
      "estimated (the stereo extrinsic, each camera's intrinsics, T_cam_lidar, the IMU's clock,\n"
      "T_gnss_lidar and the GNSS/INS clock) with the stored one through both sigmas: chi-square\n"
      "and its probability if nothing changed. Verdicts: consistent; changed (p < --alarm-p, by\n"
      "how much in px, mm, deg, ms); cannot tell (the new data do not determine it: what to\n"
      "record). Names the sensors every changed quantity involves. Exit status: 0 nothing\n"
      "changed, 3 something changed, 2 bad input (or a step failed on it), 1 internal error.");
  cmd->add_option("--rig", o->rig, "the calibration to check (rigcal calibrate's calib.yaml)")
      ->required();
  cmd->add_option("--session", o->session, "the new session (the layout of rigcal calibrate)")
      ->required();
  cmd->add_option("--report", o->report,
                  "folder for check.json, diff.json, the projection maps, and the re-estimate's\n"
                  "reports and cache (estimate/); without it they go to a temporary folder");
  cmd->add_option("--alarm-p", o->alarm_p,
                  "a quantity is 'changed' when its chi-square's probability is below this")
      ->capture_default_str()
      ->check(finite_number(true) & CLI::Range(1e-12, 0.5));
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::cli
