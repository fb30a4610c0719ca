// rigcal time-offset: the clock offset (and drift) between two sensors that see the same rotation,
// by cross-correlating their angular velocities (doc/time-offset.md).
#include <fmt/format.h>

#include <memory>

#include "cli.h"
#include "rigcal/core/text.h"
#include "rigcal/time_sync/step.h"
#include "step_output.h"

namespace rigcal::cli {
namespace time_offset_command {

void run(const time_sync::ClockRequest& o) {
  const time_sync::ClockRun run = time_sync::resolve_clock_request(o);
  const time_sync::StepInputs& in = run.inputs;

  const report::StepResult r = time_sync::estimate_clock(in, run.options, console_progress());
  finish_step(r, o.out, o.report);
  if (!o.out.empty()) {
    const rig::Sensor& s = rig::sensor(r.rig, in.other.sensor);
    fmt::print("{}: time_offset {:.6f} s{} written to {}\n", s.name, s.time_offset,
               s.time_drift_ppm ? fmt::format(", time_drift_ppm {:.3f} from {}", *s.time_drift_ppm,
                                              to_seconds_text(s.time_drift_epoch))
                                : "",
               o.out);
  }
  if (!o.report.empty()) fmt::print("the page to read: {}/report.html\n", o.report);
}

}  // namespace time_offset_command

void add_time_offset(CLI::App& app) {
  using namespace time_offset_command;
  auto o = std::make_shared<time_sync::ClockRequest>();
  CLI::App* cmd = app.add_subcommand(
      "time-offset",
      "The clock offset (and drift) between two sensors that see the same rotation, by\n"
      "cross-correlating their angular velocities (doc/time-offset.md). Inputs: IMU logs\n"
      "(vbr-devkit folder or data/imu.txt; tables t,wx,wy,wz[,ax,ay,az]) or pose trajectories\n"
      "(TUM), whose angular velocity comes from consecutive orientations. The result is\n"
      "  t_reference = t_other + offset [+ drift_ppm * 1e-6 * (t_other - epoch)].\n"
      "With --rig, --sensor and --out, the sensor's time_offset (added to its stamps to put them\n"
      "on the base clock) is written: the reference sensor's time_offset plus the offset, and\n"
      "time_drift_ppm / time_drift_epoch where drift is significant.\n"
      "Exit: 0 an offset, 2 bad input (nothing written), 3 no offset (not enough excitation,\n"
      "ambiguous, no overlap, poor correlation): the report is written, the rig is not.");
  cmd->add_option("--reference", o->reference, "the reference stream (file or vbr IMU folder)");
  cmd->add_option("--other", o->other, "the stream whose offset is measured");
  cmd->add_option("--session", o->session,
                  "a session (its motion/ recording), a recording, a bag or folder of bags: "
                  "reference ouster_imu/ (sensor os_imu), other imu/ (sensor imu), unless given");
  cmd->add_option("--reference-format", o->reference_format, "auto | vbr | table | trajectory")
      ->capture_default_str();
  cmd->add_option("--other-format", o->other_format, "auto | vbr | table | trajectory")
      ->capture_default_str();
  cmd->add_option("--reference-columns", o->reference_columns,
                  "table columns, e.g. 'wx,wy,wz,-,t' ('-' skips a field)");
  cmd->add_option("--other-columns", o->other_columns, "table columns of the other stream");
  cmd->add_option("--sensor", o->sensor, "the rig sensor of the other stream");
  cmd->add_option("--reference-sensor", o->reference_sensor,
                  "the rig sensor of the reference stream (its time_offset is added); without "
                  "it the reference is taken as on the base clock");
  cmd->add_option("--rig", o->rig, "the rig to update");
  cmd->add_option("--out", o->out, "output calibration YAML (needs --rig and --sensor)");
  cmd->add_option("--report", o->report,
                  "report folder: time_sync.json, correlation.png, aligned.png, windows.png, "
                  "report.html (the page to read)");
  cmd->add_option("--max-offset", o->max_offset,
                  "search |offset| up to this many seconds, or 'all' (every lag with enough "
                  "overlap)")
      ->capture_default_str();
  cmd->add_option("--min-overlap", o->min_overlap,
                  "overlap a lag must leave, fraction of the shorter stream")
      ->check(finite_number(true) & CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--window", o->window_s,
                  "drift windows in seconds (0: overlap/10, at least 20 s)")
      ->check(finite_number(false))
      ->capture_default_str();
  cmd->add_option("--min-excitation", o->min_excitation,
                  "rad/s: std of |w| below this is 'not enough excitation'")
      ->check(finite_number(false))
      ->capture_default_str();
  cmd->add_flag("--no-three-axis", o->no_three_axis,
                "skip the relative rotation and the three-axis refinement");
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::cli
