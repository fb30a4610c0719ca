// The ground truth's survey of markers (io::parse_marker_survey): id,x,y,z or id_a,id_b,distance.
#include "fuzz_common.h"
#include "rigcal/io/ground_truth_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rigcal;
  fuzz::expect_only_rigcal_errors(
      [&] { io::parse_marker_survey(fuzz::as_text(data, size), "markers.csv"); });
  return 0;
}
