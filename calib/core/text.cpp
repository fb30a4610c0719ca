#include "rigcal/core/text.h"

#include <fmt/format.h>

#include <cctype>
#include <charconv>
#include <cmath>

#include "rigcal/core/error.h"

namespace rigcal {

std::vector<std::string_view> split_fields(std::string_view line) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  std::vector<std::string_view> out;
  size_t i = 0;
  auto is_sep = [](char c) { return c == ' ' || c == '\t' || c == ','; };
  while (i < line.size()) {
    while (i < line.size() && is_sep(line[i])) ++i;
    const size_t start = i;
    while (i < line.size() && !is_sep(line[i])) ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

double parse_double(std::string_view text, std::string_view what) {
  std::string_view s = trim(text);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (s.empty() || ec == std::errc::invalid_argument || end != s.data() + s.size()) {
    throw Error(fmt::format("{}: expected a number, got '{}'", what, text));
  }
  if (ec == std::errc::result_out_of_range || !std::isfinite(value)) {
    throw Error(fmt::format("{}: expected a finite number, got '{}'", what, text));
  }
  return value;
}

long long parse_int(std::string_view text, std::string_view what) {
  std::string_view s = trim(text);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  long long value = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size()) {
    throw Error(fmt::format("{}: expected an integer, got '{}'", what, text));
  }
  return value;
}

std::string format_double(double value, bool keep_point) {
  std::string s = fmt::format("{}", value);  // shortest round-trip representation
  if (!keep_point || !std::isfinite(value) || s.find('.') != std::string::npos) return s;
  // YAML 1.1 readers (PyYAML) take "1e-05" and "1" for a string and an int: write "1.0e-05", "1.0".
  const size_t e = s.find('e');
  if (e == std::string::npos) return s + ".0";
  return s.insert(e, ".0");
}

std::vector<TextLine> data_lines(std::string_view text, std::string* headers) {
  std::vector<TextLine> lines;
  int number = 0;
  size_t pos = 0;
  while (pos <= text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = trim(text.substr(pos, end - pos));
    ++number;
    if (!line.empty()) {
      if (line.front() == '#' ||
          (lines.empty() && std::isalpha(static_cast<unsigned char>(line.front())))) {
        if (headers) *headers += std::string(line) + "\n";
      } else {
        lines.push_back({line, number});
      }
    }
    if (end == text.size()) break;
    pos = end + 1;
  }
  return lines;
}

}  // namespace rigcal
