// rigcal time-offset: the clock offset (and drift) between two sensors that see the same rotation,
// by cross-correlating their angular velocities (doc/time-offset.md).
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>

#include "cli.h"
#include "rigcal/core/error.h"
#include "rigcal/core/se3.h"
#include "rigcal/core/text.h"
#include "rigcal/core/time.h"
#include "rigcal/io/files.h"
#include "rigcal/io/rates_io.h"
#include "rigcal/io/time_sync_report.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/time_sync/time_sync.h"

namespace rigcal::cli {
namespace {

namespace fs = std::filesystem;

struct Options {
  std::string reference, other, session, sensor, reference_sensor, rig, out, report;
  std::string reference_format = "auto", other_format = "auto";
  std::string reference_columns, other_columns;
  std::string max_offset = "1";
  double min_overlap = 0.5, window_s = 0.0, min_excitation = 0.05;
  bool no_three_axis = false;
};

io::RateFile read_stream(const std::string& path, const std::string& format,
                         const std::string& columns, const char* what) {
  io::RateReadOptions ro;
  try {
    ro.format = io::rate_format_from_string(format);
  } catch (const Error& e) {
    throw Error(fmt::format("--{}-format: {}", what, e.what()));
  }
  ro.columns = columns;
  if (!columns.empty() && ro.format == io::RateReadOptions::Format::automatic)
    ro.format = io::RateReadOptions::Format::table;
  return io::read_rates(path, ro);
}

void run(Options o) {
  // Inputs: explicit files, or the session's two IMU folders (the LiDAR's internal IMU, on the
  // base clock, as reference; the external IMU as the other stream).
  if (!o.session.empty()) {
    if (!fs::is_directory(o.session))
      throw Error(fmt::format("--session {}: not a folder", o.session));
    if (o.reference.empty()) o.reference = (fs::path(o.session) / "ouster_imu").string();
    if (o.other.empty()) o.other = (fs::path(o.session) / "imu").string();
    if (o.sensor.empty()) o.sensor = "imu";
    if (o.reference_sensor.empty()) o.reference_sensor = "os_imu";
  }
  if (o.reference.empty() || o.other.empty())
    throw Error("give --reference and --other (IMU logs or trajectories), or --session DIR");
  if (!o.out.empty() && (o.rig.empty() || o.sensor.empty()))
    throw Error("--out writes the time_offset of --sensor into --rig: give both");

  time_sync::TimeSyncOptions topt;
  if (o.max_offset == "all") {
    topt.max_offset_s = std::numeric_limits<double>::infinity();
  } else {
    try {
      topt.max_offset_s = parse_double(o.max_offset, "--max-offset");
    } catch (const Error&) {
      topt.max_offset_s = 0;
    }
    if (!(topt.max_offset_s > 0))
      throw Error(
          fmt::format("--max-offset: expected seconds > 0 or 'all', got '{}'", o.max_offset));
  }
  if (!(o.min_overlap > 0 && o.min_overlap <= 1))
    throw Error(fmt::format("--min-overlap: expected a fraction in (0, 1], got {}", o.min_overlap));
  if (o.window_s < 0) throw Error("--window: expected seconds >= 0 (0: automatic)");
  topt.min_overlap = o.min_overlap;
  topt.window_s = o.window_s;
  topt.min_excitation_rad_s = o.min_excitation;
  topt.three_axis = !o.no_three_axis;

  // The rig, read before the work so that a bad rig fails fast.
  rig::Rig rig;
  io::TimeSyncInputs in;
  in.reference = o.reference, in.other = o.other;
  in.sensor = o.sensor, in.reference_sensor = o.reference_sensor;
  if (!o.rig.empty()) {
    rig = rig::read_rig_file(o.rig);
    if (!o.sensor.empty() && !rig::find_sensor(rig, o.sensor))
      throw Error(fmt::format("--sensor {}: no such sensor in {}", o.sensor, o.rig));
    if (!o.reference_sensor.empty()) {
      const rig::Sensor* ref = rig::find_sensor(rig, o.reference_sensor);
      if (!ref)
        throw Error(
            fmt::format("--reference-sensor {}: no such sensor in {}", o.reference_sensor, o.rig));
      in.reference_time_offset_s = ref->time_offset;
    }
  }
  if (o.reference_sensor.empty())
    in.notes.push_back("no --reference-sensor: the reference stream is taken as on the base clock");

  const io::RateFile ref =
      read_stream(o.reference, o.reference_format, o.reference_columns, "reference");
  const io::RateFile oth = read_stream(o.other, o.other_format, o.other_columns, "other");
  in.reference_format = ref.format, in.other_format = oth.format;
  for (const std::string& n : ref.notes) in.notes.push_back("reference: " + n);
  for (const std::string& n : oth.notes) in.notes.push_back("other: " + n);
  fmt::print("reference {}: {} samples ({}), {:.1f} s\n", o.reference, ref.rates.stamps.size(),
             ref.format, (ref.rates.stamps.back() - ref.rates.stamps.front()).seconds());
  fmt::print("other     {}: {} samples ({}), {:.1f} s\n", o.other, oth.rates.stamps.size(),
             oth.format, (oth.rates.stamps.back() - oth.rates.stamps.front()).seconds());

  const time_sync::TimeSyncResult r = time_sync::estimate_time_offset(ref.rates, oth.rates, topt);

  std::vector<io::OutputFile> files;
  if (!o.report.empty()) {
    files = io::time_sync_report_files(o.report, r, topt, in, ref.rates, oth.rates);
  }
  if (r.verdict != "ok") {
    io::write_files_atomic(files);
    fmt::print(stderr, "rigcal: no offset: {}: {}{}\n", r.verdict, r.reason,
               o.out.empty() ? "" : fmt::format(" ({} not written)", o.out));
    throw Exit{3};
  }

  fmt::print("offset: t_reference = t_other + {:.6f} s (1-sigma {:.6f} s = {:.3f} ms)\n",
             r.offset_s, r.sigma_s, 1e3 * r.sigma_s);
  fmt::print("peak: NCC {:.3f}, second peak {:.3f} at {:+.4f} s (ratio {:.2f}); overlap {:.1f} s\n",
             r.peak_ncc, r.second_peak_ncc, r.second_peak_offset_s, r.peak_ratio, r.overlap_s);
  if (r.three_axis) {
    const Eigen::Vector3d rpy = roll_pitch_yaw(r.R_reference_other) * 180.0 / M_PI;
    fmt::print(
        "rotation other -> reference (roll pitch yaw): {:.3f} {:.3f} {:.3f} deg; residual RMS "
        "{:.4f} rad/s\n",
        rpy.x(), rpy.y(), rpy.z(), r.residual_rms_rad_s);
  }
  if (r.drift_estimated) {
    fmt::print("drift: {:.3f} ± {:.3f} ppm over {} windows of {:.0f} s: {}\n", r.drift_ppm,
               r.drift_sigma_ppm, r.windows.size(), r.window_s,
               r.drift_significant ? "significant (offset given at the epoch, the other stream's "
                                     "first stamp)"
                                   : "not significant");
  } else {
    fmt::print("drift: not estimated (fewer than 4 usable windows)\n");
  }

  if (!o.out.empty()) {
    rig::set_clock_from(rig, o.sensor, o.reference_sensor, r.offset_s,
                        r.drift_significant ? r.drift_ppm : 0.0, r.epoch);
    files.push_back({o.out, rig::rig_to_yaml(rig)});
  }
  io::write_files_atomic(files);
  if (!o.out.empty()) {
    const rig::Sensor& s = rig::sensor(rig, o.sensor);
    fmt::print("{}: time_offset {:.6f} s{} written to {}\n", o.sensor, s.time_offset,
               s.time_drift_ppm ? fmt::format(", time_drift_ppm {:.3f} from {}", *s.time_drift_ppm,
                                              to_seconds_text(s.time_drift_epoch))
                                : "",
               o.out);
  }
  for (const std::string& n : in.notes) fmt::print("note: {}\n", n);
  if (!o.report.empty()) fmt::print("report: {}/report.json and PNGs\n", o.report);
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
                  "a session folder: reference DIR/ouster_imu (sensor os_imu), other DIR/imu "
                  "(sensor imu), unless given");
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
                  "report folder: report.json, correlation.png, "
                  "aligned.png, windows.png");
  cmd->add_option("--max-offset", o->max_offset,
                  "search |offset| up to this many seconds, or 'all' (every lag with enough "
                  "overlap)")
      ->capture_default_str();
  cmd->add_option("--min-overlap", o->min_overlap,
                  "overlap a lag must leave, fraction of the shorter stream")
      ->capture_default_str();
  cmd->add_option("--window", o->window_s,
                  "drift windows in seconds (0: overlap/10, at least 20 s)")
      ->capture_default_str();
  cmd->add_option("--min-excitation", o->min_excitation,
                  "rad/s: std of |w| below this is 'not enough excitation'")
      ->capture_default_str();
  cmd->add_flag("--no-three-axis", o->no_three_axis,
                "skip the relative rotation and the three-axis refinement");
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::cli
