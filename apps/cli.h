#pragma once
// The `rigcal` command line: each subcommand lives in its own file and registers itself here.
// Subcommands talk to people; the library computes, calib/io and calib/rig read and write.
#include <CLI/CLI.hpp>
#include <cmath>
#include <string>

namespace rigcal::cli {

// Thrown by a subcommand that ends with a status other than 0, 2 or 1 after its message
// (e.g. time-offset's 3: the data give no answer).
struct Exit {
  int status;
};

// Option checks for numbers that must be finite and > 0 (`strict`) or >= 0: CLI11's own ranges
// let NaN through.
inline CLI::Validator finite_number(bool strict) {
  return CLI::Validator(
      [strict](std::string& text) -> std::string {
        double v = 0;
        if (CLI::detail::lexical_cast(text, v) && std::isfinite(v) && (strict ? v > 0 : v >= 0))
          return {};
        return std::string("expected a finite number ") + (strict ? "> 0" : ">= 0") + ", got '" +
               text + "'";
      },
      strict ? "POSITIVE" : "NON-NEGATIVE");
}

// Option checks for a whole count (digits only): CLI11 reads '' as 0 and -1 as a huge count into
// an unsigned, and neither is a count. `what` names it in the message.
inline CLI::Validator whole_count(std::string what) {
  return CLI::Validator(
      [what](std::string& s) -> std::string {
        if (!s.empty() && s.find_first_not_of("0123456789") == std::string::npos) return {};
        return "expected " + what + ", got '" + s + "'";
      },
      "COUNT");
}

// Option checks for a span of seconds within [min_s, max_s] (finite; a span past 1e9 s, 31 years,
// is no recording's and would leave rigcal::Time's range).
inline CLI::Validator seconds_within(double min_s, double max_s = 1e9) {
  return CLI::Validator(
      [min_s, max_s](std::string& text) -> std::string {
        double v = 0;
        if (CLI::detail::lexical_cast(text, v) && std::isfinite(v) && v >= min_s && v <= max_s)
          return {};
        return "expected seconds from " + CLI::detail::to_string(min_s) + " to " +
               CLI::detail::to_string(max_s) + ", got '" + text + "'";
      },
      "SECONDS");
}

// `rigcal rig validate|show|convert`
void add_rig_validate(CLI::App& rig);
void add_rig_show(CLI::App& rig);
void add_rig_convert(CLI::App& rig);
// `rigcal bench`
void add_bench(CLI::App& app);
// `rigcal capture`
void add_capture(CLI::App& app);
// `rigcal simulate`
void add_simulate(CLI::App& app);
// `rigcal cameras`
void add_cameras(CLI::App& app);
// `rigcal time-offset`
void add_time_offset(CLI::App& app);
// `rigcal hand-eye`
void add_hand_eye(CLI::App& app);
void add_lidar_camera(CLI::App& app);
// `rigcal calibrate`, `rigcal publish`
void add_calibrate(CLI::App& app);
void add_publish(CLI::App& app);
// `rigcal diff`, `rigcal check`
void add_diff(CLI::App& app);
void add_check(CLI::App& app);
// `rigcal report`
void add_report(CLI::App& app);
// `rigcal convert`
void add_convert(CLI::App& app);
// `rigcal odometry`
void add_odometry(CLI::App& app);
// `rigcal ground-truth`
void add_ground_truth(CLI::App& app);
// `rigcal target print`
void add_target_print(CLI::App& target);

}  // namespace rigcal::cli
