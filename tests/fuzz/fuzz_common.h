#pragma once
// What the fuzz targets share (doc/testing.md, "Fuzzing"): their registration in the one fuzzing
// binary, a scratch folder of this process for the readers that take a path, and the splitting of
// one input into several files.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "rigcal/core/error.h"

namespace rigcal::fuzz {

// One binary, rigcal_fuzz, holds every target (one build and one link, not one a target): each
// file registers its function under the target's name, and the binary runs the one named by the
// link it is called through (fuzz_<target>) or by RIGCAL_FUZZ_TARGET (fuzz_main.cpp).
using Target = int (*)(const uint8_t* data, size_t size);
bool register_target(const char* name, Target target);

// A folder of this process in /dev/shm (memory, not the disk; the system's temporary folder where
// there is none), removed at a normal exit. A crash leaves it behind: rigcal-fuzz-<pid>.
inline const std::filesystem::path& scratch() {
  static const std::filesystem::path dir = [] {
    namespace fs = std::filesystem;
    const fs::path base =
        fs::is_directory("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
    const fs::path d = base / ("rigcal-fuzz-" + std::to_string(::getpid()));
    std::error_code ec;
    fs::remove_all(d, ec);
    fs::create_directories(d);
    std::atexit([] {
      std::error_code e;
      std::filesystem::remove_all(scratch(), e);
    });
    return d;
  }();
  return dir;
}

inline void write_file(const std::filesystem::path& path, std::string_view bytes) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// The parts of `data` between the lines equal to `marker` ("--imu.txt--"): one input holding
// several files. Without the marker, one part.
inline std::vector<std::string_view> split_parts(std::string_view data, std::string_view marker) {
  const std::string sep = "\n" + std::string(marker) + "\n";
  std::vector<std::string_view> parts;
  size_t pos = 0;
  for (size_t at; (at = data.find(sep, pos)) != std::string_view::npos; pos = at + sep.size()) {
    parts.push_back(data.substr(pos, at - pos));
  }
  parts.push_back(data.substr(pos));
  return parts;
}

inline std::string_view as_text(const uint8_t* data, size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// Runs `f`; rigcal::Error is the expected outcome of bad input. Anything else escapes, and
// libFuzzer reports it (an uncaught exception aborts).
template <class F>
void expect_only_rigcal_errors(F&& f) {
  try {
    f();
  } catch (const rigcal::Error&) {
  }
}

// A broken promise of the code under test (a round trip that fails): abort, a finding.
[[noreturn]] inline void finding(const char* what, const std::string& detail) {
  std::fprintf(stderr, "FINDING: %s: %s\n", what, detail.c_str());
  std::abort();
}

}  // namespace rigcal::fuzz

// At a file's end: RIGCAL_FUZZ_TARGET(rig_yaml, fuzz_rig_yaml).
#define RIGCAL_FUZZ_TARGET(name, function)                           \
  [[maybe_unused]] static const bool rigcal_fuzz_registered_##name = \
      ::rigcal::fuzz::register_target(#name, &function);
