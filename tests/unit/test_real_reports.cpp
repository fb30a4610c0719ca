// The pages of the step commands on real public data (../shared/fixtures): each says what is
// wrong with its data, if anything, and loads in a real browser. The estimates themselves are
// tested where each step is (test_camera.cpp, test_lidar_camera.cpp, test_cli.cpp).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "browser.h"
#include "cli_run.h"
#include "fixtures.h"
#include "rigcal/rig/rig_yaml.h"
#include "test_rigs.h"

namespace rigcal {
namespace {

namespace fs = std::filesystem;
using testing::slurp;

class RealReport : public testing::ScratchTest {
 protected:
  testing::CliRun run(const std::string& args) { return testing::rigcal_cli(args, dir_); }
  // The page of a report folder: written by the command, one step's section, rendered again
  // byte for byte by `rigcal report`, and loaded in Chromium with no console message.
  std::string page_of(const fs::path& report, const std::string& step) {
    const std::string page = slurp(report / "report.html");
    EXPECT_NE(page.find(fmt::format("id=\"step-{}\"", step)), std::string::npos);
    fs::remove(report / "report.html");
    const testing::CliRun again = run("report " + report.string());
    EXPECT_EQ(again.status, 0) << again.err;
    EXPECT_EQ(slurp(report / "report.html"), page);
    if (testing::have_chromium()) {
      const testing::BrowserLoad load =
          testing::load_in_browser(report / "report.html", dir_ / (step + ".png"));
      EXPECT_TRUE(load.ran) << load.log;
      EXPECT_EQ(testing::console_messages(load.log), "");
      EXPECT_NE(load.dom.find(fmt::format("id=\"step-{}\"", step)), std::string::npos);
      EXPECT_GT(load.screenshot_bytes, 20000u);
    }
    return page;
  }
};

// OpenCV's stereo samples (13 pairs of a 9 x 6 board, 640 x 480): the page says the fit is good
// (0.19 px), the rectified rows agree to the corner noise, and what is thin: the board never
// reached the images' corners.
TEST_F(RealReport, OpenCvStereoSamples) {
  RIGCAL_REQUIRE_FIXTURE(dir, "stereo/opencv_samples");
  const fs::path rep = dir_ / "rep";
  const testing::CliRun r =
      run(fmt::format("cameras --target {}/targets/checkerboard_9x6_25mm.yaml --camera "
                      "'cam_l={}/left*.jpg' --camera 'cam_r={}/right*.jpg' --out {} --report {}",
                      RIGCAL_SOURCE_DIR, dir, dir, (dir_ / "calib.yaml").string(), rep.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  std::printf("%s", r.out.c_str());
  const std::string page = page_of(rep, "cameras");
  EXPECT_NE(page.find("<b>Rectified</b>"), std::string::npos);
  EXPECT_EQ(page.find("more than twice that"), std::string::npos) << "the extrinsic fits";
  EXPECT_NE(page.find("stereo_rectified.png"), std::string::npos);
}

// ACFR's 11 real LiDAR-camera pairs (a fisheye and an OS1-128, the authors' published lens):
// the extrinsic is found, and the page's first words on it are the warning that most pairs do
// not fit it within their covariances.
TEST_F(RealReport, AcfrLidarCameraPairs) {
  RIGCAL_REQUIRE_FIXTURE(dir, "lidar_camera/acfr/2022-11-09_00-54-42");
  rig::Rig rig = rig::testing::sample_rig();
  rig::CameraModel& cam = rig::sensor(rig, "cam_r").camera;  // the fixture's cfg/camera_info.yaml
  cam.fx = 959.554, cam.fy = 960.194, cam.cx = 940.789, cam.cy = 670.737;
  cam.distortion_model = rig::DistortionModel::equidistant;
  cam.distortion_coeffs = {-0.097824, 0.141429, -0.148385, 0.055918};
  cam.width = 1920, cam.height = 1208;
  // Not placed (the sample rig's extrinsic is another rig's): the boards are searched for in the
  // whole scan.
  rig::sensor(rig, "cam_r").T_base_sensor = SE3();
  const fs::path rig_file = write("rig.yaml", rig::rig_to_yaml(rig));
  const fs::path target = write("acfr.yaml",
                                "target_type: checkerboard\ntargetCols: 7\ntargetRows: 5\n"
                                "rowSpacingMeters: 0.095\ncolSpacingMeters: 0.095\nname: acfr\n");
  const fs::path rep = dir_ / "rep";
  const testing::CliRun r =
      run(fmt::format("lidar-camera --target {} --rig {} --images '{}/images/pose*.png' --scans "
                      "'{}/pcd/pose*_full.pcd' --board-size 0.61,0.85 --report {}",
                      target.string(), rig_file.string(), dir, dir, rep.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  std::printf("%s", r.out.c_str());
  const std::string page = page_of(rep, "lidar_camera");
  EXPECT_NE(page.find("with 1 warning to read below"), std::string::npos);
  EXPECT_NE(page.find("outliers"), std::string::npos);
}

}  // namespace
}  // namespace rigcal
