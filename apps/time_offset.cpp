// rigcal time-offset: the clock offset (and drift) between two sensors that see the same rotation,
// by cross-correlating their angular velocities (doc/time-offset.md).
#include <fmt/format.h>

#include <limits>
#include <memory>

#include "cli.h"
#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/io/session.h"
#include "rigcal/time_sync/step.h"
#include "step_output.h"

namespace rigcal::cli {
namespace {

struct Options {
  std::string reference, other, session, sensor, reference_sensor, rig, out, report;
  std::string reference_format = "auto", other_format = "auto";
  std::string reference_columns, other_columns;
  std::string max_offset = "1";
  double min_overlap = 0.5, window_s = 0.0, min_excitation = 0.05;
  bool no_three_axis = false;
};

io::RateReadOptions read_options(const std::string& format, const std::string& columns,
                                 const char* what) {
  io::RateReadOptions ro;
  try {
    ro.format = io::rate_format_from_string(format);
  } catch (const Error& e) {
    throw Error(fmt::format("--{}-format: {}", what, e.what()));
  }
  ro.columns = columns;
  if (!columns.empty() && ro.format == io::RateReadOptions::Format::automatic)
    ro.format = io::RateReadOptions::Format::table;
  return ro;
}

time_sync::TimeSyncOptions sync_options(const Options& o) {
  time_sync::TimeSyncOptions t;
  if (o.max_offset == "all") {
    t.max_offset_s = std::numeric_limits<double>::infinity();
  } else {
    try {
      t.max_offset_s = parse_double(o.max_offset, "--max-offset");
    } catch (const Error&) {
      t.max_offset_s = 0;
    }
    if (!(t.max_offset_s > 0))
      throw Error(
          fmt::format("--max-offset: expected seconds > 0 or 'all', got '{}'", o.max_offset));
  }
  if (!(o.min_overlap > 0 && o.min_overlap <= 1))
    throw Error(fmt::format("--min-overlap: expected a fraction in (0, 1], got {}", o.min_overlap));
  if (o.window_s < 0) throw Error("--window: expected seconds >= 0 (0: automatic)");
  t.min_overlap = o.min_overlap;
  t.window_s = o.window_s;
  t.min_excitation_rad_s = o.min_excitation;
  t.three_axis = !o.no_three_axis;
  return t;
}

void run(const Options& o) {
  // Inputs: explicit files, or the session's motion recording (the LiDAR's internal IMU, on the
  // base clock, as reference; the external IMU as the other stream), each unless given.
  time_sync::StepInputs in;
  if (!o.session.empty())
    in = time_sync::streams_of_recording(io::recording_for(io::read_session(o.session), "motion"));
  if (!o.reference.empty()) in.reference.path = o.reference;
  if (!o.other.empty()) in.other.path = o.other;
  if (!o.sensor.empty()) in.other.sensor = o.sensor;
  if (!o.reference_sensor.empty()) in.reference.sensor = o.reference_sensor;
  if (in.reference.path.empty() || in.other.path.empty())
    throw Error("give --reference and --other (IMU logs or trajectories), or --session DIR");
  if (!o.out.empty() && (o.rig.empty() || in.other.sensor.empty()))
    throw Error("--out writes the time_offset of --sensor into --rig: give both");
  const time_sync::TimeSyncOptions topt = sync_options(o);
  in.reference.read = read_options(o.reference_format, o.reference_columns, "reference");
  in.other.read = read_options(o.other_format, o.other_columns, "other");
  io::refuse_outputs_over_inputs(
      {{o.out, ""}},
      {{"--reference", in.reference.path}, {"--other", in.other.path}});  // --rig may be --out
  if (!o.rig.empty()) in.rig = rig::read_rig_file(o.rig);  // read first: a bad rig fails fast

  const report::StepResult r = time_sync::estimate_clock(in, topt, console_progress());
  finish_step(r, o.out, o.report);
  if (!o.out.empty()) {
    const rig::Sensor& s = rig::sensor(r.rig, in.other.sensor);
    fmt::print("{}: time_offset {:.6f} s{} written to {}\n", s.name, s.time_offset,
               s.time_drift_ppm ? fmt::format(", time_drift_ppm {:.3f} from {}", *s.time_drift_ppm,
                                              to_seconds_text(s.time_drift_epoch))
                                : "",
               o.out);
  }
  if (!o.report.empty()) fmt::print("report: {}/time_sync.json and PNGs\n", o.report);
}

}  // namespace

void add_time_offset(CLI::App& app) {
  auto o = std::make_shared<Options>();
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
                  "a session (its motion/ recording) or a recording: reference ouster_imu/ "
                  "(sensor os_imu), other imu/ (sensor imu), unless given");
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
                  "report folder: time_sync.json, correlation.png, aligned.png, windows.png");
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
