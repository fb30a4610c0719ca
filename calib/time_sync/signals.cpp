#include "rigcal/time_sync/signals.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "rigcal/core/error.h"
#include "rigcal/core/se3.h"
#include "rigcal/core/stats.h"

namespace rigcal::time_sync {
namespace {

// Finite-difference tangents: central where both neighbours are within gap_s, one-sided next to a
// gap or an end (so a segment beside a gap is interpolated with its secant there).
void set_tangents(Series& s) {
  const size_t n = s.t.size();
  s.m.assign(n, Eigen::Vector3d::Zero());
  for (size_t k = 0; k < n; ++k) {
    const bool prev = k > 0 && s.t[k] - s.t[k - 1] <= s.gap_s;
    const bool next = k + 1 < n && s.t[k + 1] - s.t[k] <= s.gap_s;
    const size_t a = prev ? k - 1 : k, b = next ? k + 1 : k;
    if (a != b) s.m[k] = (s.w[b] - s.w[a]) / (s.t[b] - s.t[a]);
  }
}

// The segment j with t[j] <= x < t[j+1] (x == t.back() belongs to the last one), or false when
// x is outside or the step is a gap. `hint` makes monotone queries O(1).
bool locate(const Series& s, double x, size_t& hint, size_t& j) {
  const size_t n = s.t.size();
  if (!(x >= s.t.front() && x <= s.t.back())) return false;
  if (hint >= n - 1) hint = n - 2;
  if (s.t[hint] <= x && x <= s.t[hint + 1]) {
    j = hint;
  } else if (hint + 2 < n && s.t[hint + 1] <= x && x <= s.t[hint + 2]) {
    j = hint + 1;
  } else {
    j = static_cast<size_t>(std::upper_bound(s.t.begin(), s.t.end(), x) - s.t.begin());
    j = std::min(j, n - 1) - 1;
  }
  hint = j;
  return s.t[j + 1] - s.t[j] <= s.gap_s;
}

}  // namespace

AngularRates angular_rates_from_trajectory(const Trajectory& traj) {
  AngularRates out;
  std::vector<double> dts;
  for (size_t k = 0; k + 1 < traj.T_world_body.size(); ++k) {
    const Time dt = traj.stamps[k + 1] - traj.stamps[k];
    if (dt.ns <= 0) continue;
    const Eigen::Matrix3d dR = traj.T_world_body[k].R.transpose() * traj.T_world_body[k + 1].R;
    out.stamps.push_back(traj.stamps[k] + Time::from_ns(dt.ns / 2));
    out.rates.push_back(rotation_vector(dR) / dt.seconds());
    dts.push_back(dt.seconds());
  }
  out.averaging_s = dts.empty() ? 0.0 : median(dts);
  return out;
}

size_t repair_spikes(AngularRates& r) {
  const size_t n = r.rates.size();
  if (n < 10) return 0;
  std::vector<double> jump(n, 0.0);  // distance from the neighbours' mean
  for (size_t k = 1; k + 1 < n; ++k)
    jump[k] = (r.rates[k] - 0.5 * (r.rates[k - 1] + r.rates[k + 1])).norm();
  const double typical = median(std::vector<double>(jump.begin() + 1, jump.end() - 1));
  const double limit = kSpikeFactor * std::max(typical, 1e-6);
  std::vector<size_t> spikes;
  for (size_t k = 1; k + 1 < n; ++k) {
    if (jump[k] > limit && (r.rates[k + 1] - r.rates[k - 1]).norm() < 0.25 * jump[k])
      spikes.push_back(k);
  }
  for (size_t k : spikes) r.rates[k] = 0.5 * (r.rates[k - 1] + r.rates[k + 1]);
  return spikes.size();
}

size_t merge_equal_stamps(AngularRates& r) {
  size_t merged = 0, out = 0;
  for (size_t k = 0; k < r.stamps.size();) {
    if (k > 0 && r.stamps[k] < r.stamps[k - 1]) {
      throw Error(fmt::format("stamps go backwards at sample {} ({} after {})", k,
                              to_seconds_text(r.stamps[k]), to_seconds_text(r.stamps[k - 1])));
    }
    size_t e = k + 1;
    Eigen::Vector3d sum = r.rates[k];
    while (e < r.stamps.size() && r.stamps[e] == r.stamps[k]) sum += r.rates[e++];
    r.stamps[out] = r.stamps[k];
    r.rates[out] = sum / static_cast<double>(e - k);
    merged += e - k - 1;
    ++out;
    k = e;
  }
  r.stamps.resize(out);
  r.rates.resize(out);
  return merged;
}

Series make_series(const AngularRates& in, Time epoch, std::string_view what) {
  if (in.stamps.size() != in.rates.size())
    throw Error(fmt::format("{}: {} stamps but {} rates", what, in.stamps.size(), in.rates.size()));
  if (in.stamps.size() < 10)
    throw Error(fmt::format("{}: {} samples; at least 10 are needed", what, in.stamps.size()));
  Series s;
  s.t.reserve(in.stamps.size());
  std::vector<double> dt;
  dt.reserve(in.stamps.size());
  for (size_t k = 0; k < in.stamps.size(); ++k) {
    if (k > 0 && in.stamps[k] <= in.stamps[k - 1]) {
      throw Error(fmt::format("{}: stamps must increase (sample {}: {} after {})", what, k,
                              to_seconds_text(in.stamps[k]), to_seconds_text(in.stamps[k - 1])));
    }
    if (!in.rates[k].allFinite()) throw Error(fmt::format("{}: sample {} is not finite", what, k));
    s.t.push_back((in.stamps[k] - epoch).seconds());
    if (k > 0) dt.push_back(s.t[k] - s.t[k - 1]);
  }
  s.w = in.rates;
  s.median_dt = median(dt);
  s.gap_s = 5.0 * s.median_dt;
  s.averaging_s = in.averaging_s;
  set_tangents(s);
  return s;
}

Series slice(const Series& s, double a, double b) {
  const size_t i0 = std::lower_bound(s.t.begin(), s.t.end(), a) - s.t.begin();
  const size_t i1 = std::upper_bound(s.t.begin(), s.t.end(), b) - s.t.begin();
  Series out;
  out.median_dt = s.median_dt, out.gap_s = s.gap_s, out.averaging_s = s.averaging_s;
  out.t.assign(s.t.begin() + i0, s.t.begin() + std::max(i0, i1));
  out.w.assign(s.w.begin() + i0, s.w.begin() + std::max(i0, i1));
  out.m.assign(s.m.begin() + i0, s.m.begin() + std::max(i0, i1));
  return out;
}

bool sample(const Series& s, double x, size_t& hint, Eigen::Vector3d& out) {
  size_t j;
  if (!locate(s, x, hint, j)) return false;
  const double t0 = s.t[j], t1 = s.t[j + 1], h = t1 - t0;
  const Eigen::Vector3d& p0 = s.w[j];
  const Eigen::Vector3d& p1 = s.w[j + 1];
  const Eigen::Vector3d& m0 = s.m[j];
  const Eigen::Vector3d& m1 = s.m[j + 1];
  const double u = (x - t0) / h, u2 = u * u, u3 = u2 * u;
  out = (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * h * m0 + (-2 * u3 + 3 * u2) * p1 +
        (u3 - u2) * h * m1;
  return true;
}

Series box_filter(const Series& s, double width) {
  const size_t n = s.t.size();
  // Cumulative integral, restarting after each gap (segments are identified by `segment`).
  std::vector<Eigen::Vector3d> I(n, Eigen::Vector3d::Zero());
  std::vector<int> segment(n, 0);
  for (size_t k = 1; k < n; ++k) {
    const double h = s.t[k] - s.t[k - 1];
    if (h > s.gap_s) {
      segment[k] = segment[k - 1] + 1;
    } else {
      segment[k] = segment[k - 1];
      I[k] = I[k - 1] + 0.5 * h * (s.w[k] + s.w[k - 1]);
    }
  }
  auto integral = [&](double x, size_t& hint, int& seg, Eigen::Vector3d& v) {
    size_t j;
    if (!locate(s, x, hint, j)) return false;
    const double tau = x - s.t[j], h = s.t[j + 1] - s.t[j];
    v = I[j] + tau * s.w[j] + (s.w[j + 1] - s.w[j]) * (tau * tau / (2 * h));
    seg = segment[j];
    return true;
  };
  Series out;
  out.median_dt = s.median_dt;
  out.gap_s = s.gap_s;
  out.averaging_s = width;
  size_t h_lo = 0, h_hi = 0;
  for (size_t k = 0; k < n; ++k) {
    Eigen::Vector3d lo, hi;
    int seg_lo, seg_hi;
    if (!integral(s.t[k] - 0.5 * width, h_lo, seg_lo, lo)) continue;
    if (!integral(s.t[k] + 0.5 * width, h_hi, seg_hi, hi) || seg_lo != seg_hi) continue;
    out.t.push_back(s.t[k]);
    out.w.push_back((hi - lo) / width);
  }
  if (out.t.size() < 10) throw Error("too few samples left after matching the streams' bandwidth");
  set_tangents(out);
  return out;
}

Grid norm_grid(const Series& s, double h) {
  Grid g;
  g.n0 = static_cast<long>(std::ceil(s.t.front() / h));
  const long n1 = static_cast<long>(std::floor(s.t.back() / h));
  const size_t size = n1 >= g.n0 ? static_cast<size_t>(n1 - g.n0 + 1) : 0;
  g.v.assign(size, 0.0);
  g.m.assign(size, 0.0);
  size_t hint = 0;
  double sum = 0;
  size_t count = 0;
  for (size_t i = 0; i < size; ++i) {
    Eigen::Vector3d w;
    if (sample(s, (g.n0 + static_cast<long>(i)) * h, hint, w)) {
      g.v[i] = w.norm();
      g.m[i] = 1.0;
      sum += g.v[i];
      ++count;
    }
  }
  const double mean = count ? sum / count : 0.0;
  for (size_t i = 0; i < size; ++i) g.v[i] = g.m[i] > 0 ? g.v[i] - mean : 0.0;
  return g;
}

double stddev_of_norm(const Series& s) {
  double sum = 0, sum2 = 0;
  for (const Eigen::Vector3d& w : s.w) {
    sum += w.norm();
    sum2 += w.squaredNorm();
  }
  const double n = static_cast<double>(s.w.size());
  return std::sqrt(std::max(0.0, sum2 / n - (sum / n) * (sum / n)));
}

Pairing make_pairing(const Series& ref, const Series& other) {
  Pairing p;
  p.slow_is_reference = ref.median_dt >= other.median_dt;
  p.slow = p.slow_is_reference ? &ref : &other;
  p.fast = p.slow_is_reference ? &other : &ref;
  return p;
}

}  // namespace rigcal::time_sync
