#pragma once
// Real public data for tests lives in ../shared/fixtures (see its MANIFEST.md). Tests that need it
// skip with a message where the folder is absent.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include "rigcal/core/error.h"

namespace rigcal::testing {

inline std::filesystem::path fixtures_dir() {
  return std::filesystem::path(RIGCAL_SOURCE_DIR) / ".." / "shared" / "fixtures";
}

// The fixture path, or "" when absent.
inline std::string fixture(const std::string& relative) {
  const std::filesystem::path p = fixtures_dir() / relative;
  return std::filesystem::exists(p) ? p.string() : std::string();
}

// The message of the rigcal::Error `f` throws ("" and a failure when it throws nothing).
template <typename F>
std::string error_message_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no rigcal::Error";
  return "";
}

// A test with its own scratch folder (removed after the test), files written into it, and the
// message of the rigcal::Error a call throws.
class ScratchTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        std::filesystem::temp_directory_path() /
        ("rigcal_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) +
         "_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path write(const std::filesystem::path& rel, const std::string& bytes) {
    std::filesystem::create_directories((dir_ / rel).parent_path());
    std::ofstream(dir_ / rel, std::ios::binary) << bytes;
    return dir_ / rel;
  }
  // The message of the rigcal::Error `f` throws ("" and a failure when it throws nothing).
  template <typename F>
  static std::string error_of(F&& f) {
    return error_message_of(std::forward<F>(f));
  }
  std::filesystem::path dir_;
};

}  // namespace rigcal::testing

#define RIGCAL_REQUIRE_FIXTURE(var, relative)                                                 \
  const std::string var = ::rigcal::testing::fixture(relative);                               \
  if (var.empty()) {                                                                          \
    GTEST_SKIP() << "fixture " << relative << " not found under ../shared/fixtures; skipped"; \
  }
