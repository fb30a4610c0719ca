#pragma once
// The ground-truth step (doc/ground-truth.md): the LiDAR odometry (a file with its step
// covariances, or rigcal's own run on the scans) and the GNSS fixes of a recording, through the
// pose graph, into the LiDAR's trajectory in the fixes' local ENU frame with each pose's
// covariance (stage 1 of the paper's method); then, when the scans are there, the geometric
// LiDAR bundle adjustment over overlapping windows, whose motions replace the odometry's in a
// second pose graph with the same priors (stage 2, without its photometric term).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/gt/map.h"
#include "rigcal/gt/markers.h"
#include "rigcal/gt/motion_fusion.h"
#include "rigcal/gt/pose_graph.h"
#include "rigcal/gt/sequence_ba.h"
#include "rigcal/io/files.h"
#include "rigcal/io/gnss_fixes.h"
#include "rigcal/lidar/step.h"
#include "rigcal/report/step.h"
#include "rigcal/rig/rig.h"

namespace rigcal::gt {

struct StepOptions {
  std::string gnss_sensor = "gnss", lidar_sensor = "lidar";  // the rig's sensors
  // The ENU frame of fixes (a CSV) at this origin instead of at the first fix: sessions that
  // must share one frame. GNSS/INS poses, already in their ENU frame, refuse it.
  std::optional<io::GeodeticOrigin> enu_origin;
  PoseGraphConfig pose_graph;
  // The GNSS/INS attitudes' sigmas (StepInputs::attitude): tilt (roll and pitch, about east and
  // north) and heading, deg. The defaults are conservative for an RTK GNSS/INS (SBG's Ellipse-D
  // states 0.05 deg and 0.2 deg).
  Eigen::Vector2d attitude_sigma_deg{0.1, 0.5};
  // rigcal's odometry, when it runs on StepInputs::scans (lidar::choose_preset).
  std::string odometry_preset;
  bool odometry_sweep_motion = false;
  // Stage 2 on StepInputs::scans (skipped, with a note, when there are none).
  bool bundle_adjustment = true;
  SequenceBaConfig ba;
  // Each adjusted motion fused with the odometry's by covariance intersection (motion_fusion.h)
  // before the second pose graph; false: the adjusted motions alone (doc/ground-truth.md
  // measures both).
  bool fuse_odometry = true;
  // The map of the scans placed by the result (map.h): built when asked, or when a markers'
  // survey is given.
  bool map = false;
  MapConfig map_config;
  MarkerConfig markers;
};

struct StepInputs {
  // T_odom_lidar (any trajectory format) and its step covariances (rigcal odometry's text
  // format; `covariances` empty: beside the odometry, its name without extension +
  // _covariances.txt, what `rigcal odometry` writes).
  std::filesystem::path odometry, covariances;
  // The scans (as lidar::scans_folder gives): rigcal's odometry runs on them when `odometry` is
  // empty, and the bundle adjustment on them (their stamps the odometry's).
  std::filesystem::path scans;
  // GNSS/INS poses (T_enu_gnss; their positions are used) or a CSV of fixes (positions only).
  std::filesystem::path gnss;
  // GNSS/INS poses whose rotations are the INS frame's attitude in the fixes' ENU frame
  // (T_enu_ins, any trajectory format; the rig's GNSS sensor must be its INS frame), taken as
  // priors on the LiDAR's rotation; empty: none.
  std::filesystem::path attitude;
  rig::Rig rig;  // the lever arm (the GNSS sensor's T_b) and its clock (time_offset)
  std::string rig_source;
  // The motions of a job array's chunks of windows (each a trajectory and its step covariances
  // beside it, io::step_covariances_beside: what a run with StepOptions::ba's first_window and
  // end_window writes), joined in place of the bundle adjustment (join_window_motions): the
  // scans are then not read, unless for the map.
  std::vector<std::filesystem::path> window_motions;
  // Survey markers to check the map against (markers.h; io::read_marker_survey), and their file.
  std::optional<MarkerSurvey> markers;
  std::filesystem::path markers_file;
};

struct GroundTruthRun {
  PoseGraphResult graph;  // the last stage's
  // With the bundle adjustment: its windows, and the pose graph of stage 1 it started from.
  std::optional<SequenceBaResult> ba;
  std::optional<PoseGraphResult> stage1;
  // With the fusion: each step's weight on the odometry (0: the adjustment's motion alone).
  std::vector<double> odometry_weight;
  // The fusion's test of the two covariances: the steps whose motions differ by more than the
  // 99 % quantile; above 5 %, no fusion (motion_fusion.h).
  double fusion_disagreeing_fraction = 0;
  bool fused = false;
  std::vector<PositionFix> fixes;
  std::vector<AttitudeFix> attitudes;  // when StepInputs::attitude was given
  double attitude_correlation_s = 0;   // their correlation time (PoseGraphConfig's)
  Eigen::Vector3d p_lidar_antenna = Eigen::Vector3d::Zero();
  std::optional<io::GeodeticOrigin> origin;    // of the ENU frame, when the GNSS gave fixes
  std::optional<lidar::OdometryRun> odometry;  // when rigcal's ran here
  std::optional<LidarMap> map;                 // when asked, from the scans
  std::optional<MarkerCheck> markers;          // when a survey was given
  // A chunk of windows (StepOptions::ba's first_window, end_window): the motions its windows own,
  // chained from stage 1's pose at the first of them, with their covariances; the run stops
  // there (graph is stage 1's; no fusion, no map).
  std::optional<OdometryInput> chunk_motions;
  std::string odometry_preset;
  // The fixes' error correlation time the last solve used, s: the configuration's, or
  // estimated (PoseGraphConfig::fix_correlation_s < 0 asks for that).
  double fix_correlation_s = 0;
  bool fix_correlation_estimated = false;
  std::vector<std::string> notes;
  double seconds = 0;
};

// The step covariances of the trajectory's consecutive poses, matched by their stamps. Throws
// rigcal::Error naming `source` and the first pose pair without one.
std::vector<Matrix6d> covariances_of_steps(const Trajectory& T_odom_lidar,
                                           const std::vector<io::StepCovariance>& steps,
                                           const std::string& source);

// Throws rigcal::Error on unreadable inputs, sensors missing from the rig, or odometry and
// covariances that do not match; what the data cannot fix is in graph.undetermined.
GroundTruthRun run_ground_truth(const StepInputs& inputs, const StepOptions& options,
                                const report::Progress& progress = {});

// The report: the inputs, a summary (poses, path, fixes, priors used and rejected, outages, what
// is undetermined, the priors' residuals, the poses' sigmas), the bundle adjustment's windows
// (their residuals before and after: the map's crispness) and one row a prior
// (doc/ground-truth.md says what each number is).
nlohmann::json ground_truth_report(const GroundTruthRun& run, const StepInputs& inputs);

// What `rigcal ground-truth` prints of a run: poses, fixes and priors, outages, the priors'
// residuals, the fixes' correlation time, the poses' sigmas, the bundle adjustment, the map and
// the markers, the notes (from the report, ground_truth_report).
std::string ground_truth_summary(const GroundTruthRun& run, const nlohmann::json& report);

// Where a run's files go (an empty path: not written).
struct GroundTruthPaths {
  std::filesystem::path trajectory, sigmas, report, map;  // report: the JSON file
};
// The files of a run, with their contents: the trajectory (VBR's format) and its sigmas (when the
// pose graph placed the poses; the sigmas when it gave covariances), the report, the map (when it
// was built). A chunk of windows: its motions (TUM) at `trajectory` and their step covariances
// beside it (io::step_covariances_beside), the report; nothing when it owns no motion.
std::vector<io::OutputFile> ground_truth_files(const GroundTruthRun& run,
                                               const nlohmann::json& report,
                                               const GroundTruthPaths& paths);

// The recording's GNSS file: gnss/poses.tum, gnss/fixes.csv or gnss/navsat.csv, the first there.
// Throws rigcal::Error when none is.
std::filesystem::path default_gnss(const std::filesystem::path& recording);

// The scans a run reads (lidar::scans_folder): `given` when there is one; else the recording's,
// which must be there without an odometry (rigcal's runs on them) and are taken when they are
// there and `wanted` (by the bundle adjustment, the map or the markers); else none.
std::filesystem::path scans_of(const std::filesystem::path& recording,
                               const std::filesystem::path& given, bool odometry_given, bool wanted,
                               const report::Progress& progress = {});

// The files a `rigcal ground-truth` run names (empty: not given).
struct InputFiles {
  std::filesystem::path recording, rig, gnss, attitude, scans, odometry, covariances, markers;
  std::vector<std::filesystem::path> window_motions;
};
// A run's inputs from the files it names: the rig read, the GNSS file (default_gnss when none),
// the scans (scans_of: wanted by the bundle adjustment, the map or the markers of `options`
// and `files`), the odometry with its covariances, the markers' survey, the chunks' motions.
StepInputs step_inputs(const InputFiles& files, const StepOptions& options,
                       const report::Progress& progress = {});

// A run's outputs: `out`, its sigmas (`sigmas`, or OUT without extension + _sigmas.txt), the
// report in `report_dir` (ground_truth.json; none when empty), the map. Throws rigcal::Error
// when one of them is one of the inputs.
GroundTruthPaths ground_truth_paths(const std::filesystem::path& out,
                                    const std::filesystem::path& sigmas,
                                    const std::filesystem::path& report_dir,
                                    const std::filesystem::path& map, const StepInputs& inputs);

// The command line's words for what StepOptions holds as values (`rigcal ground-truth`'s
// options): set into `options`; throws rigcal::Error naming the option on a bad number or origin.
struct CommandWords {
  std::string enu_origin, fix_correlation = "auto", fix_model = "states";
  bool no_bundle_adjustment = false, no_fusion = false, map = false;
  std::pair<size_t, size_t> windows{0, 0};  // FROM:TO; 0:0 all
  std::pair<double, double> attitude_sigma_deg{StepOptions{}.attitude_sigma_deg.x(),
                                               StepOptions{}.attitude_sigma_deg.y()};
  std::pair<double, double> keyframes{StepOptions{}.ba.keyframe_distance_m,
                                      StepOptions{}.ba.keyframe_angle_deg};  // M,DEG
};
void apply_command_words(const CommandWords& words, StepOptions& options);

// A whole `rigcal ground-truth` run: the inputs read, the run, its files written (all or none),
// and what it says: `text` for stdout, `undetermined` lines for stderr, the exit status (0, or 3
// when the fixes leave something undetermined or place no pose). Throws as step_inputs,
// ground_truth_paths and run_ground_truth do.
struct CommandOutcome {
  std::string text;
  std::vector<std::string> undetermined;
  int exit_status = 0;
};
CommandOutcome ground_truth_command(const InputFiles& files, const StepOptions& options,
                                    const std::filesystem::path& out,
                                    const std::filesystem::path& sigmas,
                                    const std::filesystem::path& report_dir,
                                    const std::filesystem::path& map,
                                    const report::Progress& progress = {});

}  // namespace rigcal::gt
