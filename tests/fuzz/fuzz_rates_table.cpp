// Angular-rate tables (io::read_rates on a file, format detected: a table, or a pose trajectory
// turned into rates). read_rates takes a path: the input is written to the scratch folder.
#include "fuzz_common.h"
#include "rigcal/io/rates_io.h"

static int fuzz_rates_table(const uint8_t* data, size_t size) {
  using namespace rigcal;
  static const std::filesystem::path file = fuzz::scratch() / "rates.txt";
  fuzz::write_file(file, fuzz::as_text(data, size));
  fuzz::expect_only_rigcal_errors([&] { io::read_rates(file); });
  return 0;
}
RIGCAL_FUZZ_TARGET(rates_table, fuzz_rates_table)
