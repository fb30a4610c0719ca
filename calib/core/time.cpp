#include "rigcal/core/time.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "rigcal/core/error.h"
#include "rigcal/core/text.h"

namespace rigcal {
namespace {

using i128 = __int128;
constexpr i128 kMaxNs = kMaxReadNs;
constexpr std::string_view kRange = "a time within +-146 years of 1970 (below 2^62 ns)";

[[noreturn]] void bad(std::string_view what, std::string_view text, std::string_view expected) {
  throw Error(fmt::format("{}: expected {}, got '{}'", what, expected, printable(text)));
}

bool is_digit(char c) { return c >= '0' && c <= '9'; }

// Digits of a decimal number and the power of ten that scales them: value = digits * 10^exp10.
struct Decimal {
  bool negative = false;
  std::string digits;
  long exp10 = 0;
};

Decimal parse_decimal(std::string_view s, std::string_view what, std::string_view text) {
  constexpr std::string_view kExpected = "a decimal number of seconds";
  Decimal d;
  size_t i = 0;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) d.negative = s[i++] == '-';
  size_t n_int = 0, n_frac = 0;
  while (i < s.size() && is_digit(s[i])) d.digits += s[i++], ++n_int;
  if (i < s.size() && s[i] == '.') {
    ++i;
    while (i < s.size() && is_digit(s[i])) d.digits += s[i++], ++n_frac;
  }
  if (n_int + n_frac == 0) bad(what, text, kExpected);
  d.exp10 = -static_cast<long>(n_frac);
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    const std::string_view e = s.substr(i);
    if (e.empty() || e.size() > 6) bad(what, text, kExpected);
    d.exp10 += static_cast<long>(parse_int(e, what));
    i = s.size();
  }
  if (i != s.size()) bad(what, text, kExpected);
  return d;
}

// Rounds digits * 10^exp10 to an integer (half away from zero); throws beyond +-kMaxNs.
int64_t round_decimal(const Decimal& d, std::string_view what, std::string_view text) {
  size_t first = d.digits.find_first_not_of('0');
  if (first == std::string::npos) return 0;
  const std::string_view digits = std::string_view(d.digits).substr(first);
  i128 value = 0;
  auto out_of_range = [&] { bad(what, text, kRange); };
  const long keep = static_cast<long>(digits.size()) + d.exp10;  // digits left of the point
  if (keep > 19 + 1) out_of_range();
  for (long k = 0; k < keep; ++k) {
    const char c = k < static_cast<long>(digits.size()) ? digits[k] : '0';
    value = value * 10 + (c - '0');
    if (value > kMaxNs + 1) out_of_range();
  }
  // The first dropped digit decides (half away from zero); with keep < 0 it is a leading zero.
  if (keep >= 0 && keep < static_cast<long>(digits.size()) && digits[keep] >= '5') value += 1;
  if (value > kMaxNs) out_of_range();
  return static_cast<int64_t>(d.negative ? -value : value);
}

}  // namespace

Time Time::from_seconds(double seconds) {
  const double ns = std::round(seconds * 1e9);
  if (!std::isfinite(ns) || std::abs(ns) >= std::ldexp(1.0, 62)) {
    throw Error(fmt::format("time {} s is out of the range read (+-146 years)", seconds));
  }
  return Time{static_cast<int64_t>(ns)};
}

Time parse_seconds(std::string_view text, std::string_view what) {
  Decimal d = parse_decimal(trim(text), what, text);
  d.exp10 += 9;
  return Time{round_decimal(d, what, text)};
}

Time parse_nanoseconds(std::string_view text, std::string_view what) {
  const std::string_view s = trim(text);
  for (size_t i = 0; i < s.size(); ++i) {
    if (!is_digit(s[i]) && !(i == 0 && (s[i] == '-' || s[i] == '+'))) {
      bad(what, text, "an integer count of nanoseconds");
    }
  }
  const Time t{parse_int(s, what)};
  if (t.ns > kMaxNs || t.ns < -kMaxNs) bad(what, text, kRange);
  return t;
}

