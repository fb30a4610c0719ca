#pragma once
// The one time type of rigcal: a signed count of nanoseconds (int64, +-292 years).
// Used both for instants (stamps on some clock) and for spans between them. Text is parsed
// exactly, digit by digit, never through a double: "1403715529.112143517" keeps every digit.
// Every time read (text or seconds) lies within +-kMaxReadNs, half the type's range, so the sum
// or the difference of any two read times is representable.
#include <compare>
#include <cstdint>
#include <string>
#include <string_view>

namespace rigcal {

// 2^62 - 1 ns: +-146 years of 1970 (1824 to 2116), as stamps and as spans.
inline constexpr int64_t kMaxReadNs = (int64_t{1} << 62) - 1;

struct Time {
  int64_t ns = 0;

  static constexpr Time from_ns(int64_t ns) { return Time{ns}; }
  // Rounds to the nearest nanosecond. Throws rigcal::Error beyond +-kMaxReadNs.
  static Time from_seconds(double seconds);
  double seconds() const { return static_cast<double>(ns) * 1e-9; }

  constexpr auto operator<=>(const Time&) const = default;
  constexpr Time operator+(Time o) const { return Time{ns + o.ns}; }
  constexpr Time operator-(Time o) const { return Time{ns - o.ns}; }
  constexpr Time operator-() const { return Time{-ns}; }
};

// The parsers below throw rigcal::Error beyond +-kMaxReadNs.
// Decimal seconds, exact: "366.660458140", "-0.5", "1.403715529112143517e+09". Digits beyond the
// nanosecond are rounded half away from zero. Throws rigcal::Error naming `what`.
Time parse_seconds(std::string_view text, std::string_view what = "time");
// Integer nanoseconds: "1403715529112143517".
Time parse_nanoseconds(std::string_view text, std::string_view what = "time");
// ISO-8601 UTC: "1970-01-01T00:06:06.660458140", optional 'Z' or "+HH:MM"/"-HH:MM" offset,
// 'T' or a space between date and time, up to 9 fraction digits (more are rounded).
Time parse_iso8601(std::string_view text, std::string_view what = "time");
// Any of the three above: ISO-8601 when the text holds a date, else decimal seconds.
Time parse_time(std::string_view text, std::string_view what = "time");

// "366.660458140": seconds with exactly 9 decimals (lossless).
std::string to_seconds_text(Time t);
// "1970-01-01T00:06:06.660458140" (UTC, 9 fraction digits, no zone suffix).
std::string to_iso8601(Time t);

}  // namespace rigcal
