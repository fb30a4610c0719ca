// session.yaml (io::read_session, a folder). The folder holds empty recordings (stereo/,
// lidar_camera/, motion/ with their topic folders), a target and a rig file, so that the paths the
// input names can exist; then each purpose's recording is asked for.
#include "fuzz_common.h"
#include "rigcal/io/session.h"

static int fuzz_session(const uint8_t* data, size_t size) {
  using namespace rigcal;
  namespace fs = std::filesystem;
  static const fs::path root = [] {
    const fs::path r = fuzz::scratch() / "session";
    for (const char* d :
         {"stereo/camera_left", "stereo/camera_right", "lidar_camera/camera_left",
          "lidar_camera/ouster_points", "motion/imu", "motion/ouster_imu", "motion/gnss"}) {
      fs::create_directories(r / d);
    }
    fuzz::write_file(r / "target.yaml", "target_type: checkerboard\n");
    fuzz::write_file(r / "rig.yaml", "cam_l: {}\n");
    fuzz::write_file(r / "motion" / "gnss" / "poses.tum", "0 0 0 0 0 0 0 1\n");
    return r;
  }();
  fuzz::write_file(root / "session.yaml", fuzz::as_text(data, size));
  fuzz::expect_only_rigcal_errors([&] {
    const io::Session s = io::read_session(root);
    for (const char* purpose : {"cameras", "lidar_camera", "motion"}) {
      fuzz::expect_only_rigcal_errors([&] { io::recording_for(s, purpose); });
    }
  });
  return 0;
}
RIGCAL_FUZZ_TARGET(session, fuzz_session)
