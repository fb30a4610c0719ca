#include "rigcal/bench/metrics.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/SVD>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <numeric>

#include "rigcal/core/error.h"
#include "rigcal/core/memory.h"
#include "rigcal/core/stats.h"

namespace rigcal::bench {

Stats statistics(std::vector<double> values) { return statistics_in_place(values); }

Stats statistics_in_place(std::span<double> values) {
  Stats s;
  s.n = values.size();
  if (values.empty()) return s;
  double sum = 0.0;
  s.min = values.front();
  s.max = values.front();
  for (double v : values) {
    sum += v;
    s.sse += v * v;
    s.min = std::min(s.min, v);
    s.max = std::max(s.max, v);
  }
  const double n = static_cast<double>(values.size());
  s.mean = sum / n;
  s.rmse = std::sqrt(s.sse / n);
  double var = 0.0;
  for (double v : values) var += (v - s.mean) * (v - s.mean);
  s.std = std::sqrt(var / n);
  s.median = median_midpoint_in_place(values);
  return s;
}

Distribution distribution(std::vector<double> values) {
  Distribution d;
  d.n = values.size();
  if (values.empty()) return d;
  const auto [lo_it, hi_it] = std::minmax_element(values.begin(), values.end());
  const double lo = *lo_it, hi = *hi_it;
  // numpy's percentile ('linear'): at position q (n - 1), between the order statistics around it.
  auto quantile = [&](double q) {
    const double pos = q * static_cast<double>(values.size() - 1);
    const size_t k = static_cast<size_t>(pos);
    const auto at = values.begin() + static_cast<std::ptrdiff_t>(k);
    std::nth_element(values.begin(), at, values.end());
    const double below = *at;
    if (k + 1 >= values.size()) return below;
    const double above = *std::min_element(at + 1, values.end());
    return below + (pos - static_cast<double>(k)) * (above - below);
  };
  d.q1 = quantile(0.25);
  d.median = quantile(0.5);
  d.q3 = quantile(0.75);
  const double iqr = d.q3 - d.q1, reach_low = d.q1 - 1.5 * iqr, reach_high = d.q3 + 1.5 * iqr;
  d.whisker_low = d.q1;
  d.whisker_high = d.q3;
  for (double v : values) {
    if (v >= reach_low) d.whisker_low = std::min(d.whisker_low, v);
    if (v <= reach_high) d.whisker_high = std::max(d.whisker_high, v);
  }
  const double n = static_cast<double>(values.size());
  size_t bins = 1;
  if (hi > lo) {
    const double h = 2.0 * iqr / std::cbrt(n);
    bins = h > 0 ? static_cast<size_t>(std::ceil((hi - lo) / h))
                 : static_cast<size_t>(std::ceil(std::sqrt(n)));
    bins = std::clamp<size_t>(bins, 1, 50);
  }
  d.bin_low = lo;
  d.bin_width = hi > lo ? (hi - lo) / static_cast<double>(bins) : 1.0;
  d.counts.assign(bins, 0);
  for (double v : values) {
    const double f = (v - lo) / d.bin_width;
    ++d.counts[std::min(bins - 1, static_cast<size_t>(std::max(0.0, f)))];
  }
  return d;
}

std::vector<std::pair<size_t, size_t>> nearest_stamps(const std::vector<Time>& a,
                                                      const std::vector<Time>& b, Time max_diff) {
  std::vector<std::pair<size_t, size_t>> pairs;
  pairs.reserve(std::min(a.size(), b.size()));
  if (b.empty()) return pairs;
  size_t j = 0;  // first stamp of b that is >= the current stamp of a (both sorted)
  for (size_t i = 0; i < a.size(); ++i) {
    while (j < b.size() && b[j] < a[i]) ++j;
    size_t best = j;
    if (j == b.size() || (j > 0 && (a[i] - b[j - 1]) <= (b[j] - a[i]))) best = j - 1;
    while (best > 0 && best < j && b[best - 1] == b[best]) --best;  // the first of equal stamps
    const Time diff = a[i] < b[best] ? b[best] - a[i] : a[i] - b[best];
    if (diff <= max_diff) pairs.emplace_back(i, best);
  }
  return pairs;
}

Matches associate_evo(const Trajectory& gt, const Trajectory& est, Time max_diff) {
  Matches m;
  const bool est_longer = est.size() > gt.size();
  const auto pairs = est_longer ? nearest_stamps(gt.stamps, est.stamps, max_diff)
                                : nearest_stamps(est.stamps, gt.stamps, max_diff);
  for (const auto& [short_i, long_i] : pairs) {
    m.gt.push_back(est_longer ? short_i : long_i);
    m.est.push_back(est_longer ? long_i : short_i);
  }
  return m;
}

std::vector<std::pair<size_t, size_t>> nearest_seconds(const std::vector<double>& a,
                                                       const std::vector<double>& b,
                                                       double max_diff) {
  std::vector<std::pair<size_t, size_t>> pairs;
  pairs.reserve(std::min(a.size(), b.size()));
  if (b.empty()) return pairs;
  size_t j = 0;  // first stamp of b that is >= the current stamp of a
  for (size_t i = 0; i < a.size(); ++i) {
    const double t = a[i];
    while (j < b.size() && b[j] < t) ++j;
    // Rounded differences are monotone on each side of t, so the smallest is at j - 1 or j, and
    // an earlier stamp below t can only tie with j - 1: numpy's argmin takes the first of a tie.
    const double d_hi = j < b.size() ? std::abs(b[j] - t) : INFINITY;
    const double d_lo = j > 0 ? std::abs(b[j - 1] - t) : INFINITY;
    size_t best = j;
    double d = d_hi;
    if (j > 0 && d_lo <= d_hi) {
      d = d_lo;
      best = j - 1;
      if (best > 0 && std::abs(b[best - 1] - t) <= d_lo) {
        best = static_cast<size_t>(
            std::partition_point(b.begin(), b.begin() + static_cast<std::ptrdiff_t>(j),
                                 [&](double s) { return std::abs(s - t) > d_lo; }) -
            b.begin());
      }
    }
    if (d <= max_diff) pairs.emplace_back(i, best);
  }
  return pairs;
}

std::vector<double> evo_seconds(const std::vector<Time>& stamps, bool read_as_ns) {
  std::vector<double> out(stamps.size());
  for (size_t i = 0; i < stamps.size(); ++i) {
    if (read_as_ns) {
      out[i] = static_cast<double>(stamps[i].ns) / 1e9;
    } else {
      const std::string text = to_seconds_text(stamps[i]);
      std::from_chars(text.data(), text.data() + text.size(), out[i]);
    }
  }
  return out;
}

Matches associate_evo_seconds(std::vector<double> gt_seconds, std::vector<double> est_seconds,
                              double max_diff, double est_offset) {
  Matches m;
  const bool est_longer = est_seconds.size() > gt_seconds.size();
  if (est_offset != 0.0) {
    for (double& s : est_longer ? est_seconds : gt_seconds)
      s += est_longer ? est_offset : -est_offset;
  }
  const auto pairs = est_longer ? nearest_seconds(gt_seconds, est_seconds, max_diff)
                                : nearest_seconds(est_seconds, gt_seconds, max_diff);
  for (const auto& [short_i, long_i] : pairs) {
    m.gt.push_back(est_longer ? short_i : long_i);
    m.est.push_back(est_longer ? long_i : short_i);
  }
  return m;
}

Matches associate_one_to_one(const Trajectory& gt, const Trajectory& est, Time max_diff) {
  struct Candidate {
    int64_t diff;
    size_t gt, est;
  };
  std::vector<Candidate> candidates;
  size_t lo = 0;
  for (size_t i = 0; i < gt.size(); ++i) {
    while (lo < est.size() && est.stamps[lo] < gt.stamps[i] - max_diff) ++lo;
    for (size_t j = lo; j < est.size() && est.stamps[j] <= gt.stamps[i] + max_diff; ++j) {
      candidates.push_back({std::abs((gt.stamps[i] - est.stamps[j]).ns), i, j});
    }
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
    return std::tie(x.diff, x.gt, x.est) < std::tie(y.diff, y.gt, y.est);
  });
  std::vector<char> gt_used(gt.size(), 0), est_used(est.size(), 0);
  std::vector<std::pair<size_t, size_t>> chosen;
  for (const Candidate& c : candidates) {
    if (gt_used[c.gt] || est_used[c.est]) continue;
    gt_used[c.gt] = est_used[c.est] = 1;
    chosen.emplace_back(c.gt, c.est);
  }
  std::sort(chosen.begin(), chosen.end());
  Matches m;
  for (const auto& [g, e] : chosen) {
    m.gt.push_back(g);
    m.est.push_back(e);
  }
  return m;
}

