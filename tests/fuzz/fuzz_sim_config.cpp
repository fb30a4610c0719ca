// The simulator's configuration (io::apply_sim_config) over the defaults. Relative paths in it
// resolve against the scratch folder, where nothing else lives.
#include "fuzz_common.h"
#include "rigcal/io/sim_config.h"

static int fuzz_sim_config(const uint8_t* data, size_t size) {
  using namespace rigcal;
  static const std::string file = (fuzz::scratch() / "sim.yaml").string();
  sim::SimConfig config;
  fuzz::expect_only_rigcal_errors(
      [&] { io::apply_sim_config(fuzz::as_text(data, size), file, config); });
  return 0;
}
RIGCAL_FUZZ_TARGET(sim_config, fuzz_sim_config)
