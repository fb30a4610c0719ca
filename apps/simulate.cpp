// rigcal simulate: a synthetic session with known truth (doc/simulator.md).
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <memory>

#include "cli.h"
#include "rigcal/core/error.h"
#include "rigcal/io/files.h"
#include "rigcal/io/session_io.h"
#include "rigcal/io/sim_config.h"
#include "rigcal/io/target_yaml.h"
#include "rigcal/rig/rig_yaml.h"
#include "sample_rig.h"

namespace rigcal::cli {
namespace simulate_command {

namespace fs = std::filesystem;

struct Options {
  std::string rig, out, what = "stereo,lidar-camera,imu,trajectories,scans", config, target;
  uint64_t seed = 1;
  bool seed_given = false, force = false;
};

void run(const Options& o) {
  const rig::Rig rig = o.rig.empty() ? rig::parse_rig_yaml(kSampleRigYaml, "<bundled sample rig>")
                                     : rig::read_rig_file(o.rig);
  std::vector<std::string> parts;
  for (size_t start = 0; start <= o.what.size();) {
    const size_t comma = std::min(o.what.find(',', start), o.what.size());
    const std::string part = o.what.substr(start, comma - start);
    if (part != "stereo" && part != "lidar-camera" && part != "imu" && part != "trajectories" &&
        part != "scans" && part != "ground-truth") {
      throw Error(fmt::format(
          "--what: unknown part '{}'; expected stereo, lidar-camera, imu, trajectories, scans, "
          "ground-truth",
          part));
    }
    parts.push_back(part);
    start = comma + 1;
  }
  const auto has = [&](std::string_view p) {
    return std::find(parts.begin(), parts.end(), p) != parts.end();
  };
  if (has("ground-truth") && has("trajectories"))
    throw Error("--what: ground-truth is the trajectories part with sweeps and markers; give one");
  // The ground-truth recording is the trajectories part from its own defaults.
  sim::SimConfig config;
  if (has("ground-truth")) sim::ground_truth_defaults(config);
  if (!o.config.empty()) io::read_sim_config(o.config, config);
  if (o.seed_given) config.seed = o.seed;
  if (!o.target.empty()) config.target = io::read_target_file(o.target);
  const fs::path out = o.out;
  std::error_code ec;
  if (fs::exists(out, ec) && !fs::is_empty(out, ec)) {
    if (!o.force)
      throw Error(
          fmt::format("{}: exists and is not empty; choose a new folder or give --force", o.out));
    io::refuse_replacing_inputs(out,
                                {{"--config", o.config}, {"--rig", o.rig}, {"--target", o.target}});
  }
  // Everything goes to a temporary sibling, renamed into place at the end: a failed run leaves
  // nothing half-written.
  const fs::path tmp = out.string() + fmt::format(".partial-{}", ::getpid());
  fs::remove_all(tmp, ec);
  fs::create_directories(tmp);
  try {
    io::write_simulated_session(tmp, rig, config, parts, [](const std::string& text) {
      fmt::print("{}", text);
      std::fflush(stdout);
    });
    if (fs::exists(out, ec)) fs::remove_all(out);
    fs::rename(tmp, out);
  } catch (...) {
    fs::remove_all(tmp, ec);
    throw;
  }
  fmt::print("wrote {} (truth: {}/truth.yaml, {}/truth.json)\n", o.out, o.out, o.out);
}

}  // namespace simulate_command

void add_simulate(CLI::App& app) {
  using namespace simulate_command;
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "simulate",
      "Write a synthetic session with known truth in the session layout (doc/simulator.md):\n"
      "  stereo        target images seen by both cameras, with the true corners\n"
      "  lidar-camera  scans and images of the target on a stand in a room\n"
      "  imu           two IMU streams of one hand-held motion, on their own clocks\n"
      "  trajectories  true LiDAR poses, drifting LiDAR odometry, GNSS/INS with RTK noise\n"
      "                (trajectories.scans: true in --config adds sweeps along the motion)\n"
      "  scans         LiDAR sweeps along a drive through a street of box buildings\n"
      "  ground-truth  the trajectories part for `rigcal ground-truth`: a 60 s walk with its\n"
      "                sweeps, 6 survey markers (trajectories/markers.csv), RTK noise correlated\n"
      "                over 5 s and a 15 s outage (its defaults; --config changes them)\n"
      "The true rig goes to truth.yaml, the rest of the truth to truth.json. The same seed gives\n"
      "byte-identical files.");
  cmd->add_option("--rig", o->rig, "the true rig (default: the bundled VBR-like sample rig)");
  cmd->add_option("--out", o->out, "output folder (new or empty)")->required();
  cmd->add_option("--what", o->what, "comma-separated parts")->capture_default_str();
  cmd->add_option("--seed", o->seed, "random seed (default 1, or the config's)")
      ->check(CLI::Validator(
          [](std::string& s) {
            return s.empty() ? std::string("expected an integer, got ''") : "";
          },
          "INT"))
      ->each([o](const std::string&) { o->seed_given = true; });
  cmd->add_option("--config", o->config, "simulator settings (YAML; doc/simulator.md)");
  cmd->add_option("--target", o->target, "target YAML (default: the A3 checkerboard)");
  cmd->add_flag("--force", o->force, "replace a non-empty output folder");
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::cli