Matches associate_by_index(const Trajectory& gt, const Trajectory& est) {
  Matches m;
  const size_t n = std::min(gt.size(), est.size());
  m.gt.resize(n);
  m.est.resize(n);
  std::iota(m.gt.begin(), m.gt.end(), 0);
  std::iota(m.est.begin(), m.est.end(), 0);
  return m;
}

Interpolated interpolate_gt(const Trajectory& gt, const Trajectory& est, Time max_gap) {
  // In chunks of estimate stamps, in parallel: first counted, then written at their offsets.
  constexpr size_t kChunk = size_t{1} << 14;
  const size_t n = est.size(), n_chunks = (n + kChunk - 1) / kChunk;
  // Calls take(i, j, fraction) for each estimate stamp of the chunk inside a GT interval no
  // longer than max_gap (j: the first GT stamp at or after it; fraction < 0: at GT stamp j).
  auto visit = [&](size_t chunk, auto&& take) {
    const size_t i0 = chunk * kChunk, i1 = std::min(n, i0 + kChunk);
    size_t j = static_cast<size_t>(
        std::lower_bound(gt.stamps.begin(), gt.stamps.end(), est.stamps[i0]) - gt.stamps.begin());
    for (size_t i = i0; i < i1; ++i) {
      const Time t = est.stamps[i];
      while (j < gt.size() && gt.stamps[j] < t) ++j;
      if (j == gt.size()) return;
      if (gt.stamps[j] == t) {
        take(i, j, -1.0);
        continue;
      }
      if (j == 0) continue;
      const Time gap = gt.stamps[j] - gt.stamps[j - 1];
      if (gap > max_gap) continue;
      take(i, j, static_cast<double>((t - gt.stamps[j - 1]).ns) / static_cast<double>(gap.ns));
    }
  };
  std::vector<size_t> offset(n_chunks + 1, 0);
  tbb::parallel_for(size_t{0}, n_chunks, [&](size_t c) {
    size_t count = 0;
    visit(c, [&](size_t, size_t, double) { ++count; });
    offset[c + 1] = count;
  });
  for (size_t c = 0; c < n_chunks; ++c) offset[c + 1] += offset[c];
  Interpolated out;
  reserve_huge_touched(out.est, offset.back());
  reserve_huge_touched(out.T_world_gt, offset.back());
  out.est.resize(offset.back());
  out.T_world_gt.resize(offset.back());
  tbb::parallel_for(size_t{0}, n_chunks, [&](size_t c) {
    size_t at = offset[c];
    visit(c, [&](size_t i, size_t j, double fraction) {
      out.est[at] = i;
      out.T_world_gt[at] = fraction < 0
                               ? gt.T_world_body[j]
                               : interpolate(gt.T_world_body[j - 1], gt.T_world_body[j], fraction);
      ++at;
    });
  });
  return out;
}

