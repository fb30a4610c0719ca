#include "rigcal/core/error.h"

#include <fmt/format.h>

namespace rigcal {

std::string where(std::string_view file, int line, std::string_view key) {
  std::string out(file.empty() ? "<input>" : file);
  if (line > 0) out += fmt::format(":{}", line);
  if (!key.empty()) out += fmt::format(": key '{}'", key);
  return out;
}

void fail_at(std::string_view file, int line, std::string_view key, std::string_view what) {
  throw Error(fmt::format("{}: {}", where(file, line, key), what));
}

}  // namespace rigcal
