// GNSS/INS fixes CSV (io::parse_gnss_fixes), under both attitude conventions and for positions
// only (at the first fix and at a given origin); the origin's own text (--enu-origin).
#include "fuzz_common.h"
#include "rigcal/io/gnss_fixes.h"

static int fuzz_gnss_fixes(const uint8_t* data, size_t size) {
  using namespace rigcal;
  for (const std::optional<io::Attitude> a :
       {std::optional(io::Attitude::enu), std::optional(io::Attitude::ned),
        std::optional<io::Attitude>()}) {
    fuzz::expect_only_rigcal_errors(
        [&] { io::parse_gnss_fixes(fuzz::as_text(data, size), "fixes.csv", a); });
  }
  // At a given origin (--enu-origin), and the text as such an origin.
  fuzz::expect_only_rigcal_errors([&] {
    io::parse_gnss_fixes(fuzz::as_text(data, size), "fixes.csv", std::nullopt,
                         io::GeodeticOrigin{41.89021, 12.492231, 69.0});
  });
  fuzz::expect_only_rigcal_errors(
      [&] { io::parse_geodetic_origin(fuzz::as_text(data, size), "--enu-origin"); });
  return 0;
}
RIGCAL_FUZZ_TARGET(gnss_fixes, fuzz_gnss_fixes)
