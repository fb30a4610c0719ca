#pragma once
// Internal to time_sync: the two streams as signals in seconds since a common epoch, their
// interpolation, bandwidth matching, resampling on lattices and pairing (signals.cpp).
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <string_view>
#include <vector>

#include "rigcal/core/time.h"
#include "rigcal/time_sync/time_sync.h"

namespace rigcal::time_sync {

// A stream in seconds since a common epoch. A step longer than gap_s is a gap: nothing is
// interpolated across it.
struct Series {
  std::vector<double> t;
  std::vector<Eigen::Vector3d> w;
  std::vector<Eigen::Vector3d> m;  // tangents dw/dt for the interpolation (set_tangents)
  double median_dt = 0.0, gap_s = 0.0, averaging_s = 0.0;
  double rate_hz() const { return 1.0 / median_dt; }
};

// The stream as a Series in seconds since `epoch` (median step, gap 5 steps, tangents set).
// Throws rigcal::Error on fewer than 10 samples, stamps not increasing or rates not finite;
// `what` names the stream in the message.
Series make_series(const AngularRates& in, Time epoch, std::string_view what);

// The samples of s with a <= t <= b (tangents kept: they are those of the whole stream).
Series slice(const Series& s, double a, double b);

// The signal at x by cubic Hermite interpolation with finite-difference tangents (linear next to
// a gap or an end); false outside the stream or inside a gap. `hint` makes monotone queries O(1).
bool sample(const Series& s, double x, size_t& hint, Eigen::Vector3d& out);

// The mean over [x - width/2, x + width/2] of the piecewise-linear signal, for every sample whose
// window lies inside one gap-free segment (others are dropped); the result's averaging_s is
// width. Throws rigcal::Error when fewer than 10 samples are left.
Series box_filter(const Series& s, double width);

// |w| on the lattice t = n * h for n in [n0, n0 + size), with a validity mask; the values have
// their mean removed.
struct Grid {
  long n0 = 0;
  std::vector<double> v, m;
};

// The Grid of |w| of s on the lattice of step h.
Grid norm_grid(const Series& s, double h);

// The standard deviation of |w| over the samples: the stream's excitation, rad/s.
double stddev_of_norm(const Series& s);

// Pairs of reference and other rates at offset d: the slower stream's samples (those in
// `points`), the faster one interpolated.
struct Pairing {
  const Series* slow;
  const Series* fast;
  bool slow_is_reference;
  std::vector<size_t> points;  // indices into slow

  // t_ref = t_other + d: the fast stream's time for a slow sample.
  double fast_time(double t_slow, double d) const {
    return slow_is_reference ? t_slow - d : t_slow + d;
  }
  // Calls f(w_ref, w_other, index in points) for every pair with index in [q0, q1) that can be
  // interpolated; returns how many.
  template <class F>
  size_t for_each(double d, F f, size_t q0 = 0, size_t q1 = SIZE_MAX) const {
    size_t hint = 0, n = 0;
    for (size_t q = q0; q < std::min(q1, points.size()); ++q) {
      const size_t i = points[q];
      Eigen::Vector3d w;
      if (!sample(*fast, fast_time(slow->t[i], d), hint, w)) continue;
      if (slow_is_reference) {
        f(slow->w[i], w, q);
      } else {
        f(w, slow->w[i], q);
      }
      ++n;
    }
    return n;
  }
  // Sums f(acc, w_ref, w_other) over the pairs into an Acc (with a count n and operator+), in
  // parallel over chunks of points for long streams, combined in a fixed order so that the
  // result does not depend on the scheduling.
  template <class Acc, class F>
  Acc reduce(double d, F f) const {
    auto run = [&](size_t q0, size_t q1, Acc acc) {
      acc.n += for_each(
          d, [&](const Eigen::Vector3d& wr, const Eigen::Vector3d& wo, size_t) { f(acc, wr, wo); },
          q0, q1);
      return acc;
    };
    constexpr size_t kChunk = 16384;
    if (points.size() < 2 * kChunk) return run(0, points.size(), Acc{});
    return tbb::parallel_deterministic_reduce(
        tbb::blocked_range<size_t>(0, points.size(), kChunk), Acc{},
        [&](const tbb::blocked_range<size_t>& r, Acc acc) { return run(r.begin(), r.end(), acc); },
        [](const Acc& a, const Acc& b) { return a + b; });
  }
};

// The pairing of two streams (no points yet): the one with the longer median step is the slow one.
Pairing make_pairing(const Series& reference, const Series& other);

}  // namespace rigcal::time_sync
