#include "rigcal/core/text.h"

#include <fmt/format.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>

#include "rigcal/core/error.h"

namespace rigcal {

namespace {
template <class Visit>
void for_each_field(std::string_view line, Visit visit) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  size_t i = 0;
  auto is_sep = [](char c) { return c == ' ' || c == '\t' || c == ','; };
  while (i < line.size()) {
    while (i < line.size() && is_sep(line[i])) ++i;
    const size_t start = i;
    while (i < line.size() && !is_sep(line[i])) ++i;
    if (i > start) visit(line.substr(start, i - start));
  }
}
}  // namespace

std::vector<std::string_view> split_fields(std::string_view line) {
  std::vector<std::string_view> out;
  for_each_field(line, [&](std::string_view f) { out.push_back(f); });
  return out;
}

size_t split_fields(std::string_view line, std::span<std::string_view> out) {
  size_t n = 0;
  for_each_field(line, [&](std::string_view f) {
    if (n < out.size()) out[n] = f;
    ++n;
  });
  return n;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

namespace {
// Length of the valid UTF-8 sequence starting at s[i] (2..4), or 0.
size_t utf8_sequence(std::string_view s, size_t i) {
  const auto c = static_cast<unsigned char>(s[i]);
  const size_t n = c >= 0xC2 && c <= 0xDF   ? 2
                   : c >= 0xE0 && c <= 0xEF ? 3
                   : c >= 0xF0 && c <= 0xF4 ? 4
                                            : 0;
  if (n == 0 || i + n > s.size()) return 0;
  for (size_t k = 1; k < n; ++k)
    if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return 0;
  const auto c1 = static_cast<unsigned char>(s[i + 1]);
  if ((c == 0xE0 && c1 < 0xA0) || (c == 0xED && c1 > 0x9F) || (c == 0xF0 && c1 < 0x90) ||
      (c == 0xF4 && c1 > 0x8F))
    return 0;  // overlong, surrogate or beyond U+10FFFF
  return n;
}
}  // namespace

size_t first_invalid_utf8(std::string_view text) {
  for (size_t i = 0; i < text.size();) {
    const size_t n = static_cast<unsigned char>(text[i]) < 0x80 ? 1 : utf8_sequence(text, i);
    if (n == 0) return i;
    i += n;
  }
  return std::string_view::npos;
}

std::string printable(std::string_view text, size_t max_chars) {
  std::string out;
  size_t chars = 0;
  for (size_t i = 0; i < text.size(); ++chars) {
    if (chars == max_chars) return out + "...";
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7F) {
      out += static_cast<char>(c);
      ++i;
    } else if (const size_t n = c >= 0x80 ? utf8_sequence(text, i) : 0; n > 0) {
      out.append(text.substr(i, n));
      i += n;
    } else {
      out += fmt::format("\\x{:02X}", c);
      ++i;
    }
  }
  return out;
}

namespace {

// Plain decimals ([-]digits[.digits][e[+-]digits]) whose significant digits fit 2^53 and whose
// power of ten is within 1e+-22: then both m and 10^e are exact doubles, and one multiplication
// or division rounds correctly, the same double as from_chars (Clinger's fast path). The rows of
// KITTI files (10 digits) take it; false for anything else, which from_chars reads.
bool parse_simple_decimal(std::string_view s, double& value) {
  static constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                      1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                      1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  size_t i = 0;
  const bool negative = i < s.size() && s[i] == '-';
  if (negative) ++i;
  uint64_t m = 0;
  int digits = 0, exponent = 0;  // significant digits taken; the power of ten of m's last digit
  bool any = false;
  auto take = [&](char c, bool after_point) {
    if (m == 0 && c == '0') {  // leading zeros are not significant
      if (after_point) --exponent;
      return true;
    }
    if (++digits > 18) return false;
    m = m * 10 + static_cast<uint64_t>(c - '0');
    if (after_point) --exponent;
    return true;
  };
  for (; i < s.size() && s[i] >= '0' && s[i] <= '9'; ++i, any = true)
    if (!take(s[i], false)) return false;
  if (i < s.size() && s[i] == '.') {
    for (++i; i < s.size() && s[i] >= '0' && s[i] <= '9'; ++i, any = true)
      if (!take(s[i], true)) return false;
  }
  if (!any) return false;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    const bool minus = i < s.size() && s[i] == '-';
    if (i < s.size() && (s[i] == '-' || s[i] == '+')) ++i;
    int e = 0, n = 0;
    for (; i < s.size() && s[i] >= '0' && s[i] <= '9' && n < 4; ++i, ++n) e = e * 10 + (s[i] - '0');
    if (n == 0 || n == 4) return false;
    exponent += minus ? -e : e;
  }
  if (i != s.size() || m > (uint64_t{1} << 53)) return false;
  double v = static_cast<double>(m);
  if (m != 0) {
    if (exponent < -22 || exponent > 22) return false;
    v = exponent < 0 ? v / kPow10[-exponent] : v * kPow10[exponent];
  }
  value = negative ? -v : v;
  return true;
}

}  // namespace

double parse_double(std::string_view text, std::string_view what) {
  std::string_view s = trim(text);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double value = 0.0;
  if (parse_simple_decimal(s, value)) return value;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (s.empty() || ec == std::errc::invalid_argument || end != s.data() + s.size()) {
    throw Error(fmt::format("{}: expected a number, got '{}'", what, printable(text)));
  }
  if (ec == std::errc::result_out_of_range || !std::isfinite(value)) {
    throw Error(fmt::format("{}: expected a finite number, got '{}'", what, printable(text)));
  }
  return value;
}

long long parse_int(std::string_view text, std::string_view what) {
  std::string_view s = trim(text);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  long long value = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size()) {
    throw Error(fmt::format("{}: expected an integer, got '{}'", what, printable(text)));
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
