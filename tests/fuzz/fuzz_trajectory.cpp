// Trajectory files (io::parse_trajectory), one target per format (tum, kitti, euroc), each with
// every policy for equal stamps. KITTI: the part after a line "--times--" is
// the times file (a path option), written to the scratch folder.
#include "fuzz_common.h"
#include "rigcal/io/trajectory_io.h"

template <rigcal::io::TrajectoryFormat format>
int fuzz_trajectory(const uint8_t* data, size_t size) {
  using namespace rigcal;
  using Duplicates = io::TrajectoryReadOptions::Duplicates;
  io::TrajectoryReadOptions options;
  options.format = format;
  std::string_view text = fuzz::as_text(data, size);
  if (options.format == io::TrajectoryFormat::kitti) {
    const std::vector<std::string_view> parts = fuzz::split_parts(text, "--times--");
    if (parts.size() > 1) {
      text = parts[0];
      options.kitti_times = fuzz::scratch() / "times.txt";
      fuzz::write_file(options.kitti_times, parts[1]);
    }
  }
  for (const Duplicates d : {Duplicates::error, Duplicates::drop, Duplicates::keep}) {
    options.duplicates = d;
    fuzz::expect_only_rigcal_errors([&] { io::parse_trajectory(text, "trajectory.txt", options); });
  }
  return 0;
}
RIGCAL_FUZZ_TARGET(trajectory_tum, fuzz_trajectory<rigcal::io::TrajectoryFormat::tum>)
RIGCAL_FUZZ_TARGET(trajectory_kitti, fuzz_trajectory<rigcal::io::TrajectoryFormat::kitti>)
RIGCAL_FUZZ_TARGET(trajectory_euroc, fuzz_trajectory<rigcal::io::TrajectoryFormat::euroc>)