Alignment alignment_from_string(std::string_view name) {
  for (Alignment a :
       {Alignment::se3, Alignment::sim3, Alignment::yaw, Alignment::origin, Alignment::none}) {
    if (name == to_string(a)) return a;
  }
  throw Error(fmt::format("unknown alignment '{}'; expected se3, sim3, yaw, origin or none", name));
}

std::string_view to_string(Alignment alignment) {
  switch (alignment) {
    case Alignment::se3:
      return "se3";
    case Alignment::sim3:
      return "sim3";
    case Alignment::yaw:
      return "yaw";
    case Alignment::origin:
      return "origin";
    case Alignment::none:
      return "none";
  }
  return "?";
}

AlignmentResult align(const std::vector<SE3>& T_world_gt, const std::vector<SE3>& T_world_est,
                      Alignment method, size_t n_first) {
  if (T_world_gt.size() != T_world_est.size()) throw Error("alignment needs matched poses");
  AlignmentResult r;
  r.method = method;
  const size_t n = n_first == 0 ? T_world_gt.size() : std::min(n_first, T_world_gt.size());
  r.n_used = n;
  if (method == Alignment::none) return r;
  if (n == 0) throw Error("no matched poses to align");
  if (method == Alignment::origin) {
    r.T_gt_est = T_world_gt.front() * T_world_est.front().inverse();
    r.n_used = 1;
    return r;
  }
  if (n < 3)
    throw Error(
        fmt::format("{} alignment needs at least 3 matched poses, got {}", to_string(method), n));
  Eigen::Vector3d mean_gt = Eigen::Vector3d::Zero(), mean_est = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    mean_gt += T_world_gt[i].t;
    mean_est += T_world_est[i].t;
  }
  mean_gt /= static_cast<double>(n);
  mean_est /= static_cast<double>(n);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  double var_est = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d g = T_world_gt[i].t - mean_gt, e = T_world_est[i].t - mean_est;
    cov += g * e.transpose();
    var_est += e.squaredNorm();
  }
  cov /= static_cast<double>(n);
  var_est /= static_cast<double>(n);
  if (method == Alignment::yaw) {
    const double yaw = std::atan2(cov(1, 0) - cov(0, 1), cov(0, 0) + cov(1, 1));
    r.T_gt_est.R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    r.T_gt_est.t = mean_gt - r.T_gt_est.R * mean_est;
    return r;
  }
  // Umeyama (1991): cov = U D V^T, R = U S V^T, scale = trace(D S) / var_est.
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d d = svd.singularValues();
  if (!(d(1) > 1e-12 * std::max(1.0, d(0)))) {
    throw Error(
        "the matched positions lie on a line (or a point): rotation alignment is undefined; "
        "use --align origin or none");
  }
  Eigen::Vector3d s(1, 1, 1);
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0) s(2) = -1;
  r.T_gt_est.R = svd.matrixU() * s.asDiagonal() * svd.matrixV().transpose();
  if (method == Alignment::sim3) r.scale = d.dot(s) / var_est;
  r.T_gt_est.t = mean_gt - r.scale * (r.T_gt_est.R * mean_est);
  return r;
}

