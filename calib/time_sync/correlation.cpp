#include "rigcal/time_sync/correlation.h"

#include <algorithm>
#include <opencv2/core.hpp>

namespace rigcal::time_sync {

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

Peaks find_peaks(const std::vector<double>& ncc, long k_first, long k_lo, long k_hi) {
  Peaks peaks;
  long& best = peaks.best;
  for (size_t i = 0; i < ncc.size(); ++i) {
    const long k = k_first + static_cast<long>(i);
    if (k < k_lo || k > k_hi || std::isnan(ncc[i])) continue;
    peaks.valid.push_back(static_cast<long>(i));
    if (best < 0 || ncc[i] > ncc[best]) best = static_cast<long>(i);
  }
  if (best < 0) return peaks;
  auto ok = [&](long i) {
    const long k = k_first + i;
    return i >= 0 && i < static_cast<long>(ncc.size()) && k >= k_lo && k <= k_hi &&
           !std::isnan(ncc[i]);
  };
  long lo = best, hi = best;
  while (ok(lo - 1) && ncc[lo - 1] <= ncc[lo]) --lo;
  while (ok(hi + 1) && ncc[hi + 1] <= ncc[hi]) ++hi;
  for (long i : peaks.valid) {
    if (i >= lo && i <= hi) continue;
    const bool local_max =
        (!ok(i - 1) || ncc[i - 1] <= ncc[i]) && (!ok(i + 1) || ncc[i + 1] <= ncc[i]);
    if (local_max && ncc[i] > peaks.second_ncc) {
      peaks.second_ncc = ncc[i];
      peaks.second = i;
    }
  }
  peaks.at_edge = !ok(best - 1) || !ok(best + 1);
  return peaks;
}

FinePeak fine_peak(const Grid& fa, const Grid& fb, double h, double d0, double half_range,
                   size_t min_count) {
  FinePeak out;
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
  return out;
}

double parabola_vertex(double y0, double y1, double y2) {
  const double den = y0 - 2 * y1 + y2;
  if (!(std::abs(den) > 0)) return 0.0;
  return std::clamp(0.5 * (y0 - y2) / den, -1.0, 1.0);
}

}  // namespace rigcal::time_sync
