// Target YAML (io::parse_target_yaml); target_to_yaml must read back to the same text.
#include "fuzz_common.h"
#include "rigcal/io/target_yaml.h"

static int fuzz_target_yaml(const uint8_t* data, size_t size) {
  using namespace rigcal;
  std::optional<camera::Target> parsed;
  fuzz::expect_only_rigcal_errors(
      [&] { parsed = io::parse_target_yaml(fuzz::as_text(data, size), "target.yaml"); });
  if (!parsed) return 0;
  const std::string text = io::target_to_yaml(*parsed);
  try {
    if (io::target_to_yaml(io::parse_target_yaml(text, "written.yaml")) != text)
      fuzz::finding("the written target reads back different", text);
  } catch (const Error& e) {
    fuzz::finding("the written target does not read back", std::string(e.what()) + "\n" + text);
  }
  return 0;
}
RIGCAL_FUZZ_TARGET(target_yaml, fuzz_target_yaml)
