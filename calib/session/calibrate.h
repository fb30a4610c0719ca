#pragma once
// The per-session calibration (doc/session.md): the steps in order on a session's recordings,
// the calibration YAML published once, atomically, only when every step is ok.
//
//   cameras       stereo/          intrinsics of cam_l and cam_r, their extrinsic
//   lidar_camera  lidar_camera/    T_cam_r_lidar (the right camera, as VBR), other cameras follow
//   time_sync     motion/          the external IMU's clock against the LiDAR's internal IMU
//   hand_eye      motion/          T_gnss_lidar and the GNSS/INS clock offset, from the LiDAR
//                                  odometry and the GNSS/INS trajectory
//
// Each step's report goes to OUT/reports/<step>/, its result to OUT/cache/<step>.json, keyed by
// the hashes of the files it reads, the rig entries it reads, its options and the tool version:
// a rerun with unchanged inputs reuses it. A step that fails (bad input) or cannot determine its
// parameters is named with its reason; the steps that do not depend on it still run; nothing is
// published then.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/camera/step.h"
#include "rigcal/hand_eye/step.h"
#include "rigcal/lidar_camera/step.h"
#include "rigcal/report/step.h"
#include "rigcal/time_sync/step.h"

namespace rigcal::session {

// The steps in the order they run.
inline constexpr const char* kSteps[] = {"cameras", "lidar_camera", "time_sync", "hand_eye"};
// Throws rigcal::Error listing the names for one that is not a step.
void check_step_name(std::string_view name);

struct CalibrateOptions {
  std::filesystem::path session, out;
  // Override what session.yaml names (or its defaults): the prior rig, the target, the motion's
  // LiDAR odometry and GNSS/INS trajectory.
  std::filesystem::path rig, target, odometry, gnss;
  std::string from, only;  // a step name or ""
  camera::StepOptions cameras;
  lidar_camera::StepOptions lidar_camera;
  time_sync::TimeSyncOptions time_sync;
  hand_eye::StepOptions hand_eye = [] {
    hand_eye::StepOptions o;
    o.estimate_offset = true;
    return o;
  }();
};

struct StepRun {
  std::string step;
  // ok, undetermined (the data do not determine it), failed (bad input or an internal error),
  // blocked (a step it depends on failed or is undetermined), not run (--only, or a step it
  // depends on was not run).
  std::string status;
  bool cached = false;  // taken from OUT/cache without running
  double seconds = 0;   // running time (0 when cached or not run)
  std::string reason, remedy;
  std::vector<std::string> summary, notes, warnings;
  std::vector<report::Figure> sigmas, residuals;
  std::vector<report::Correlation> correlations;
};

// What a step's result says, as calibrate records it (no time, not cached).
StepRun step_run(const report::StepResult& r);
// A single step's command with a report folder (`rigcal cameras --report DIR`): DIR/run.json,
// the step's run as OUT/reports/calibrate.json holds each step's, from which `render_report`
// (report_html.h) renders DIR/report.html.
io::OutputFile step_run_file(const report::StepResult& r, const std::filesystem::path& dir);

struct CalibrateResult {
  std::vector<StepRun> steps;
  rig::Rig rig;  // with every step that ended ok written in
  bool published = false;
  std::filesystem::path calibration;  // OUT/calib.yaml when published
  // Not published: an earlier run's OUT/calib.yaml, removed since it does not match these inputs.
  std::filesystem::path removed_stale;
  // 0 every step that ran is ok (published when all ran); 2 a step failed on bad input; 3 a step
  // is undetermined (and none failed); 1 a step hit an internal error.
  int exit_status = 0;
};

// Lines of progress for people: "[cameras] detecting the target 12/40".
using Progress = report::Progress;

// Throws rigcal::Error for bad input that stops the whole run (no session, no rig, a --from step
// without the earlier steps' cached results); a step's own bad input is a failed StepRun.
CalibrateResult calibrate(const CalibrateOptions& options, const Progress& progress = {});

// What a run says to people: `lines` for stdout (each step that ran: its summary, notes,
// warnings, reason and remedy; the table of steps; what was published or removed; the page to
// read; "" a blank line) and `error_line` for stderr, last: the first step that failed (else was
// undetermined) with its reason, "" when none did.
struct CalibrateText {
  std::vector<std::string> lines;
  std::string error_line;
};
CalibrateText calibrate_text(const CalibrateResult& result, const std::filesystem::path& out);

}  // namespace rigcal::session
