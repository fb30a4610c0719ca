// The ground truth's survey of markers (io::parse_marker_survey): id,x,y,z or id_a,id_b,distance.
#include "fuzz_common.h"
#include "rigcal/io/ground_truth_io.h"

static int fuzz_marker_survey(const uint8_t* data, size_t size) {
  using namespace rigcal;
  fuzz::expect_only_rigcal_errors(
      [&] { io::parse_marker_survey(fuzz::as_text(data, size), "markers.csv"); });
  return 0;
}
RIGCAL_FUZZ_TARGET(marker_survey, fuzz_marker_survey)
