#pragma once
// rigcal's one error type. Bad input raises rigcal::Error with a message that names where the
// problem is (file, line, key) and what was expected; the command line prints it as one line and
// exits 2.
#include <stdexcept>
#include <string>
#include <string_view>

namespace rigcal {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "FILE:LINE: key 'KEY': WHAT". `line` is 1-based; 0 leaves it out, an empty key leaves it out.
std::string where(std::string_view file, int line, std::string_view key);
[[noreturn]] void fail_at(std::string_view file, int line, std::string_view key,
                          std::string_view what);

}  // namespace rigcal