Time parse_iso8601(std::string_view text, std::string_view what) {
  constexpr std::string_view kExpected = "an ISO-8601 time like 1970-01-01T00:06:06.660458140";
  const std::string_view s = trim(text);
  auto num = [&](size_t pos, size_t len) {
    if (pos + len > s.size()) bad(what, text, kExpected);
    int v = 0;
    for (size_t k = pos; k < pos + len; ++k) {
      if (!is_digit(s[k])) bad(what, text, kExpected);
      v = v * 10 + (s[k] - '0');
    }
    return v;
  };
  // YYYY-MM-DDTHH:MM:SS
  if (s.size() < 19 || s[4] != '-' || s[7] != '-' || (s[10] != 'T' && s[10] != ' ') ||
      s[13] != ':' || s[16] != ':') {
    bad(what, text, kExpected);
  }
  const int year = num(0, 4), month = num(5, 2), day = num(8, 2);
  const int hour = num(11, 2), minute = num(14, 2), second = num(17, 2);
  const std::chrono::year_month_day ymd{std::chrono::year(year), std::chrono::month(month),
                                        std::chrono::day(day)};
  if (!ymd.ok() || hour > 23 || minute > 59 || second > 60) bad(what, text, kExpected);
  size_t i = 19;
  Decimal frac;
  frac.digits = "0";
  if (i < s.size() && s[i] == '.') {
    ++i;
    const size_t start = i;
    while (i < s.size() && is_digit(s[i])) ++i;
    if (i == start) bad(what, text, kExpected);
    frac.digits = std::string(s.substr(start, i - start));
    frac.exp10 = 9 - static_cast<long>(i - start);
  }
  int64_t offset_s = 0;
  if (i < s.size()) {
    if (s[i] == 'Z' && i + 1 == s.size()) {
      ++i;
    } else if ((s[i] == '+' || s[i] == '-') && s.size() == i + 6 && s[i + 3] == ':') {
      const int sign = s[i] == '-' ? -1 : 1;
      offset_s = sign * (num(i + 1, 2) * 3600 + num(i + 4, 2) * 60);
      i = s.size();
    } else {
      bad(what, text, kExpected);
    }
  }
  const int64_t days = std::chrono::sys_days(ymd).time_since_epoch().count();
  const i128 total_s =
      static_cast<i128>(days) * 86400 + hour * 3600 + minute * 60 + second - offset_s;
  const i128 ns = total_s * 1000000000 + round_decimal(frac, what, text);
  if (ns > kMaxNs || ns < -kMaxNs) bad(what, text, kRange);
  return Time{static_cast<int64_t>(ns)};
}

Time parse_time(std::string_view text, std::string_view what) {
  const std::string_view s = trim(text);
  if (s.size() >= 10 && s[4] == '-' && s[7] == '-') return parse_iso8601(s, what);
  return parse_seconds(s, what);
}

std::string to_seconds_text(Time t) {
  const bool negative = t.ns < 0;
  const uint64_t abs_ns =
      negative ? static_cast<uint64_t>(-(t.ns + 1)) + 1 : static_cast<uint64_t>(t.ns);
  return fmt::format("{}{}.{:09d}", negative ? "-" : "", abs_ns / 1000000000ULL,
                     abs_ns % 1000000000ULL);
}

std::string to_iso8601(Time t) {
  int64_t s = t.ns / 1000000000;
  int64_t ns = t.ns % 1000000000;
  if (ns < 0) ns += 1000000000, s -= 1;
  int64_t days = s / 86400;
  int64_t sec_of_day = s % 86400;
  if (sec_of_day < 0) sec_of_day += 86400, days -= 1;
  const std::chrono::year_month_day ymd{std::chrono::sys_days(std::chrono::days(days))};
  return fmt::format("{:04d}-{:02d}-{:02d}T{:02d}:{:02d}:{:02d}.{:09d}", int(ymd.year()),
                     unsigned(ymd.month()), unsigned(ymd.day()), sec_of_day / 3600,
                     (sec_of_day / 60) % 60, sec_of_day % 60, ns);
}

}  // namespace rigcal
