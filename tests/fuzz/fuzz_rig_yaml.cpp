// The calibration YAML (rig::parse_rig_yaml). A rig that reads must also write, and what it writes
// must read back (calib/rig/rig_yaml.h promises the identical rig).
#include "fuzz_common.h"
#include "rigcal/rig/rig_yaml.h"

static int fuzz_rig_yaml(const uint8_t* data, size_t size) {
  using namespace rigcal;
  std::optional<rig::Rig> parsed;
  fuzz::expect_only_rigcal_errors(
      [&] { parsed = rig::parse_rig_yaml(fuzz::as_text(data, size), "rig.yaml"); });
  if (!parsed) return 0;
  std::string text;
  try {
    text = rig::rig_to_yaml(*parsed);
  } catch (const Error& e) {
    fuzz::finding("a rig that parsed does not write", e.what());
  }
  try {
    const rig::Rig again = rig::parse_rig_yaml(text, "written.yaml");
    if (rig::rig_to_yaml(again) != text)
      fuzz::finding("the written rig reads back different", text);
  } catch (const Error& e) {
    fuzz::finding("the written rig does not read back", std::string(e.what()) + "\n" + text);
  }
  return 0;
}
RIGCAL_FUZZ_TARGET(rig_yaml, fuzz_rig_yaml)