SE3 apply(const AlignmentResult& alignment, const SE3& T_world_est) {
  SE3 scaled = T_world_est;
  scaled.t *= alignment.scale;
  return alignment.T_gt_est * scaled;
}

PoseErrors absolute_errors(const std::vector<SE3>& T_world_gt,
                           const std::vector<SE3>& T_world_est) {
  PoseErrors e;
  reserve_huge_touched(e.trans, T_world_gt.size());
  reserve_huge_touched(e.rot_deg, T_world_gt.size());
  e.trans.resize(T_world_gt.size());
  e.rot_deg.resize(T_world_gt.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, T_world_gt.size(), 4096), [&](const auto& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      e.trans[i] = (T_world_est[i].t - T_world_gt[i].t).norm();
      e.rot_deg[i] =
          rotation_angle(T_world_gt[i].R.transpose() * T_world_est[i].R) * (180.0 / M_PI);
    }
  });
  return e;
}

std::vector<double> cumulative_distances(const std::vector<SE3>& T_world_body) {
  std::vector<double> dist;
  reserve_huge_touched(dist, T_world_body.size());
  dist.resize(T_world_body.size(), 0.0);
  for (size_t i = 1; i < T_world_body.size(); ++i) {
    dist[i] = dist[i - 1] + (T_world_body[i].t - T_world_body[i - 1].t).norm();
  }
  return dist;
}

