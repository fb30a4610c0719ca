// GNSS/INS fixes CSV (io::parse_gnss_fixes), under both attitude conventions.
#include "fuzz_common.h"
#include "rigcal/io/gnss_fixes.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rigcal;
  for (const io::Attitude a : {io::Attitude::enu, io::Attitude::ned}) {
    fuzz::expect_only_rigcal_errors(
        [&] { io::parse_gnss_fixes(fuzz::as_text(data, size), "fixes.csv", a); });
  }
  return 0;
}
