// libFuzzer's entry points for rigcal_fuzz, the binary of every fuzz target: the target is the
// one named by the link the binary is called through (build-fuzz/bin/fuzz_rig_yaml runs
// rig_yaml) or by the environment's RIGCAL_FUZZ_TARGET.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>

#include "fuzz_common.h"

namespace rigcal::fuzz {
namespace {

std::map<std::string, Target>& targets() {
  static std::map<std::string, Target> all;
  return all;
}

Target chosen = nullptr;

}  // namespace

bool register_target(const char* name, Target target) {
  targets()[name] = target;
  return true;
}

}  // namespace rigcal::fuzz

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  using namespace rigcal::fuzz;
  std::string name;
  if (const char* env = std::getenv("RIGCAL_FUZZ_TARGET")) {
    name = env;
  } else if (*argc > 0) {
    name = std::filesystem::path((*argv)[0]).filename().string();
    if (name.rfind("fuzz_", 0) == 0) name = name.substr(5);
  }
  const auto found = targets().find(name);
  if (found == targets().end()) {
    std::fprintf(stderr,
                 "rigcal_fuzz: no fuzz target '%s'; call it through a link fuzz_<target> or set "
                 "RIGCAL_FUZZ_TARGET to one of:",
                 name.c_str());
    for (const auto& [n, t] : targets()) std::fprintf(stderr, " %s", n.c_str());
    std::fprintf(stderr, "\n");
    std::exit(2);
  }
  chosen = found->second;
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return rigcal::fuzz::chosen(data, size);
}
