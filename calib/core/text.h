#pragma once
// Small text helpers shared by every reader and writer: strict number parsing and the
// shortest number text that reads back to the same double.
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace rigcal {

// Splits on runs of spaces, tabs and commas; drops empty fields and a trailing '\r'.
std::vector<std::string_view> split_fields(std::string_view line);
// The same into `out`, without allocating: returns the number of fields, of which the first
// out.size() are stored (millions of lines of a trajectory).
size_t split_fields(std::string_view line, std::span<std::string_view> out);

// Whole-string, finite double (no NaN or infinity). Throws rigcal::Error naming `what`.
double parse_double(std::string_view text, std::string_view what);
// Whole-string integer. Throws rigcal::Error naming `what`.
long long parse_int(std::string_view text, std::string_view what);

// Shortest decimal text that parses back to exactly `value` (lossless like %.17g, but 0.1 stays
// "0.1"). With `keep_point` the mantissa always has a '.', as YAML 1.1 floats need ("1.0",
// "1.0e-05").
std::string format_double(double value, bool keep_point = false);

std::string_view trim(std::string_view s);

// `text` made safe to quote in a one-line message: bytes that are not printable ASCII or part of
// valid UTF-8 (control characters, a line break, stray bytes) written as \xNN, and anything past
// `max_chars` cut with "...". A message never ends in a raw invalid byte or spans lines.
std::string printable(std::string_view text, size_t max_chars = 80);

// The offset of the first byte that is not part of well-formed UTF-8 (overlong forms, surrogates
// and cut sequences are not), npos when all of `text` is UTF-8.
size_t first_invalid_utf8(std::string_view text);

struct TextLine {
  std::string_view text;  // trimmed
  int number;             // 1-based
};
// The non-empty lines of a text file that are not comments ('#') or a header (a first line that
// starts with a letter); `headers`, when given, receives the comment and header lines.
std::vector<TextLine> data_lines(std::string_view text, std::string* headers);

}  // namespace rigcal
