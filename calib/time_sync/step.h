#pragma once
// The clock-offset step (doc/time-offset.md): the offset (and drift) between two sensors that
// see the same rotation, from their angular velocities, written into the rig as the sensor's
// time_offset (and time_drift_ppm where the drift is significant).
#include <filesystem>
#include <optional>
#include <string>

#include "rigcal/io/rates_io.h"
#include "rigcal/report/step.h"
#include "rigcal/time_sync/time_sync.h"

namespace rigcal::time_sync {

// One angular-rate stream: an IMU log (a vbr-devkit folder or its data/imu.txt, a table) or a
// pose trajectory, read by io::read_rates.
struct Stream {
  std::filesystem::path path;
  io::RateReadOptions read;
  std::string sensor;  // the rig's sensor of this stream ("" where not named)
};

struct StepInputs {
  Stream reference, other;
  // The rig: the reference sensor's time_offset is added; with the other stream's sensor named,
  // its clock is written. None: the offset is measured and reported only.
  std::optional<rig::Rig> rig;
};

// The two IMU folders of a recording (doc/session.md): the LiDAR's internal IMU (ouster_imu/,
// sensor os_imu, on the base clock) as the reference and the external IMU (imu/, sensor imu).
StepInputs streams_of_recording(const std::filesystem::path& recording);

// What `rigcal time-offset` is asked, as the command line gives it: explicit streams, or a session
// whose motion recording gives both (each unless given).
struct ClockRequest {
  std::string reference, other, session, sensor, reference_sensor, rig, out, report;
  std::string reference_format = "auto", other_format = "auto";
  std::string reference_columns, other_columns;  // a table's columns; a table when given
  std::string max_offset = "1";                  // seconds, or "all"
  double min_overlap = 0.5, window_s = 0.0, min_excitation = 0.05;
  bool no_three_axis = false;
};

struct ClockRun {
  StepInputs inputs;  // the rig read when the request names one
  TimeSyncOptions options;
};

// Checks the request and resolves it: the session read, an output that is one of the files the
// step reads refused (--rig may be --out), the rig read first so that a bad one fails fast.
// Throws rigcal::Error naming the option on a bad value or a missing stream.
ClockRun resolve_clock_request(const ClockRequest& request);

// Status undetermined when the data give no offset (not enough excitation, ambiguous, no overlap,
// poor correlation): the report is made, the rig is returned unchanged. Throws rigcal::Error on
// bad input (unreadable streams, sensors missing from the rig).
report::StepResult estimate_clock(const StepInputs& inputs, const TimeSyncOptions& options,
                                  const report::Progress& progress = {});

}  // namespace rigcal::time_sync