namespace {
// The angle of a rotation from its antisymmetric part and its trace: sin and cos of the angle,
// accurate at small angles (the sine from the differences, not from a cosine near 1).
double angle_of(const Eigen::Matrix3d& M) {
  const double s =
      0.5 * Eigen::Vector3d(M(2, 1) - M(1, 2), M(0, 2) - M(2, 0), M(1, 0) - M(0, 1)).norm();
  const double c = 0.5 * (M.trace() - 1.0);
  return std::atan2(s, c);
}
}  // namespace

SegmentErrors length_segment_errors(const std::vector<SE3>& T_world_gt,
                                    const std::vector<SE3>& T_world_est,
                                    const std::vector<double>& lengths, size_t step,
                                    std::vector<Segment>* segments) {
  const std::vector<double> dist = cumulative_distances(T_world_gt);
  const size_t n_starts = (dist.size() + step - 1) / step, n_len = lengths.size();
  // A start has a segment of length k when the path after it is longer (the end is then the
  // first pose farther than the length): the path left shrinks as the start advances, so the
  // starts with one are the first with[k]. Start s's segments go from Σ_k min(s, with[k]) on.
  std::vector<size_t> with(n_len);
  size_t total = 0;
  for (size_t k = 0; k < n_len; ++k) {
    size_t lo = 0, hi = n_starts;
    while (lo < hi) {
      const size_t mid = lo + (hi - lo) / 2;
      if (dist[mid * step] + lengths[k] < dist.back())
        lo = mid + 1;
      else
        hi = mid;
    }
    with[k] = lo;
    total += lo;
  }
  SegmentErrors out;
  reserve_huge(out.trans, total);
  reserve_huge(out.rot_deg, total);
  out.trans.resize(total);
  out.rot_deg.resize(total);
  if (segments) {
    reserve_huge_touched(*segments, total);
    segments->resize(total);
  }
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n_starts, 1024), [&](const auto& range) {
    // Each length's end, carried from start to start: the ends only move forward.
    std::vector<size_t> end(n_len, 0);
    for (size_t s = range.begin(); s < range.end(); ++s) {
      const size_t first = s * step;
      size_t at = 0;
      for (size_t k = 0; k < n_len; ++k) at += std::min(s, with[k]);
      const SE3& gi = T_world_gt[first];
      const SE3& ei = T_world_est[first];
      // E = inv(dP_est) dP_gt: |t(E)| = |t(dP_gt) - t(dP_est)| (a rotation keeps lengths), and
      // R(E) = R_ej' A R_gj with A = R_ei R_gi', similar to A R_gj R_ej': the same angle.
      const Eigen::Matrix3d A = ei.R * gi.R.transpose();
      for (size_t k = 0; k < n_len; ++k) {
        if (s >= with[k]) continue;
        // The first pose farther than the length along the GT path (the KITTI devkit's rule).
        const double target = dist[first] + lengths[k];
        size_t last = std::max(end[k], first);
        while (dist[last] <= target) ++last;  // stops: the path after `first` is longer
        end[k] = last;
        const SE3& gj = T_world_gt[last];
        const SE3& ej = T_world_est[last];
        const Eigen::Vector3d d_gt = gi.R.transpose() * (gj.t - gi.t);
        const Eigen::Vector3d d_est = ei.R.transpose() * (ej.t - ei.t);
        const Eigen::Matrix3d M = A * gj.R * ej.R.transpose();
        out.trans[at] = (d_gt - d_est).norm();
        out.rot_deg[at] = angle_of(M) * (180.0 / M_PI);
        if (segments) (*segments)[at] = {first, last, lengths[k], out.trans[at], out.rot_deg[at]};
        ++at;
      }
    }
  });
  // The pooled sums in the segments' order, as one thread adds them.
  size_t i = 0;
  for (size_t s = 0; s < n_starts; ++s) {
    for (size_t k = 0; k < n_len; ++k) {
      if (s >= with[k]) continue;
      out.trans_per_length += out.trans[i] / lengths[k];
      out.rot_deg_per_length += out.rot_deg[i] / lengths[k];
      ++i;
    }
  }
  return out;
}

