// GNSS/INS fixes CSV (io::parse_gnss_fixes), under both attitude conventions and for positions
// only.
#include "fuzz_common.h"
#include "rigcal/io/gnss_fixes.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rigcal;
  for (const std::optional<io::Attitude> a :
       {std::optional(io::Attitude::enu), std::optional(io::Attitude::ned),
        std::optional<io::Attitude>()}) {
    fuzz::expect_only_rigcal_errors(
        [&] { io::parse_gnss_fixes(fuzz::as_text(data, size), "fixes.csv", a); });
  }
  return 0;
}
