#pragma once
// Small robust statistics shared by the modules.
#include <algorithm>
#include <cmath>
#include <vector>

namespace rigcal {

// The median (the upper one of an even count); NaN when empty.
inline double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// The median with the two middle values of an even count averaged (the textbook's, numpy's);
// NaN when empty.
inline double median_midpoint(std::vector<double> v) {
  if (v.empty()) return NAN;
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  if (v.size() % 2 == 1) return v[mid];
  const double upper = v[mid];
  const double lower = *std::max_element(v.begin(), v.begin() + mid);
  return 0.5 * (lower + upper);
}

// The root mean square; 0 when empty.
inline double rms(const std::vector<double>& v) {
  double sum = 0;
  for (double x : v) sum += x * x;
  return v.empty() ? 0.0 : std::sqrt(sum / double(v.size()));
}

}  // namespace rigcal
