#pragma once
// The benchmarks' shared main: `--smoke` as the first argument asks for small inputs (make test
// runs each benchmark once that way, so none rots); the rest goes to Google Benchmark.
#include <benchmark/benchmark.h>

#include <cstring>

namespace rigcal::perf {

// Removes a leading --smoke from the arguments and says whether it was there.
inline bool take_smoke_flag(int& argc, char**& argv) {
  if (argc < 2 || std::strcmp(argv[1], "--smoke") != 0) return false;
  argv[1] = argv[0];
  ++argv, --argc;
  return true;
}

inline int run_benchmarks(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}

}  // namespace rigcal::perf
