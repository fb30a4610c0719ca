// vbr-devkit's IMU folder (io::read_rates on the folder): the input is timestamps.txt, a line
// "--imu.txt--", then data/imu.txt (no marker: data/imu.txt alone, no timestamps.txt).
#include "fuzz_common.h"
#include "rigcal/io/rates_io.h"

static int fuzz_rates_vbr(const uint8_t* data, size_t size) {
  using namespace rigcal;
  namespace fs = std::filesystem;
  static const fs::path dir = fuzz::scratch() / "imu";
  const std::vector<std::string_view> parts =
      fuzz::split_parts(fuzz::as_text(data, size), "--imu.txt--");
  std::error_code ec;
  fs::remove_all(dir, ec);
  if (parts.size() > 1) fuzz::write_file(dir / "timestamps.txt", parts[0]);
  fuzz::write_file(dir / "data" / "imu.txt", parts.back());
  fuzz::expect_only_rigcal_errors([&] { io::read_rates(dir); });
  return 0;
}
RIGCAL_FUZZ_TARGET(rates_vbr, fuzz_rates_vbr)