std::vector<Segment> length_segments(const std::vector<SE3>& T_world_gt,
                                     const std::vector<SE3>& T_world_est,
                                     const std::vector<double>& lengths, size_t step) {
  std::vector<Segment> segments;
  length_segment_errors(T_world_gt, T_world_est, lengths, step, &segments);
  return segments;
}

DeltaUnit delta_unit_from_string(std::string_view name) {
  if (name == "f" || name == "frames") return DeltaUnit::frames;
  if (name == "m" || name == "meters") return DeltaUnit::meters;
  if (name == "d" || name == "deg" || name == "degrees") return DeltaUnit::degrees;
  if (name == "r" || name == "rad" || name == "radians") return DeltaUnit::radians;
  throw Error(fmt::format(
      "unknown delta unit '{}'; expected f (frames), m (metres), d (degrees) or r (radians)",
      name));
}

std::string_view to_string(DeltaUnit unit) {
  switch (unit) {
    case DeltaUnit::frames:
      return "frames";
    case DeltaUnit::meters:
      return "m";
    case DeltaUnit::degrees:
      return "deg";
    case DeltaUnit::radians:
      return "rad";
  }
  return "?";
}

namespace {

// evo's filter_pairs_by_path with all_pairs: for each i, numpy's argmin over j > i of
// |(dist[j] - dist[i]) - delta|. The differences grow with j, so the smallest is at the first j
// whose path reaches delta or at the one before it, and a tie goes to the first of equal paths.
std::vector<std::pair<size_t, size_t>> all_pairs_by_path(const std::vector<double>& dist,
                                                         double delta, double tol) {
  std::vector<std::pair<size_t, size_t>> pairs;
  const size_t n = dist.size();
  for (size_t i = 0; i + 1 < n; ++i) {
    const double d0 = dist[i];
    const auto reach = [&](double d) { return (d - d0) - delta; };
    size_t k = static_cast<size_t>(
        std::partition_point(dist.begin() + static_cast<std::ptrdiff_t>(i + 1), dist.end(),
                             [&](double d) { return reach(d) < 0.0; }) -
        dist.begin());
    if (k > i + 1 && (k == n || std::abs(reach(dist[k - 1])) <= std::abs(reach(dist[k])))) {
      const double below = reach(dist[k - 1]);  // the first path that rounds to the same
      k = static_cast<size_t>(
          std::partition_point(dist.begin() + static_cast<std::ptrdiff_t>(i + 1),
                               dist.begin() + static_cast<std::ptrdiff_t>(k - 1),
                               [&](double d) { return reach(d) < below; }) -
          dist.begin());
    }
    if (std::abs(reach(dist[k])) <= tol) pairs.emplace_back(i, k);
  }
  return pairs;
}

// evo's filter_pairs_by_angle with all_pairs: every later pose whose relative rotation's angle
// is within [delta - tol, delta + tol] rad. Quadratic, as evo's; rows in parallel.
std::vector<std::pair<size_t, size_t>> all_pairs_by_angle(const std::vector<SE3>& poses,
                                                          double delta, double tol) {
  const size_t n = poses.size();
  std::vector<std::vector<size_t>> ends(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 16), [&](const auto& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      const Eigen::Matrix3d Rt = poses[i].R.transpose();
      for (size_t j = i + 1; j < n; ++j) {
        const double angle = rotation_angle(Rt * poses[j].R);
        if (delta - tol <= angle && angle <= delta + tol) ends[i].push_back(j);
      }
    }
  });
  std::vector<std::pair<size_t, size_t>> pairs;
  for (size_t i = 0; i < n; ++i)
    for (size_t j : ends[i]) pairs.emplace_back(i, j);
  return pairs;
}

}  // namespace

