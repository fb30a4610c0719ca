#pragma once
// Small robust statistics shared by the modules.
#include <algorithm>
#include <cmath>
#include <span>
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
// In place: reorders v.
inline double median_midpoint_in_place(std::span<double> v) {
  if (v.empty()) return NAN;
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  if (v.size() % 2 == 1) return v[mid];
  const double upper = v[mid];
  const double lower = *std::max_element(v.begin(), v.begin() + mid);
  return 0.5 * (lower + upper);
}
inline double median_midpoint(std::vector<double> v) { return median_midpoint_in_place(v); }

// The root mean square; 0 when empty.
inline double rms(const std::vector<double>& v) {
  double sum = 0;
  for (double x : v) sum += x * x;
  return v.empty() ? 0.0 : std::sqrt(sum / double(v.size()));
}

// P(X >= x) for X chi-square with `dof` degrees of freedom (dof >= 1): the probability of a
// squared Mahalanobis distance at least x when nothing but noise made it. Closed forms by the
// parity of dof (Abramowitz and Stegun 26.4.4 and 26.4.5).
inline double chi2_upper_tail(double x, int dof) {
  if (!(x > 0)) return 1.0;
  const double h = 0.5 * x;
  double sum = 0, term = 0;
  if (dof % 2 == 0) {
    term = 1.0;
    for (int k = 0; k < dof / 2; ++k) {
      if (k > 0) term *= h / k;
      sum += term;
    }
    return std::min(1.0, std::exp(-h) * sum);
  }
  term = std::sqrt(x) * std::sqrt(2.0 / M_PI);
  for (int k = 1; k <= (dof - 1) / 2; ++k) {
    if (k > 1) term *= x / (2 * k - 1);
    sum += term;
  }
  return std::min(1.0, std::erfc(std::sqrt(h)) + std::exp(-h) * sum);
}

}  // namespace rigcal
