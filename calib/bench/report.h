#pragma once
// Reports of the benchmark: bench.json (every figure, named as doc/bench.md defines them), SVG
// plots, and the leaderboard in Markdown, CSV and JSON.
#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "rigcal/bench/leaderboard.h"
#include "rigcal/io/trajectory_io.h"

namespace rigcal::bench {

// The plane a trajectory is drawn in (evo's plot modes): the two axes named.
enum class PlotMode { automatic, xy, xz, yz };
PlotMode plot_mode_from_string(std::string_view name);  // auto|xy|xz|yz
std::string_view to_string(PlotMode mode);
// The two axes along which the positions spread most (KITTI's camera frame, y down: xz).
PlotMode dominant_plane(const std::vector<Eigen::Vector3d>& positions);
// The plane's two coordinates (0 x, 1 y, 2 z); `automatic` as xy.
std::pair<int, int> plane_axes(PlotMode mode);

struct ReportOptions {
  PlotMode plot_mode = PlotMode::automatic;
  bool per_pose = false;  // also the per-pose and per-segment rows, as CSV
};

// The summary: every figure doc/bench.md defines, a few kB whatever the trajectory's length.
nlohmann::json bench_json(const EvalResult& result,
                          const std::map<std::string, std::string>& inputs);
// DIR/bench.json; DIR/trajectory.svg (the plot mode's plane, the estimate coloured by ATE),
// DIR/ate.svg and DIR/rpe.svg (errors along the trajectory with their rmse, mean, median and
// mean +- std as lines); with per_pose, DIR/per_pose.csv and DIR/segments_<kind>.csv. Needs a
// result evaluated with keep_per_pose (and keep_segments for per_pose).
void write_bench_report(const EvalResult& result, const std::filesystem::path& dir,
                        const std::map<std::string, std::string>& inputs,
                        const ReportOptions& options = {});

// Reads GT_DIR/<seq>_gt.txt and, per method, EST_DIR/<method>/<seq>_es.txt (EST_DIR/<seq>_es.txt
// when `methods` is empty). A missing or unreadable estimate is recorded, not fatal.
LeaderboardInput load_leaderboard_input(const std::filesystem::path& gt_dir,
                                        const std::filesystem::path& est_dir,
                                        const std::string& methods,
                                        const io::TrajectoryReadOptions& read_options,
                                        LeaderboardInput base);

std::string leaderboard_markdown(const Leaderboard& board);
std::string leaderboard_csv(const Leaderboard& board);
nlohmann::json leaderboard_json(const Leaderboard& board);
// DIR/leaderboard.{md,csv,json}, DIR/cumulative_ate.svg, DIR/cumulative_rpe.svg.
void write_leaderboard_report(const Leaderboard& board, const std::filesystem::path& dir);

}  // namespace rigcal::bench
