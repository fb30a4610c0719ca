#pragma once
// Reports of the benchmark: bench.json (every figure, named as doc/bench.md defines them), SVG
// plots, and the leaderboard in Markdown, CSV and JSON.
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "rigcal/bench/leaderboard.h"
#include "rigcal/io/trajectory_io.h"

namespace rigcal::bench {

nlohmann::json bench_json(const EvalResult& result,
                          const std::map<std::string, std::string>& inputs);
// DIR/bench.json, DIR/trajectory_top.svg (top view coloured by ATE), DIR/ate_along.svg.
void write_bench_report(const EvalResult& result, const std::filesystem::path& dir,
                        const std::map<std::string, std::string>& inputs);

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
