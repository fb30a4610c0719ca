#pragma once
// Real public data for tests lives in ../shared/fixtures (see its MANIFEST.md). Tests that need it
// skip with a message where the folder is absent.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace rigcal::testing {

inline std::filesystem::path fixtures_dir() {
  return std::filesystem::path(RIGCAL_SOURCE_DIR) / ".." / "shared" / "fixtures";
}

// The fixture path, or "" when absent.
inline std::string fixture(const std::string& relative) {
  const std::filesystem::path p = fixtures_dir() / relative;
  return std::filesystem::exists(p) ? p.string() : std::string();
}

}  // namespace rigcal::testing

#define RIGCAL_REQUIRE_FIXTURE(var, relative)                                                 \
  const std::string var = ::rigcal::testing::fixture(relative);                               \
  if (var.empty()) {                                                                          \
    GTEST_SKIP() << "fixture " << relative << " not found under ../shared/fixtures; skipped"; \
  }
