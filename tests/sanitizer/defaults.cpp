// Default options of the sanitizers in the sanitizer build (doc/testing.md), read by their runtimes
// at start-up; ASAN_OPTIONS, UBSAN_OPTIONS and LSAN_OPTIONS in the environment still override.
// Linked into the CLI, the unit tests and the fuzz targets of that build only.
extern "C" {
// Stack traces symbolized by Debian's llvm-14 (the unversioned llvm-symbolizer may be absent).
const char* __asan_default_options() {
  return "check_initialization_order=1:strict_init_order=1:detect_leaks=1:"
         "external_symbolizer_path=/usr/lib/llvm-14/bin/llvm-symbolizer";
}
const char* __ubsan_default_options() { return "print_stacktrace=1:halt_on_error=1"; }
// Leaks inside Debian's libraries, each with its reason, in tests/sanitizer/lsan.supp.
const char* __lsan_default_options() { return "suppressions=" RIGCAL_LSAN_SUPPRESSIONS; }
}
