#pragma once
// Two calibrations of one rig side by side (doc/diff.md): every sensor's pose and clock, each
// camera's intrinsics, and each camera's projection difference over its image (mrcal's
// projection-diff idea: the rays of A's pixels projected through B). Where a calibration's
// `rigcal.steps` holds the 1-sigmas of a quantity, its difference is also given in sigmas of the
// two estimates together, with the chi-square probability of a difference at least that large
// when nothing changed (through the whole covariance where the steps stored the correlations).
#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "rigcal/io/files.h"
#include "rigcal/rig/rig.h"

namespace rigcal::session {

// A difference's size against its uncertainty: where both or either calibration gives sigmas.
// The combined covariance is C_A + C_B, each from its stored sigmas and the correlations the
// step stored among them (none stored: the diagonal).
struct Significance {
  std::vector<double> sigma;  // combined 1-sigma of each component, sqrt(s_A^2 + s_B^2)
  // Each component's 1-sigma with the others known, 1 / sqrt((C^-1)_ii): the size of a change
  // along that component alone is judged against it (equal to sigma when uncorrelated).
  std::vector<double> conditional_sigma;
  double chi2 = 0;                 // d' C^-1 d over the components with a sigma
  int dof = 0;                     // those components
  double p_value = 1;              // P(chi-square(dof) >= chi2): small when the change is real
  bool correlated = false;         // whether stored correlations entered C
  std::vector<size_t> components;  // the components judged, indexes into the difference
  Eigen::MatrixXd whiten;          // W with W' W = C^-1 over `components`: chi2 = |W d|^2
};

// T_a_b in B against A: the rotation Log(R_B R_A') and the translation t_B - t_A, both in frame
// a (the convention of the steps' sigmas: the rotation perturbed on the left, about a's axes).
struct PoseDifference {
  std::string a, b;
  Eigen::Vector3d rotation_rad = Eigen::Vector3d::Zero();
  Eigen::Vector3d translation_m = Eigen::Vector3d::Zero();
  std::optional<Significance> significance;  // rotation x y z (rad), then translation (m)
};

// A sensor's clock against the reference sensor's (RigDifference::base_frame): its time_offset
// less the reference's, B's less A's.
struct ClockDifference {
  std::string sensor;
  double offset_s = 0;
  std::optional<double> drift_ppm;           // where either has a drift (none counts as 0)
  std::optional<Significance> significance;  // of the offset (s), then the drift (ppm)
};

// The same rays through both lenses, on a grid of pixels of A's image: each pixel's ray by A's
// intrinsics, projected by B's. `fitted`: after the rotation that best maps A's rays onto B's
// (what a small turn of the camera absorbs, as mrcal's implied transformation at infinity).
struct ProjectionDifference {
  int columns = 0, rows = 0;              // the grid, row-major
  double step_px = 0;                     // between grid points
  std::vector<double> u, v;               // each grid point's pixel (px)
  std::vector<double> raw_px, fitted_px;  // |difference| per grid point; NaN outside the lens
  double raw_rms_px = 0, raw_max_px = 0, fitted_rms_px = 0, fitted_max_px = 0;
  double fitted_rotation_deg = 0;  // the rotation the fit took out
};

struct CameraDifference {
  std::string camera;
  // B - A of fx fy cx cy and of each distortion coefficient (when the models agree).
  std::vector<std::string> names;
  std::vector<double> values;
  std::optional<Significance> significance;  // of fx fy cx cy, where sigmas are stored
  std::optional<ProjectionDifference> projection;
  std::string note;  // why no projection difference (another model, another resolution)
};

struct RigDifference {
  std::string base_frame;  // where each sensor's pose is compared (T_base_sensor in both)
  std::vector<PoseDifference> poses;      // each sensor but the base, then the steps' relations
  std::vector<ClockDifference> clocks;    // every sensor in both but the reference
  std::vector<CameraDifference> cameras;  // every camera in both
  std::vector<std::string> only_in_a, only_in_b;
  std::vector<std::string> notes;
};

struct DiffConfig {
  double grid_step_px = 20;  // of the projection difference
};

// The two sensors of a relation's frames ("cam_r_lidar" of T_cam_r_lidar): the split at an
// underscore where both parts are sensors of `rig`; none when there is no such split.
std::optional<std::pair<std::string, std::string>> relation_sensors(std::string_view frames,
                                                                    const rig::Rig& rig);

// Poses are compared in A's base frame, or, when B has no sensor of that name, in the first
// sensor of A that B has (said in `notes`). Throws rigcal::Error when they share no sensor.
RigDifference diff_rigs(const rig::Rig& a, const rig::Rig& b, const DiffConfig& config = {});

// The difference as data (doc/diff.md names every key; angles in deg, lengths in mm, clocks in
// ms, as a person reads them).
nlohmann::json diff_json(const RigDifference& d);
// Lines for people: a table of poses, clocks and cameras, each with its sigmas where stored.
std::vector<std::string> diff_lines(const RigDifference& d);
// Each camera's map: projection_diff_<camera>.svg (the fitted difference over the image, with
// its colour bar), by file name.
std::vector<std::pair<std::string, std::string>> projection_maps(const RigDifference& d);
// The report: diff.json, report.html and the maps.
std::vector<io::OutputFile> diff_report_files(const RigDifference& d,
                                              const std::filesystem::path& dir);

}  // namespace rigcal::session
