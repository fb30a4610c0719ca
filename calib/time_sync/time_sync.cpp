#include "rigcal/time_sync/time_sync.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/SVD>
#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/core.hpp>
#include <optional>

#include "rigcal/core/error.h"
#include "rigcal/core/se3.h"
#include "rigcal/core/stats.h"

namespace rigcal::time_sync {
namespace {

// A stream in seconds since a common epoch. A step longer than gap_s is a gap: nothing is
// interpolated across it.
struct Series {
  std::vector<double> t;
  std::vector<Eigen::Vector3d> w;
  std::vector<Eigen::Vector3d> m;  // tangents dw/dt for the interpolation (set_tangents)
  double median_dt = 0.0, gap_s = 0.0, averaging_s = 0.0;
  double rate_hz() const { return 1.0 / median_dt; }
};

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

// The samples of s with a <= t <= b (tangents kept: they are those of the whole stream).
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

// The two-sided 99.73 % quantile of Student's t (the "3 sigma" of a normal) with `dof` degrees of
// freedom: a drift fitted on few windows needs more than 3 of its sigmas to be significant.
double t_quantile_3sigma(double dof) {
  static constexpr double kTable[] = {235.783, 19.206, 9.219, 6.620, 5.507, 4.904, 4.530,
                                      4.277,   4.094,  3.957, 3.850, 3.764, 3.694, 3.636,
                                      3.586,   3.544,  3.507, 3.475, 3.447, 3.422};
  if (dof < 1) return INFINITY;
  if (dof <= 20) return kTable[static_cast<int>(dof) - 1];
  return 3.0 + 0.422 * 20.0 / dof;  // within 0.015 of the quantile beyond 20
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

// Cubic Hermite interpolation with finite-difference tangents (linear next to a gap or an end).
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

// The mean over [x - width/2, x + width/2] of the piecewise-linear signal, for every sample whose
// window lies inside one gap-free segment (others are dropped).
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

// |w| on the lattice t = n * h for n in [n0, n0 + size), with a validity mask; the values have
// their mean removed.
struct Grid {
  long n0 = 0;
  std::vector<double> v, m;
};

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

// Masked normalized cross-correlation (Padfield 2010) for every lag k = n_a - n_b (offset k*h)
// by FFT: the Pearson correlation of the overlapping valid samples. Entries with fewer than
// min_count overlapping samples are NaN. Returns values for k in [k_first, k_first + size).
std::vector<double> masked_ncc_fft(const Grid& a, const Grid& b, size_t min_count, long& k_first) {
  const int na = static_cast<int>(a.v.size()), nb = static_cast<int>(b.v.size());
  const int L = cv::getOptimalDFTSize(na + nb - 1);
  auto spectrum = [L](const std::vector<double>& x, int power, const std::vector<double>& mask) {
    cv::Mat row = cv::Mat::zeros(1, L, CV_64F);
    for (size_t i = 0; i < x.size(); ++i) {
      row.at<double>(0, static_cast<int>(i)) =
          power == 0 ? mask[i] : (power == 1 ? x[i] : x[i] * x[i]) * mask[i];
    }
    cv::Mat f;
    cv::dft(row, f);
    return f;
  };
  const cv::Mat Fma = spectrum(a.v, 0, a.m), Fa = spectrum(a.v, 1, a.m),
                Faa = spectrum(a.v, 2, a.m);
  const cv::Mat Fmb = spectrum(b.v, 0, b.m), Fb = spectrum(b.v, 1, b.m),
                Fbb = spectrum(b.v, 2, b.m);
  auto corr = [](const cv::Mat& A, const cv::Mat& B) {
    cv::Mat p, r;
    cv::mulSpectrums(A, B, p, 0, /*conjB=*/true);
    cv::idft(p, r, cv::DFT_SCALE | cv::DFT_REAL_OUTPUT);
    return r;
  };
  const cv::Mat n = corr(Fma, Fmb), sa = corr(Fa, Fmb), sb = corr(Fma, Fb), saa = corr(Faa, Fmb),
                sbb = corr(Fma, Fbb), sab = corr(Fa, Fb);
  // Index m = i - j in [-(nb-1), na-1] sits at m mod L; k = m + (a.n0 - b.n0).
  std::vector<double> out;
  out.reserve(static_cast<size_t>(na + nb - 1));
  k_first = -(nb - 1) + (a.n0 - b.n0);
  for (int m = -(nb - 1); m <= na - 1; ++m) {
    const int idx = m >= 0 ? m : m + L;
    const double cnt = std::round(n.at<double>(0, idx));
    if (cnt < static_cast<double>(min_count) || cnt < 3) {
      out.push_back(NAN);
      continue;
    }
    const double Sa = sa.at<double>(0, idx), Sb = sb.at<double>(0, idx);
    const double va = saa.at<double>(0, idx) - Sa * Sa / cnt;
    const double vb = sbb.at<double>(0, idx) - Sb * Sb / cnt;
    const double cov = sab.at<double>(0, idx) - Sa * Sb / cnt;
    out.push_back(va > 1e-12 * cnt && vb > 1e-12 * cnt ? cov / std::sqrt(va * vb) : NAN);
  }
  return out;
}

// The same correlation for one lag, directly; also returns the overlap count.
double masked_ncc_direct(const Grid& a, const Grid& b, long k, size_t& count) {
  // Pairs a[i], b[j] with (a.n0 + i) - (b.n0 + j) = k.
  const long shift = k - (a.n0 - b.n0);  // i = j + shift
  const long j0 = std::max(0L, -shift);
  const long j1 = std::min(static_cast<long>(b.v.size()), static_cast<long>(a.v.size()) - shift);
  double n = 0, Sa = 0, Sb = 0, Saa = 0, Sbb = 0, Sab = 0;
  for (long j = j0; j < j1; ++j) {
    const size_t i = static_cast<size_t>(j + shift);
    const double m = a.m[i] * b.m[static_cast<size_t>(j)];
    if (m == 0) continue;
    const double x = a.v[i], y = b.v[static_cast<size_t>(j)];
    n += 1;
    Sa += x;
    Sb += y;
    Saa += x * x;
    Sbb += y * y;
    Sab += x * y;
  }
  count = static_cast<size_t>(n);
  if (n < 3) return NAN;
  const double va = Saa - Sa * Sa / n, vb = Sbb - Sb * Sb / n;
  return va > 0 && vb > 0 ? (Sab - Sa * Sb / n) / std::sqrt(va * vb) : NAN;
}

// The vertex of the parabola through (-1, y0), (0, y1), (1, y2), in [-1, 1].
double parabola_vertex(double y0, double y1, double y2) {
  const double den = y0 - 2 * y1 + y2;
  if (!(std::abs(den) > 0)) return 0.0;
  return std::clamp(0.5 * (y0 - y2) / den, -1.0, 1.0);
}

// Minimizes f on [lo, hi] (f unimodal there) to within tol: Brent's method, golden-section steps
// where a parabola through the three best points cannot be trusted. On the smooth correlation
// and residual curves it converges in about 10 evaluations where golden section takes 25.
template <class F>
double brent_minimize(F f, double lo, double hi, double tol) {
  const double c = 0.5 * (3.0 - std::sqrt(5.0));
  double x = lo + c * (hi - lo), w = x, v = x;
  double fx = f(x), fw = fx, fv = fx;
  double d = 0.0, e = 0.0;  // the last step and the one before
  for (int it = 0; it < 100; ++it) {
    const double m = 0.5 * (lo + hi);
    const double tol1 = 0.5 * tol, tol2 = 2.0 * tol1;
    if (std::abs(x - m) <= tol2 - 0.5 * (hi - lo)) break;
    bool golden = true;
    if (std::abs(e) > tol1) {
      // The parabola through (v, fv), (w, fw), (x, fx); its step p / q from x.
      const double r = (x - w) * (fx - fv);
      double q = (x - v) * (fx - fw);
      double p = (x - v) * q - (x - w) * r;
      q = 2.0 * (q - r);
      if (q > 0) p = -p;
      q = std::abs(q);
      // Accept when it moves less than half the step before last and stays inside.
      if (std::abs(p) < std::abs(0.5 * q * e) && p > q * (lo - x) && p < q * (hi - x)) {
        e = d;
        d = p / q;
        const double u = x + d;
        if (u - lo < tol2 || hi - u < tol2) d = x < m ? tol1 : -tol1;
        golden = false;
      }
    }
    if (golden) {
      e = (x < m ? hi : lo) - x;
      d = c * e;
    }
    const double u = std::abs(d) >= tol1 ? x + d : x + (d > 0 ? tol1 : -tol1);
    const double fu = f(u);
    if (fu <= fx) {
      (u < x ? hi : lo) = x;
      v = w, fv = fw, w = x, fw = fx, x = u, fx = fu;
    } else {
      (u < x ? lo : hi) = u;
      if (fu <= fw || w == x) {
        v = w, fv = fw, w = u, fw = fu;
      } else if (fu <= fv || v == x || v == w) {
        v = u, fv = fu;
      }
    }
  }
  return x;
}

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

// Pearson correlation of |w_ref| and |w_other| at offset d.
double norm_ncc(const Pairing& p, double d) {
  struct Sums {
    double n = 0, Sa = 0, Sb = 0, Saa = 0, Sbb = 0, Sab = 0;
    Sums operator+(const Sums& o) const {
      return {n + o.n, Sa + o.Sa, Sb + o.Sb, Saa + o.Saa, Sbb + o.Sbb, Sab + o.Sab};
    }
  };
  const Sums t =
      p.reduce<Sums>(d, [](Sums& a, const Eigen::Vector3d& wr, const Eigen::Vector3d& wo) {
        const double x = wr.norm(), y = wo.norm();
        a.Sa += x;
        a.Sb += y;
        a.Saa += x * x;
        a.Sbb += y * y;
        a.Sab += x * y;
      });
  const double n = t.n, Sa = t.Sa, Sb = t.Sb, Saa = t.Saa, Sbb = t.Sbb, Sab = t.Sab;
  if (n < 3) return NAN;
  const double va = Saa - Sa * Sa / n, vb = Sbb - Sb * Sb / n;
  return va > 0 && vb > 0 ? (Sab - Sa * Sb / n) / std::sqrt(va * vb) : NAN;
}

struct AxisFit {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double sse = NAN;
  size_t n = 0;
};

// w_ref = R w_other + b by least squares (Kabsch on centred vectors) at offset d.
AxisFit fit_axes(const Pairing& p, double d) {
  struct Sums {
    size_t n = 0;
    Eigen::Vector3d sr = Eigen::Vector3d::Zero(), so = Eigen::Vector3d::Zero();
    Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
    double Srr = 0, Soo = 0;
    Sums operator+(const Sums& o) const {
      return {n + o.n, sr + o.sr, so + o.so, S + o.S, Srr + o.Srr, Soo + o.Soo};
    }
  };
  const Sums t =
      p.reduce<Sums>(d, [](Sums& a, const Eigen::Vector3d& wr, const Eigen::Vector3d& wo) {
        a.sr += wr;
        a.so += wo;
        a.S += wr * wo.transpose();
        a.Srr += wr.squaredNorm();
        a.Soo += wo.squaredNorm();
      });
  const Eigen::Vector3d &sr = t.sr, &so = t.so;
  const Eigen::Matrix3d& S = t.S;
  const double Srr = t.Srr, Soo = t.Soo;
  AxisFit fit;
  fit.n = t.n;
  if (fit.n < 10) return fit;
  const double n = static_cast<double>(fit.n);
  const Eigen::Vector3d mr = sr / n, mo = so / n;
  const Eigen::Matrix3d C = S - n * mr * mo.transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(C, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) D(2, 2) = -1;
  fit.R = svd.matrixU() * D * svd.matrixV().transpose();
  fit.b = mr - fit.R * mo;
  // SSE = sum |wr - mr|^2 + |wo - mo|^2 - 2 tr(R^T C).
  const double var_r = Srr - n * mr.squaredNorm(), var_o = Soo - n * mo.squaredNorm();
  fit.sse = std::max(0.0, var_r + var_o - 2.0 * (fit.R.transpose() * C).trace());
  return fit;
}

// The lag-1 autocorrelation of a residual sequence, clamped to [0, 0.99].
double lag1_correlation(const std::vector<double>& r) {
  if (r.size() < 3) return 0.0;
  double mean = 0;
  for (double x : r) mean += x;
  mean /= static_cast<double>(r.size());
  double c0 = 0, c1 = 0;
  for (size_t i = 0; i < r.size(); ++i) {
    c0 += (r[i] - mean) * (r[i] - mean);
    if (i > 0) c1 += (r[i] - mean) * (r[i - 1] - mean);
  }
  return c0 > 0 ? std::clamp(c1 / c0, 0.0, 0.99) : 0.0;
}

// Formal 1-sigma of d from the residuals of the final model at d and their derivative in d,
// inflated for residuals correlated in time (AR(1): n_eff = n (1 - rho) / (1 + rho)).
double formal_sigma(const Pairing& p, double d, bool three_axis, const AxisFit& fit, double eps) {
  // The norm model: |w_ref| = alpha |w_other| + beta.
  double alpha = 1, beta = 0;
  if (!three_axis) {
    double n = 0, Sx = 0, Sy = 0, Sxx = 0, Sxy = 0;
    p.for_each(d, [&](const Eigen::Vector3d& wr, const Eigen::Vector3d& wo, size_t) {
      const double x = wo.norm(), y = wr.norm();
      n += 1, Sx += x, Sy += y, Sxx += x * x, Sxy += x * y;
    });
    alpha = (n * Sxy - Sx * Sy) / (n * Sxx - Sx * Sx);
    beta = (Sy - alpha * Sx) / n;
  }
  // Residuals per evaluation point at d, d + eps and d - eps; points missing at any of the
  // three (at the ends of the overlap) are left out.
  auto residuals = [&](double dd) {
    std::vector<std::optional<Eigen::Vector3d>> r(p.points.size());
    p.for_each(dd, [&](const Eigen::Vector3d& wr, const Eigen::Vector3d& wo, size_t q) {
      r[q] = three_axis ? Eigen::Vector3d(wr - fit.R * wo - fit.b)
                        : Eigen::Vector3d(wr.norm() - alpha * wo.norm() - beta, 0, 0);
    });
    return r;
  };
  std::vector<std::optional<Eigen::Vector3d>> r0, rp, rm;
  tbb::parallel_invoke([&] { r0 = residuals(d); }, [&] { rp = residuals(d + eps); },
                       [&] { rm = residuals(d - eps); });
  const int dims = three_axis ? 3 : 1;
  double sse = 0, jtj = 0;
  size_t n = 0;
  std::vector<double> seq[3];
  for (size_t i = 0; i < r0.size(); ++i) {
    if (!r0[i] || !rp[i] || !rm[i]) continue;
    const Eigen::Vector3d J = (*rp[i] - *rm[i]) / (2 * eps);
    for (int c = 0; c < dims; ++c) {
      sse += (*r0[i])[c] * (*r0[i])[c];
      jtj += J[c] * J[c];
      seq[c].push_back((*r0[i])[c]);
    }
    ++n;
  }
  if (n < 10) return NAN;
  double rho = 0;
  for (int c = 0; c < dims; ++c) rho += lag1_correlation(seq[c]) / dims;
  const double dof = static_cast<double>(dims * n) - (three_axis ? 7.0 : 3.0);
  const double sigma2 = sse / dof;
  return std::sqrt(sigma2 / jtj * (1 + rho) / (1 - rho));
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

struct Refined {
  double integer_d = NAN, parabolic_d = NAN, norm_d = NAN, d = NAN, peak = NAN;
  AxisFit fit;
  bool at_edge = false;
  std::vector<CorrelationPoint> curve;
};

// From a first guess d0: the fine-grid correlation over d0 +- half_range, its integer peak, the
// parabola, the continuous norm refinement and (optionally) the three-axis refinement.
Refined refine(const Grid& fa, const Grid& fb, double h, const Pairing& p, double d0,
               double half_range, bool three_axis, size_t min_count, bool norm_stage = true) {
  Refined out;
  const long k0 = std::lround((d0 - half_range) / h), k1 = std::lround((d0 + half_range) / h);
  long best = k0;
  std::vector<double> ncc;
  for (long k = k0; k <= k1; ++k) {
    size_t count = 0;
    double c = masked_ncc_direct(fa, fb, k, count);
    if (count < min_count) c = NAN;
    ncc.push_back(c);
    out.curve.push_back({k * h, c});
    if (!std::isnan(c) && (std::isnan(ncc[best - k0]) || c > ncc[best - k0])) best = k;
  }
  if (std::isnan(ncc[best - k0])) return out;
  out.peak = ncc[best - k0];
  out.integer_d = best * h;
  out.at_edge = best == k0 || best == k1;
  double frac = 0;
  if (!out.at_edge) frac = parabola_vertex(ncc[best - k0 - 1], ncc[best - k0], ncc[best - k0 + 1]);
  out.parabolic_d = (best + frac) * h;
  // The continuous norm stage; skipped (the parabola stands for it) when only the three-axis
  // optimum is wanted, as in the drift windows.
  out.norm_d = norm_stage || !three_axis
                   ? brent_minimize([&](double d) { return -norm_ncc(p, d); }, out.parabolic_d - h,
                                    out.parabolic_d + h, 1e-6)
                   : out.parabolic_d;
  out.d = out.norm_d;
  if (three_axis) {
    out.d = brent_minimize([&](double d) { return fit_axes(p, d).sse; }, out.norm_d - h,
                           out.norm_d + h, 1e-6);
  }
  out.fit = fit_axes(p, out.d);
  return out;
}

Pairing make_pairing(const Series& ref, const Series& other) {
  Pairing p;
  p.slow_is_reference = ref.median_dt >= other.median_dt;
  p.slow = p.slow_is_reference ? &ref : &other;
  p.fast = p.slow_is_reference ? &other : &ref;
  return p;
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

namespace {

// One pass: the offset over the whole overlap, then the windows and the drift line.
TimeSyncResult estimate_pass(const AngularRates& reference_in, const AngularRates& other_in,
                             const TimeSyncOptions& opt) {
  TimeSyncResult res;
  if (reference_in.stamps.empty() || other_in.stamps.empty())
    throw Error("both streams need samples");
  const Time epoch_ref = reference_in.stamps.front();
  res.epoch = other_in.stamps.front();
  Series ref = make_series(reference_in, epoch_ref, "reference");
  Series oth = make_series(other_in, epoch_ref, "other");
  const double epoch_other_s = (res.epoch - epoch_ref).seconds();
  res.reference_rate_hz = ref.rate_hz();
  res.other_rate_hz = oth.rate_hz();
  // Match bandwidths: an instantaneous stream is box-filtered to the other's averaging.
  if (ref.averaging_s < oth.averaging_s) ref = box_filter(ref, oth.averaging_s);
  if (oth.averaging_s < ref.averaging_s) oth = box_filter(oth, ref.averaging_s);
  auto fail = [&](std::string verdict, std::string reason) {
    res.verdict = std::move(verdict);
    res.reason = std::move(reason);
    res.offset_s = res.sigma_s = NAN;
    return res;
  };
  res.excitation_reference_rad_s = stddev_of_norm(ref);
  res.excitation_other_rad_s = stddev_of_norm(oth);
  if (std::min(res.excitation_reference_rad_s, res.excitation_other_rad_s) <
      opt.min_excitation_rad_s) {
    return fail("not enough excitation",
                fmt::format("the angular rate's norm varies by {:.4f} rad/s (reference) and {:.4f} "
                            "rad/s (other), 1-sigma; at least {} is needed: rotate the sensors "
                            "back and forth about changing axes, not at a constant rate",
                            res.excitation_reference_rad_s, res.excitation_other_rad_s,
                            opt.min_excitation_rad_s));
  }
  const double span = std::min(ref.t.back() - ref.t.front(), oth.t.back() - oth.t.front());
  const double min_overlap_s = opt.min_overlap * span;

  // Coarse pass: FFT over every lag, both streams box-filtered to the coarse step.
  res.coarse_hz = std::min(opt.coarse_hz, std::max(res.reference_rate_hz, res.other_rate_hz));
  const double hc = 1.0 / res.coarse_hz;
  Grid ga, gb;
  tbb::parallel_invoke(
      [&] { ga = norm_grid(ref.averaging_s < hc ? box_filter(ref, hc) : ref, hc); },
      [&] { gb = norm_grid(oth.averaging_s < hc ? box_filter(oth, hc) : oth, hc); });
  if (ga.v.size() < 3 || gb.v.size() < 3) return fail("no overlap", "the streams are too short");
  long k_first = 0;
  const std::vector<double> coarse =
      masked_ncc_fft(ga, gb, static_cast<size_t>(min_overlap_s / hc), k_first);
  long best = -1;
  const long k_lo =
      std::isfinite(opt.max_offset_s) ? std::lround(-opt.max_offset_s / hc) : LONG_MIN;
  const long k_hi = std::isfinite(opt.max_offset_s) ? std::lround(opt.max_offset_s / hc) : LONG_MAX;
  std::vector<long> valid;
  for (size_t i = 0; i < coarse.size(); ++i) {
    const long k = k_first + static_cast<long>(i);
    if (k < k_lo || k > k_hi || std::isnan(coarse[i])) continue;
    valid.push_back(static_cast<long>(i));
    if (best < 0 || coarse[i] > coarse[best]) best = static_cast<long>(i);
  }
  if (best < 0) {
    return fail(
        "no overlap",
        fmt::format("no offset within +-{} s leaves {:.1f} s of overlap (half the shorter "
                    "stream); the reference spans [{:.3f}, {:.3f}] s and the other [{:.3f}, "
                    "{:.3f}] s of stamps: widen the search (--max-offset)",
                    opt.max_offset_s, min_overlap_s, ref.t.front(), ref.t.back(), oth.t.front(),
                    oth.t.back()));
  }
  for (long i : valid) res.coarse_curve.push_back({(k_first + i) * hc, coarse[i]});
  res.coarse_offset_s = (k_first + best) * hc;
  res.peak_ncc = coarse[best];
  // The main lobe: from the peak outwards while the correlation keeps falling.
  long lo = best, hi = best;
  auto ok = [&](long i) {
    const long k = k_first + i;
    return i >= 0 && i < static_cast<long>(coarse.size()) && k >= k_lo && k <= k_hi &&
           !std::isnan(coarse[i]);
  };
  while (ok(lo - 1) && coarse[lo - 1] <= coarse[lo]) --lo;
  while (ok(hi + 1) && coarse[hi + 1] <= coarse[hi]) ++hi;
  res.second_peak_ncc = -1;
  for (long i : valid) {
    if (i >= lo && i <= hi) continue;
    const bool local_max =
        (!ok(i - 1) || coarse[i - 1] <= coarse[i]) && (!ok(i + 1) || coarse[i + 1] <= coarse[i]);
    if (local_max && coarse[i] > res.second_peak_ncc) {
      res.second_peak_ncc = coarse[i];
      res.second_peak_offset_s = (k_first + i) * hc;
    }
  }
  res.peak_ratio = res.second_peak_ncc > 0 ? res.second_peak_ncc / res.peak_ncc : 0.0;
  res.overlap_s = std::min(ref.t.back(), oth.t.back() + res.coarse_offset_s) -
                  std::max(ref.t.front(), oth.t.front() + res.coarse_offset_s);
  if (!ok(best - 1) || !ok(best + 1)) {
    return fail("peak at the edge",
                fmt::format("the best correlation ({:.3f}) is at the edge of the search range, "
                            "offset {:.3f} s: the true offset may lie outside; widen --max-offset",
                            res.peak_ncc, res.coarse_offset_s));
  }
  if (res.peak_ncc < opt.min_peak_ncc) {
    return fail("poor correlation",
                fmt::format("the best normalized correlation is {:.3f} (at {:.3f} s), below {}: "
                            "the streams do not seem to see the same motion",
                            res.peak_ncc, res.coarse_offset_s, opt.min_peak_ncc));
  }
  if (res.peak_ratio > opt.max_peak_ratio) {
    return fail(
        "ambiguous",
        fmt::format("a second correlation peak at {:.3f} s reaches {:.3f} against {:.3f} at "
                    "{:.3f} s (ratio {:.2f}): the motion is too periodic to tell the offset; "
                    "record less regular motion or narrow --max-offset",
                    res.second_peak_offset_s, res.second_peak_ncc, res.peak_ncc,
                    res.coarse_offset_s, res.peak_ratio));
  }

  // Fine pass and continuous refinement.
  res.grid_hz = std::min(opt.fine_hz_max, std::max(res.reference_rate_hz, res.other_rate_hz));
  const double hf = 1.0 / res.grid_hz;
  Grid fa, fb;
  tbb::parallel_invoke([&] { fa = norm_grid(ref, hf); }, [&] { fb = norm_grid(oth, hf); });
  Pairing p = make_pairing(ref, oth);
  for (size_t i = 0; i < p.slow->t.size(); ++i) p.points.push_back(i);
  const size_t min_fine = static_cast<size_t>(min_overlap_s / hf);
  const Refined r = refine(fa, fb, hf, p, res.coarse_offset_s, 3 * hc, opt.three_axis, min_fine);
  if (std::isnan(r.d)) return fail("no overlap", "the fine correlation found no overlap");
  res.integer_offset_s = r.integer_d;
  res.parabolic_offset_s = r.parabolic_d;
  res.norm_offset_s = r.norm_d;
  res.fine_curve = r.curve;
  res.three_axis = opt.three_axis;
  res.R_reference_other = r.fit.R;
  res.bias_difference = r.fit.b;
  res.samples_used = r.fit.n;
  res.residual_rms_rad_s = std::sqrt(r.fit.sse / (3.0 * r.fit.n));
  res.sigma_formal_s = formal_sigma(p, r.d, opt.three_axis, r.fit, 0.1 * hf);
  res.mean_offset_s = r.d;

  // Drift: offsets in consecutive windows along the other stream.
  const double t0 = std::max(ref.t.front() - r.d, oth.t.front());
  const double t1 = std::min(ref.t.back() - r.d, oth.t.back());
  res.window_s = opt.window_s > 0 ? opt.window_s : std::max(20.0, (t1 - t0) / 10.0);
  const double W = res.window_s;
  std::vector<double> starts;
  for (double ws = t0; ws + W <= t1 + 1e-9; ws += W) starts.push_back(ws);
  // One window's offset; the windows are independent and run in parallel.
  auto window = [&](double ws) {
    WindowOffset wo;
    wo.t_other_s = ws + 0.5 * W - epoch_other_s;
    // The window's samples, in both streams (the other clock).
    Series rw = slice(ref, ws + r.d - 0.2, ws + r.d + W + 0.2), ow = slice(oth, ws, ws + W);
    if (rw.t.size() < 20 || ow.t.size() < 20) {
      wo.note = "too few samples";
      return wo;
    }
    if (std::min(stddev_of_norm(rw), stddev_of_norm(ow)) < opt.min_excitation_rad_s) {
      wo.note = "not enough excitation";
      return wo;
    }
    const Grid wa = norm_grid(rw, hf), wb = norm_grid(ow, hf);
    Pairing wp = make_pairing(rw, ow);
    for (size_t i = 0; i < wp.slow->t.size(); ++i) wp.points.push_back(i);
    const Refined wr = refine(wa, wb, hf, wp, r.d, std::min(0.1, 3 * hc), opt.three_axis,
                              static_cast<size_t>(0.8 * W / hf), /*norm_stage=*/false);
    wo.ncc = wr.peak;
    if (std::isnan(wr.d) || wr.at_edge || !(wr.peak >= opt.min_peak_ncc)) {
      wo.note =
          std::isnan(wr.d) ? "no overlap" : (wr.at_edge ? "peak at the edge" : "poor correlation");
      return wo;
    }
    wo.offset_s = wr.d;
    wo.sigma_s = formal_sigma(wp, wr.d, opt.three_axis, wr.fit, 0.1 * hf);
    wo.used = true;
    return wo;
  };
  res.windows.resize(starts.size());
  tbb::parallel_for(size_t(0), starts.size(),
                    [&](size_t k) { res.windows[k] = window(starts[k]); });
  // Linear fit offset = o0 + drift * t (other clock, seconds since the epoch), one pass of
  // outlier rejection (5 x 1.4826 MAD).
  auto fit_line = [&](double& o0, double& s, double& sd_o0, double& sd_s, double& rms) {
    double n = 0, St = 0, So = 0, Stt = 0, Sto = 0;
    for (const WindowOffset& w : res.windows) {
      if (!w.used) continue;
      n += 1, St += w.t_other_s, So += w.offset_s, Stt += w.t_other_s * w.t_other_s,
          Sto += w.t_other_s * w.offset_s;
    }
    const double det = n * Stt - St * St;
    s = (n * Sto - St * So) / det;
    o0 = (So - s * St) / n;
    double sse = 0;
    for (const WindowOffset& w : res.windows) {
      if (w.used) sse += std::pow(w.offset_s - o0 - s * w.t_other_s, 2);
    }
    const double sigma2 = n > 2 ? sse / (n - 2) : NAN;
    rms = std::sqrt(sse / n);
    // From the scatter about the line, and from the windows' own sigmas propagated (few windows
    // can scatter less than their noise by chance): the larger.
    double W = 0, Wt = 0, Wtt = 0;
    for (const WindowOffset& w : res.windows) {
      if (!w.used || !(w.sigma_s > 0)) continue;
      const double k = 1.0 / (w.sigma_s * w.sigma_s);
      W += k, Wt += k * w.t_other_s, Wtt += k * w.t_other_s * w.t_other_s;
    }
    const double wdet = W * Wtt - Wt * Wt;
    const double formal_s2 = wdet > 0 ? W / wdet : 0.0, formal_o02 = wdet > 0 ? Wtt / wdet : 0.0;
    sd_s = std::sqrt(std::max(sigma2 * n / det, formal_s2));
    sd_o0 = std::sqrt(std::max(sigma2 * Stt / det, formal_o02));
    return n;
  };
  size_t used = 0;
  for (const WindowOffset& w : res.windows) used += w.used;
  if (used >= 4) {
    double o0, s, sd_o0, sd_s, rms;
    fit_line(o0, s, sd_o0, sd_s, rms);
    std::vector<double> dev;
    for (const WindowOffset& w : res.windows) {
      if (w.used) dev.push_back(std::abs(w.offset_s - o0 - s * w.t_other_s));
    }
    const double mad = 1.4826 * median(dev);
    for (WindowOffset& w : res.windows) {
      // A window is an outlier beyond 5 MAD of the line, but never within 4 of its own sigma
      // (windows agreeing to a microsecond would otherwise reject their own noise).
      const double limit = std::max({5 * mad, 4 * w.sigma_s, 1e-6});
      if (w.used && std::abs(w.offset_s - o0 - s * w.t_other_s) > limit) {
        w.used = false;
        w.note = "outlier in the drift fit";
      }
    }
    used = 0;
    for (const WindowOffset& w : res.windows) used += w.used;
  }
  if (used >= 4) {
    double o0, s, sd_o0, sd_s, rms;
    fit_line(o0, s, sd_o0, sd_s, rms);
    res.drift_estimated = true;
    res.drift_ppm = s * 1e6;
    res.drift_sigma_ppm = sd_s * 1e6;
    res.window_residual_rms_s = rms;
    res.drift_significance_sigma = t_quantile_3sigma(static_cast<double>(used) - 2);
    res.drift_significant = std::abs(s) > res.drift_significance_sigma * sd_s;
    // Without drift, the windows' spread says how well the mean offset is known.
    double mean = 0, var = 0;
    for (const WindowOffset& w : res.windows) mean += w.used ? w.offset_s / used : 0.0;
    for (const WindowOffset& w : res.windows)
      var += w.used ? (w.offset_s - mean) * (w.offset_s - mean) / (used - 1) : 0.0;
    res.sigma_windows_s = std::sqrt(var / used);
    if (res.drift_significant) {
      // The whole-overlap formal sigma assumes a constant offset; with drift the line's own
      // intercept uncertainty is the figure.
      res.offset_s = o0;
      res.sigma_s = sd_o0;
      return res;
    }
  }
  res.offset_s = r.d;
  res.sigma_s = std::max(res.sigma_formal_s, res.sigma_windows_s);
  return res;
}

}  // namespace

TimeSyncResult estimate_time_offset(const AngularRates& reference, const AngularRates& other,
                                    const TimeSyncOptions& opt) {
  TimeSyncResult first = estimate_pass(reference, other, opt);
  if (first.verdict != "ok" || !first.drift_significant) return first;
  // With drift, a window's offset is the mean of a changing offset weighted by where in the
  // window the motion is: biased by up to drift x window / 2. Remove the drift from the other
  // stamps, t' = t + s (t - epoch), and measure again: the second pass sees an almost constant
  // offset, its windows are unbiased and its whole-overlap fit is meaningful again.
  const double s = first.drift_ppm * 1e-6;
  AngularRates warped = other;
  for (Time& t : warped.stamps) t = t + Time::from_seconds(s * (t - first.epoch).seconds());
  TimeSyncResult res = estimate_pass(reference, warped, opt);
  if (res.verdict != "ok" || !res.drift_estimated) return first;
  // t_ref = t' + o + s2 (t' - e) with t' - e = (1 + s)(t - e): drift s + s2 (1 + s).
  const double residual = res.drift_ppm * 1e-6;
  res.drift_ppm = 1e6 * (s + residual * (1 + s));
  res.drift_significant =
      std::abs(res.drift_ppm) > res.drift_significance_sigma * res.drift_sigma_ppm;
  if (!res.drift_significant) return first;  // only if the second pass undoes the first
  for (WindowOffset& w : res.windows) {
    w.t_other_s /= 1 + s;
    if (std::isfinite(w.offset_s)) w.offset_s += s * w.t_other_s;
  }
  // The offset at the epoch: the second pass's line when its residual drift is significant,
  // else its constant offset (the epoch is a fixed point of the warp).
  res.mean_offset_s = first.mean_offset_s;
  return res;
}

}  // namespace rigcal::time_sync