std::vector<std::pair<size_t, size_t>> evo_delta_pairs(const std::vector<SE3>& T_world_body,
                                                       double delta, DeltaUnit unit, bool all_pairs,
                                                       double rel_tol) {
  std::vector<std::pair<size_t, size_t>> pairs;
  const size_t n = T_world_body.size();
  if (!(delta > 0)) throw Error("the RPE delta must be positive");
  if (unit == DeltaUnit::frames) {
    const size_t d = static_cast<size_t>(delta);
    if (static_cast<double>(d) != delta) throw Error("a delta in frames must be a whole number");
    reserve_huge(pairs, all_pairs ? n : n / d + 1);
    for (size_t i = 0; i + d < n; i += all_pairs ? 1 : d) pairs.emplace_back(i, i + d);
    return pairs;
  }
  if (unit == DeltaUnit::meters) {
    if (all_pairs)
      return all_pairs_by_path(cumulative_distances(T_world_body), delta, delta * rel_tol);
    std::vector<size_t> ids;
    double path = 0.0;
    for (size_t i = 1; i < n; ++i) {
      path += (T_world_body[i].t - T_world_body[i - 1].t).norm();
      if (path >= delta) ids.push_back(i), path = 0.0;
    }
    for (size_t k = 0; k + 1 < ids.size(); ++k) pairs.emplace_back(ids[k], ids[k + 1]);
    return pairs;
  }
  const bool degrees = unit == DeltaUnit::degrees;
  if (delta > (degrees ? 180.0 : M_PI)) {
    throw Error(fmt::format("an angle delta must be within [0, {}] {}", degrees ? "180" : "pi",
                            to_string(unit)));
  }
  const double delta_rad = degrees ? delta * (M_PI / 180.0) : delta;  // numpy's deg2rad
  const double tol_rad = degrees ? (delta * rel_tol) * (M_PI / 180.0) : delta * rel_tol;
  if (all_pairs) return all_pairs_by_angle(T_world_body, delta_rad, tol_rad);
  double accumulated = 0.0;
  size_t start = 0;
  for (size_t i = 0; i + 1 < n; ++i) {
    accumulated += rotation_angle(T_world_body[i].R.transpose() * T_world_body[i + 1].R);
    if (accumulated >= delta_rad) {
      pairs.emplace_back(start, i + 1);
      accumulated = 0.0;
      start = i + 1;
    }
  }
  return pairs;
}

std::vector<Segment> delta_errors(const std::vector<SE3>& T_world_gt,
                                  const std::vector<SE3>& T_world_est,
                                  const std::vector<std::pair<size_t, size_t>>& pairs) {
  std::vector<Segment> segments;
  reserve_huge_touched(segments, pairs.size());
  segments.resize(pairs.size());
  const std::vector<double> dist = cumulative_distances(T_world_gt);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, pairs.size(), 4096), [&](const auto& r) {
    for (size_t k = r.begin(); k < r.end(); ++k) {
      const auto [i, j] = pairs[k];
      const SE3 dQ = T_world_gt[i].inverse() * T_world_gt[j];
      const SE3 dP = T_world_est[i].inverse() * T_world_est[j];
      const SE3 E = dQ.inverse() * dP;
      segments[k] = {i, j, dist[j] - dist[i], E.t.norm(), rotation_angle(E.R) * (180.0 / M_PI)};
    }
  });
  return segments;
}

std::vector<Segment> frame_deltas(const std::vector<SE3>& T_world_gt,
                                  const std::vector<SE3>& T_world_est, size_t delta) {
  if (delta == 0) throw Error("the RPE delta must be at least 1 frame");
  return delta_errors(
      T_world_gt, T_world_est,
      evo_delta_pairs(T_world_est, static_cast<double>(delta), DeltaUnit::frames, false));
}

Drift pooled_drift(const std::vector<Segment>& segments) {
  Drift d;
  d.n_segments = segments.size();
  if (segments.empty()) return d;
  double t = 0.0, r = 0.0;
  for (const Segment& s : segments) {
    t += s.trans / s.length;
    r += s.rot_deg / s.length;
  }
  d.trans_pct = 100.0 * t / static_cast<double>(segments.size());
  d.rot_deg_per_m = r / static_cast<double>(segments.size());
  return d;
}

}  // namespace rigcal::bench
