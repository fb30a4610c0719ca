#include "rigcal/time_sync/step.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "rigcal/core/error.h"
#include "rigcal/core/se3.h"
#include "rigcal/core/text.h"
#include "rigcal/io/files.h"
#include "rigcal/io/session.h"
#include "rigcal/report/rotation.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/time_sync/report.h"

namespace rigcal::time_sync {
namespace fs = std::filesystem;

StepInputs streams_of_recording(const fs::path& recording) {
  if (!fs::is_directory(recording))
    throw Error(fmt::format("{}: not a folder", recording.string()));
  StepInputs in;
  const fs::path dir = recording.lexically_normal();
  in.reference.path = dir / "ouster_imu";
  in.reference.sensor = "os_imu";
  in.other.path = dir / "imu";
  in.other.sensor = "imu";
  return in;
}

namespace {

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

TimeSyncOptions sync_options(const ClockRequest& o) {
  TimeSyncOptions t;
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
  // Below a second a window holds too few samples to correlate (and 1e-320 s would be 1e320 of
  // them).
  if (!(o.window_s == 0 || (o.window_s >= 1 && std::isfinite(o.window_s))))
    throw Error(
        fmt::format("--window: expected 0 (automatic) or at least 1 s, got {}", o.window_s));
  t.min_overlap = o.min_overlap;
  t.window_s = o.window_s;
  t.min_excitation_rad_s = o.min_excitation;
  t.three_axis = !o.no_three_axis;
  return t;
}

}  // namespace

ClockRun resolve_clock_request(const ClockRequest& o) {
  ClockRun run;
  StepInputs& in = run.inputs;
  if (!o.session.empty())
    in = streams_of_recording(io::recording_for(io::read_session(o.session), "motion"));
  if (!o.reference.empty()) in.reference.path = o.reference;
  if (!o.other.empty()) in.other.path = o.other;
  if (!o.sensor.empty()) in.other.sensor = o.sensor;
  if (!o.reference_sensor.empty()) in.reference.sensor = o.reference_sensor;
  if (in.reference.path.empty() || in.other.path.empty())
    throw Error("give --reference and --other (IMU logs or trajectories), or --session DIR");
  if (!o.out.empty() && (o.rig.empty() || in.other.sensor.empty()))
    throw Error("--out writes the time_offset of --sensor into --rig: give both");
  run.options = sync_options(o);
  in.reference.read = read_options(o.reference_format, o.reference_columns, "reference");
  in.other.read = read_options(o.other_format, o.other_columns, "other");
  std::vector<std::pair<std::string, fs::path>> files_read;
  for (const auto& [what, stream] :
       {std::pair{"--reference", &in.reference}, {"--other", &in.other}})
    for (const fs::path& f : io::rate_files(stream->path)) files_read.emplace_back(what, f);
  io::refuse_outputs_over_inputs({{o.out, ""}}, files_read);
  if (!o.rig.empty()) in.rig = rig::read_rig_file(o.rig);
  return run;
}

report::StepResult estimate_clock(const StepInputs& in, const TimeSyncOptions& topt,
                                  const report::Progress& progress) {
  report::StepResult out;
  out.step = "time_sync";
  TimeSyncInputs rin;
  rin.reference = in.reference.path.string(), rin.other = in.other.path.string();
  rin.sensor = in.other.sensor, rin.reference_sensor = in.reference.sensor;
  if (in.rig) {
    if (!in.other.sensor.empty() && !rig::find_sensor(*in.rig, in.other.sensor))
      throw Error(fmt::format("--sensor {}: no such sensor in the rig", in.other.sensor));
    if (!in.reference.sensor.empty()) {
      const rig::Sensor* ref = rig::find_sensor(*in.rig, in.reference.sensor);
      if (!ref)
        throw Error(
            fmt::format("--reference-sensor {}: no such sensor in the rig", in.reference.sensor));
      rin.reference_time_offset_s = ref->time_offset;
    }
  }
  if (in.reference.sensor.empty())
    rin.notes.push_back(
        "no --reference-sensor: the reference stream is taken as on the base clock");

  report::tell(progress, "reading the angular rates", 0, 2);
  const io::RateFile ref = io::read_rates(in.reference.path, in.reference.read);
  report::tell(progress, "reading the angular rates", 1, 2);
  const io::RateFile oth = io::read_rates(in.other.path, in.other.read);
  report::tell(progress, "reading the angular rates", 2, 2);
  for (const auto* f : {&ref, &oth}) {
    if (f->rates.stamps.size() < 10) {
      throw Error(fmt::format("{}: {} samples; an angular-rate stream needs at least 10",
                              (f == &ref ? in.reference.path : in.other.path).string(),
                              f->rates.stamps.size()));
    }
  }
  rin.reference_format = ref.format, rin.other_format = oth.format;
  for (const std::string& n : ref.notes) rin.notes.push_back("reference: " + n);
  for (const std::string& n : oth.notes) rin.notes.push_back("other: " + n);
  out.summary.push_back(
      fmt::format("reference {}: {} samples ({}), {:.1f} s", rin.reference, ref.rates.stamps.size(),
                  ref.format, (ref.rates.stamps.back() - ref.rates.stamps.front()).seconds()));
  out.summary.push_back(
      fmt::format("other     {}: {} samples ({}), {:.1f} s", rin.other, oth.rates.stamps.size(),
                  oth.format, (oth.rates.stamps.back() - oth.rates.stamps.front()).seconds()));

  const TimeSyncResult r = estimate_time_offset(ref.rates, oth.rates, topt);
  out.report_files = time_sync_report_files("", r, topt, rin, ref.rates, oth.rates);
  out.notes = rin.notes;
  out.inputs = {{"reference", in.reference.path}, {"other", in.other.path}};
  out.rig = in.rig.value_or(rig::Rig{});
  if (r.verdict != "ok") {
    out.status = report::StepStatus::undetermined;
    out.reason = fmt::format("no offset: {}: {}", r.verdict, r.reason);
    out.remedy =
        "record the two IMUs while turning the rig briskly about changing axes for a minute "
        "(at least 0.05 rad/s of variation in the rate's magnitude), with both streams covering "
        "the same time";
    report::finish_report(out, "time_sync.json");
    return out;
  }

  out.summary.push_back(
      fmt::format("offset: t_reference = t_other + {:.6f} s (1-sigma {:.6f} s = {:.3f} ms)",
                  r.offset_s, r.sigma_s, 1e3 * r.sigma_s));
  out.summary.push_back(fmt::format(
      "peak: NCC {:.3f}, second peak {:.3f} at {:+.4f} s (ratio {:.2f}); overlap {:.1f} s",
      r.peak_ncc, r.second_peak_ncc, r.second_peak_offset_s, r.peak_ratio, r.overlap_s));
  if (r.three_axis) {
    const auto [angle_deg, axis] = report::angle_axis_deg(r.R_reference_other);
    out.summary.push_back(fmt::format(
        "rotation other -> reference: {:.3f} deg about [{:.4f} {:.4f} {:.4f}]; residual RMS "
        "{:.4f} rad/s",
        angle_deg, axis.x(), axis.y(), axis.z(), r.residual_rms_rad_s));
  }
  if (r.drift_estimated) {
    out.summary.push_back(fmt::format(
        "drift: {:.3f} ± {:.3f} ppm over {} windows of {:.0f} s: {}", r.drift_ppm,
        r.drift_sigma_ppm, r.windows.size(), r.window_s,
        r.drift_significant ? "significant (offset given at the epoch, the other stream's "
                              "first stamp)"
                            : "not significant"));
  } else {
    out.summary.push_back("drift: not estimated (fewer than 4 usable windows)");
  }
  if (in.rig && !in.other.sensor.empty()) {
    rig::set_clock_from(out.rig, in.other.sensor, in.reference.sensor, r.offset_s,
                        r.drift_significant ? r.drift_ppm : 0.0, r.epoch);
    out.wrote.push_back(in.other.sensor);
  }
  const std::string who = in.other.sensor.empty() ? "other" : in.other.sensor;
  out.sigmas.push_back({who + ".time_offset", r.sigma_s, "s"});
  if (r.drift_estimated) out.sigmas.push_back({who + ".time_drift_ppm", r.drift_sigma_ppm, "ppm"});
  out.residuals = {{"peak_ncc", r.peak_ncc, ""},
                   {"peak_ratio", r.peak_ratio, ""},
                   {"residual_rms_rad_s", r.residual_rms_rad_s, "rad/s"},
                   {"overlap_s", r.overlap_s, "s"}};
  report::finish_report(out, "time_sync.json");
  return out;
}

}  // namespace rigcal::time_sync
