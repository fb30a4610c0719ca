// The camera step's detections cache, corners.vnl (camera::parse_corners_vnl), for the 9 x 6
// checkerboard of targets/checkerboard_9x6_25mm.yaml (the file's first line names the target).
#include "fuzz_common.h"
#include "rigcal/camera/report.h"
#include "rigcal/io/target_yaml.h"

static int fuzz_corners_vnl(const uint8_t* data, size_t size) {
  using namespace rigcal;
  static const camera::Target target = io::parse_target_yaml(
      "target_type: checkerboard\ntargetCols: 9\ntargetRows: 6\nrowSpacingMeters: 0.025\n"
      "colSpacingMeters: 0.025\nname: checkerboard_9x6_25mm\n",
      "checkerboard_9x6_25mm.yaml");
  fuzz::expect_only_rigcal_errors(
      [&] { camera::parse_corners_vnl(fuzz::as_text(data, size), target); });
  return 0;
}
RIGCAL_FUZZ_TARGET(corners_vnl, fuzz_corners_vnl)
