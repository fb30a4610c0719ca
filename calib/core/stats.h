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

}  // namespace rigcal
