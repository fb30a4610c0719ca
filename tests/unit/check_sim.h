#pragma once
// `rigcal check` on simulated sessions (doc/check.md, "Measured"): the sample rig's session of one
// seed calibrated once, then a new session of another seed recorded with the rig as it was or
// with one thing changed (a camera turned or moved, a clock shifted, the LiDAR moved), checked
// against that calibration. Shared by the short test (make test) and the long one.
#include <fmt/format.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <random>
#include <string>

#include "cli_run.h"
#include "rigcal/core/se3.h"
#include "rigcal/rig/rig.h"
#include "rigcal/rig/rig_yaml.h"

namespace rigcal::testing {

// A change of the rig, and the sensor it moves.
struct RigChange {
  std::string name, sensor;
  std::function<void(rig::Rig&, std::mt19937_64&)> apply;
};

inline Eigen::Vector3d random_direction(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
}

// The acceptance's changes, each in a random direction.
inline std::vector<RigChange> acceptance_changes() {
  return {
      {"unchanged", "", [](rig::Rig&, std::mt19937_64&) {}},
      {"cam_r turned 0.2 deg", "cam_r",
       [](rig::Rig& r, std::mt19937_64& rng) {
         SE3& T = rig::sensor(r, "cam_r").T_base_sensor;
         T.R = T.R * rotation_from_vector(random_direction(rng) * 0.2 * M_PI / 180);
       }},
      {"cam_r moved 3 mm", "cam_r",
       [](rig::Rig& r, std::mt19937_64& rng) {
         rig::sensor(r, "cam_r").T_base_sensor.t += 0.003 * random_direction(rng);
       }},
      {"imu clock 2 ms", "imu",
       [](rig::Rig& r, std::mt19937_64&) { rig::sensor(r, "imu").time_offset += 0.002; }},
      {"lidar moved 5 mm", "lidar",
       [](rig::Rig& r, std::mt19937_64& rng) {
         // The LiDAR (and its internal IMU) moved within the rig: every other sensor's pose in
         // the LiDAR's frame moves the other way.
         const Eigen::Vector3d d = 0.005 * random_direction(rng);
         for (rig::Sensor& s : r.sensors)
           if (s.name != "lidar" && s.name != "os_imu") s.T_base_sensor.t -= d;
       }},
  };
}

struct CheckOutcome {
  int status = -1;
  nlohmann::json report;  // check.json
  std::string out, err;
};

// `sessions`: the simulator's --what; `config`: its YAML. The reference calibration of `seed`
// is made once in dir/reference (kept between calls).
inline CheckOutcome simulated_check(const std::filesystem::path& dir, uint64_t seed,
                                    const RigChange& change, const std::string& config) {
  namespace fs = std::filesystem;
  const std::string what = "stereo,lidar-camera,imu,trajectories";
  fs::create_directories(dir);
  std::ofstream(dir / "sim.yaml") << config;
  CheckOutcome o;
  const fs::path reference = dir / "reference";
  if (!fs::exists(reference / "calib" / "calib.yaml")) {
    CliRun r = rigcal_cli(fmt::format("simulate --what {} --config {}/sim.yaml --seed {} --out {}",
                                      what, dir.string(), seed, (reference / "rec").string()),
                          dir);
    if (r.status != 0) return {r.status, {}, r.out, r.err};
    r = rigcal_cli(fmt::format("calibrate {0}/rec --rig {1}/data/sample_prior_rig.yaml --out "
                               "{0}/calib",
                               reference.string(), RIGCAL_SOURCE_DIR),
                   dir);
    if (r.status != 0) return {r.status, {}, r.out, r.err};
  }
  // The new session: another seed, the rig as changed.
  rig::Rig truth = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  std::mt19937_64 rng(seed * 7919 + std::hash<std::string>{}(change.name));
  change.apply(truth, rng);
  const fs::path next = dir / "next";
  fs::remove_all(next);
  fs::create_directories(next);
  rig::write_rig_file(truth, next / "truth.yaml");
  CliRun r = rigcal_cli(
      fmt::format(
          "simulate --what {} --config {}/sim.yaml --seed {} --rig {}/truth.yaml --out {}/rec",
          what, dir.string(), seed + 100000, next.string(), next.string()),
      dir);
  if (r.status != 0) return {r.status, {}, r.out, r.err};
  r = rigcal_cli(fmt::format("check --rig {}/calib/calib.yaml --session {}/rec --report {}/check",
                             reference.string(), next.string(), next.string()),
                 dir);
  o.status = r.status;
  o.out = r.out;
  o.err = r.err;
  if (fs::exists(next / "check/check.json"))
    o.report = nlohmann::json::parse(slurp(next / "check/check.json"));
  return o;
}

// Flagged on the right sensor: exit 3, and every changed quantity involves `sensor`.
inline bool flagged_on(const CheckOutcome& o, const std::string& sensor) {
  if (o.status != 3 || o.report.is_null()) return false;
  for (const nlohmann::json& v : o.report["verdicts"]) {
    if (v["verdict"] != "changed") continue;
    const std::vector<std::string> sensors = v["sensors"];
    if (std::find(sensors.begin(), sensors.end(), sensor) == sensors.end()) return false;
  }
  return true;
}

}  // namespace rigcal::testing
