#pragma once
// The rigcal command line run from a test: its exit status, stdout, stderr and wall time.
#include <fmt/format.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace rigcal::testing {

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct CliRun {
  int status = -1;
  std::string out, err;
  double seconds = 0;
};

// `rigcal ARGS`, its output kept in `scratch`; `env` ("TMPDIR=...") set for it alone.
inline CliRun rigcal_cli(const std::string& args, const std::filesystem::path& scratch,
                         const std::string& env = "") {
  const std::filesystem::path out = scratch / "stdout.txt", err = scratch / "stderr.txt";
  const auto t0 = std::chrono::steady_clock::now();
  const int raw = std::system(
      fmt::format("{} {} {} > {} 2> {}", env, RIGCAL_CLI, args, out.string(), err.string())
          .c_str());
  CliRun r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

}  // namespace rigcal::testing
