// rigcal: calibrate a multi-sensor rig, publish the calibration, score trajectories.
// Exit status: 0 success, 2 bad input or usage (one line on stderr), 1 internal error.
#include <fmt/format.h>

#include <cstdio>
#include <exception>
#include <filesystem>
#include <opencv2/core/utils/logger.hpp>

#include "cli.h"
#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/core/version.h"

namespace main_command {
// A message quotes what it was given (a key, a value, a path): on stderr it stays one line of
// valid text, whatever bytes the input held.
std::string one_line(const char* message) { return rigcal::printable(message, 2000); }
}  // namespace main_command

int main(int argc, char** argv) {
  using namespace main_command;
  // OpenCV's warnings (a decoder's "can't read data" before rigcal's own error on the same file)
  // are not rigcal's one line: only its errors are kept.
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
  CLI::App app{
      "rigcal: calibrates a multi-sensor rig (stereo cameras, LiDAR, IMUs, GNSS/INS), publishes\n"
      "the calibration as YAML, and scores trajectories. Conventions: T_a_b maps points of frame\n"
      "b into frame a; the base frame is the LiDAR; SI units. See doc/ for every format.",
      "rigcal"};
  app.set_version_flag("--version", rigcal::version_string());
  app.require_subcommand(1);
  app.footer(
      "Exit status: 0 success, 2 bad input (the message names file, line and key), 1 bug;\n"
      "3 when the data do not determine the answer (time-offset, hand-eye, calibrate,\n"
      "ground-truth), or, for check, when the calibration no longer fits.");

  rigcal::cli::add_calibrate(app);
  rigcal::cli::add_publish(app);
  rigcal::cli::add_check(app);
  rigcal::cli::add_diff(app);
  rigcal::cli::add_report(app);
  rigcal::cli::add_convert(app);
  rigcal::cli::add_capture(app);
  CLI::App* rig = app.add_subcommand("rig", "Check, show and convert a calibration YAML");
  rig->require_subcommand(1);
  rigcal::cli::add_rig_validate(*rig);
  rigcal::cli::add_rig_show(*rig);
  rigcal::cli::add_rig_convert(*rig);
  rigcal::cli::add_bench(app);
  rigcal::cli::add_simulate(app);
  rigcal::cli::add_cameras(app);
  rigcal::cli::add_time_offset(app);
  rigcal::cli::add_hand_eye(app);
  rigcal::cli::add_lidar_camera(app);
  rigcal::cli::add_odometry(app);
  rigcal::cli::add_ground_truth(app);
  CLI::App* target = app.add_subcommand("target", "Calibration targets: printable PDFs");
  target->require_subcommand(1);
  rigcal::cli::add_target_print(*target);

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help, --version
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "rigcal: %s (see rigcal --help)\n", one_line(e.what()).c_str());
    return 2;
  } catch (const rigcal::cli::Exit& e) {
    return e.status;
  } catch (const rigcal::Error& e) {
    std::fprintf(stderr, "rigcal: error: %s\n", one_line(e.what()).c_str());
    return 2;
  } catch (const std::filesystem::filesystem_error& e) {
    // The file system refused (permissions, a link loop, a name too long, a full disk): the
    // input or the place to write is at fault, not rigcal.
    std::fprintf(stderr, "rigcal: error: %s: %s\n", one_line(e.path1().c_str()).c_str(),
                 one_line(e.code().message().c_str()).c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rigcal: internal error: %s\n", one_line(e.what()).c_str());
    return 1;
  }
  return 0;
}
