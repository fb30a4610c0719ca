#pragma once
// What a step read, as the calibration's provenance and the key of the session cache: every
// input file or folder with its SHA-256 (a folder's over its files' names and contents), and the
// `rigcal.steps` section of the calibration YAML.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "rigcal/report/step.h"
#include "rigcal/rig/rig.h"

namespace rigcal::session {

struct HashedInput {
  std::string role;
  std::filesystem::path path;
  std::string sha256;
  size_t files = 1;  // regular files under a folder, 1 for a file
};

// Throws rigcal::Error naming the path when it does not exist or cannot be read.
HashedInput hash_input(const std::string& role, const std::filesystem::path& path);

// One step's record in `rigcal.steps`.
struct StepRecord {
  std::string step, status, tool_version, reason;
  std::vector<HashedInput> inputs;
  std::vector<report::Figure> sigmas, residuals;
  // Read back: names are the stored keys (figure_key of the sigmas they correlate).
  std::vector<report::Correlation> correlations;
};

// The records as YAML flow text, for Rig::extra_metadata under the key "steps".
std::string steps_yaml(const std::vector<StepRecord>& records);
// The records of a rig read from a calibration YAML (empty when it has none). Figures keep the
// key they were written under as their name, with no unit. Throws rigcal::Error when the section
// is not of this shape.
std::vector<StepRecord> read_steps(const rig::Rig& rig);

// The stored sigmas with the correlations among them (those a step stored: within one quantity).
struct StoredUncertainty {
  std::map<std::string, double> sigma;                        // by key, as stored_sigmas
  std::map<std::pair<std::string, std::string>, double> rho;  // by the two keys, both orders
  // The correlation of two keys: 1 for a key with itself, 0 where none is stored.
  double correlation(const std::string& a, const std::string& b) const;
};
// Every 1-sigma the steps stored, by the key it was written under ("T_cam_r_lidar.t.x_m",
// "cam_l.fx_px", "imu.time_offset_s"), with their correlations: of records already read, or of a
// calibration.
StoredUncertainty uncertainty_of(const std::vector<StepRecord>& records);
StoredUncertainty stored_uncertainty(const rig::Rig& rig);

// "name_unit" unless the name ends with the unit already: the key a figure is written under.
std::string figure_key(const report::Figure& figure);

}  // namespace rigcal::session
