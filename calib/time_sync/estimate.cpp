#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <Eigen/SVD>
#include <algorithm>
#include <climits>
#include <cmath>
#include <optional>

#include "rigcal/core/error.h"
#include "rigcal/core/stats.h"
#include "rigcal/time_sync/correlation.h"
#include "rigcal/time_sync/signals.h"
#include "rigcal/time_sync/time_sync.h"

namespace rigcal::time_sync {
namespace {

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

struct Refined {
  FinePeak peak;
  double norm_d = NAN, d = NAN;
  AxisFit fit;
};

// From a first guess d0: the fine-grid correlation over d0 +- half_range, its integer peak, the
// parabola, the continuous norm refinement and (optionally) the three-axis refinement.
Refined refine(const Grid& fa, const Grid& fb, double h, const Pairing& p, double d0,
               double half_range, bool three_axis, size_t min_count, bool norm_stage = true) {
  Refined out;
  out.peak = fine_peak(fa, fb, h, d0, half_range, min_count);
  if (std::isnan(out.peak.peak)) return out;
  const double parabolic_d = out.peak.parabolic_d;
  // The continuous norm stage; skipped (the parabola stands for it) when only the three-axis
  // optimum is wanted, as in the drift windows.
  out.norm_d = norm_stage || !three_axis ? brent_minimize([&](double d) { return -norm_ncc(p, d); },
                                                          parabolic_d - h, parabolic_d + h, 1e-6)
                                         : parabolic_d;
  out.d = out.norm_d;
  if (three_axis) {
    out.d = brent_minimize([&](double d) { return fit_axes(p, d).sse; }, out.norm_d - h,
                           out.norm_d + h, 1e-6);
  }
  out.fit = fit_axes(p, out.d);
  return out;
}

// Marks res as failed: the verdict, the reason, and no offset. Returns false.
bool fail(TimeSyncResult& res, std::string verdict, std::string reason) {
  res.verdict = std::move(verdict);
  res.reason = std::move(reason);
  res.offset_s = res.sigma_s = NAN;
  return false;
}

// Both streams in seconds since the reference's first stamp, their bandwidths matched: an
// instantaneous stream is box-filtered to the other's averaging.
struct Streams {
  Series ref, oth;
  double epoch_other_s = 0.0;  // the other stream's first stamp (res.epoch)
};

Streams make_streams(const AngularRates& reference_in, const AngularRates& other_in,
                     TimeSyncResult& res) {
  if (reference_in.stamps.empty() || other_in.stamps.empty())
    throw Error("both streams need samples");
  const Time epoch_ref = reference_in.stamps.front();
  res.epoch = other_in.stamps.front();
  Streams s{make_series(reference_in, epoch_ref, "reference"),
            make_series(other_in, epoch_ref, "other"), (res.epoch - epoch_ref).seconds()};
  Series &ref = s.ref, &oth = s.oth;
  res.reference_rate_hz = ref.rate_hz();
  res.other_rate_hz = oth.rate_hz();
  if (ref.averaging_s < oth.averaging_s) ref = box_filter(ref, oth.averaging_s);
  if (oth.averaging_s < ref.averaging_s) oth = box_filter(oth, ref.averaging_s);
  return s;
}

bool check_excitation(const Streams& s, const TimeSyncOptions& opt, TimeSyncResult& res) {
  res.excitation_reference_rad_s = stddev_of_norm(s.ref);
  res.excitation_other_rad_s = stddev_of_norm(s.oth);
  if (std::min(res.excitation_reference_rad_s, res.excitation_other_rad_s) >=
      opt.min_excitation_rad_s)
    return true;
  return fail(res, "not enough excitation",
              fmt::format("the angular rate's norm varies by {:.4f} rad/s (reference) and {:.4f} "
                          "rad/s (other), 1-sigma; at least {} is needed: rotate the sensors "
                          "back and forth about changing axes, not at a constant rate",
                          res.excitation_reference_rad_s, res.excitation_other_rad_s,
                          opt.min_excitation_rad_s));
}

// Coarse pass: FFT over every lag, both streams box-filtered to the coarse step; the peak, the
// second peak and the checks on them.
bool coarse_pass(const Streams& s, const TimeSyncOptions& opt, double min_overlap_s,
                 TimeSyncResult& res) {
  const Series &ref = s.ref, &oth = s.oth;
  res.coarse_hz = std::min(opt.coarse_hz, std::max(res.reference_rate_hz, res.other_rate_hz));
  const double hc = 1.0 / res.coarse_hz;
  Grid ga, gb;
  tbb::parallel_invoke(
      [&] { ga = norm_grid(ref.averaging_s < hc ? box_filter(ref, hc) : ref, hc); },
      [&] { gb = norm_grid(oth.averaging_s < hc ? box_filter(oth, hc) : oth, hc); });
  if (ga.v.size() < 3 || gb.v.size() < 3)
    return fail(res, "no overlap", "the streams are too short");
  long k_first = 0;
  const std::vector<double> coarse =
      masked_ncc_fft(ga, gb, static_cast<size_t>(min_overlap_s / hc), k_first);
  const long k_lo =
      std::isfinite(opt.max_offset_s) ? std::lround(-opt.max_offset_s / hc) : LONG_MIN;
  const long k_hi = std::isfinite(opt.max_offset_s) ? std::lround(opt.max_offset_s / hc) : LONG_MAX;
  const Peaks peaks = find_peaks(coarse, k_first, k_lo, k_hi);
  const long best = peaks.best;
  if (best < 0) {
    return fail(
        res, "no overlap",
        fmt::format("no offset within +-{} s leaves {:.1f} s of overlap (half the shorter "
                    "stream); the reference spans [{:.3f}, {:.3f}] s and the other [{:.3f}, "
                    "{:.3f}] s of stamps: widen the search (--max-offset)",
                    opt.max_offset_s, min_overlap_s, ref.t.front(), ref.t.back(), oth.t.front(),
                    oth.t.back()));
  }
  for (long i : peaks.valid) res.coarse_curve.push_back({(k_first + i) * hc, coarse[i]});
  res.coarse_offset_s = (k_first + best) * hc;
  res.peak_ncc = coarse[best];
  res.second_peak_ncc = peaks.second_ncc;
  if (peaks.second >= 0) res.second_peak_offset_s = (k_first + peaks.second) * hc;
  res.peak_ratio = res.second_peak_ncc > 0 ? res.second_peak_ncc / res.peak_ncc : 0.0;
  res.overlap_s = std::min(ref.t.back(), oth.t.back() + res.coarse_offset_s) -
                  std::max(ref.t.front(), oth.t.front() + res.coarse_offset_s);
  if (peaks.at_edge) {
    return fail(res, "peak at the edge",
                fmt::format("the best correlation ({:.3f}) is at the edge of the search range, "
                            "offset {:.3f} s: the true offset may lie outside; widen --max-offset",
                            res.peak_ncc, res.coarse_offset_s));
  }
  if (res.peak_ncc < opt.min_peak_ncc) {
    return fail(res, "poor correlation",
                fmt::format("the best normalized correlation is {:.3f} (at {:.3f} s), below {}: "
                            "the streams do not seem to see the same motion",
                            res.peak_ncc, res.coarse_offset_s, opt.min_peak_ncc));
  }
  if (res.peak_ratio > opt.max_peak_ratio) {
    return fail(
        res, "ambiguous",
        fmt::format("a second correlation peak at {:.3f} s reaches {:.3f} against {:.3f} at "
                    "{:.3f} s (ratio {:.2f}): the motion is too periodic to tell the offset; "
                    "record less regular motion or narrow --max-offset",
                    res.second_peak_offset_s, res.second_peak_ncc, res.peak_ncc,
                    res.coarse_offset_s, res.peak_ratio));
  }
  return true;
}

// Fine pass and continuous refinement around the coarse offset: the offset over the whole
// overlap, its stages, the three-axis fit and the formal sigma. Returns the offset, NaN on
// failure.
double fine_pass(const Streams& s, const TimeSyncOptions& opt, double min_overlap_s,
                 TimeSyncResult& res) {
  const double hc = 1.0 / res.coarse_hz;
  res.grid_hz = std::min(opt.fine_hz_max, std::max(res.reference_rate_hz, res.other_rate_hz));
  const double hf = 1.0 / res.grid_hz;
  Grid fa, fb;
  tbb::parallel_invoke([&] { fa = norm_grid(s.ref, hf); }, [&] { fb = norm_grid(s.oth, hf); });
  Pairing p = make_pairing(s.ref, s.oth);
  for (size_t i = 0; i < p.slow->t.size(); ++i) p.points.push_back(i);
  const size_t min_fine = static_cast<size_t>(min_overlap_s / hf);
  const Refined r = refine(fa, fb, hf, p, res.coarse_offset_s, 3 * hc, opt.three_axis, min_fine);
  if (std::isnan(r.d)) {
    fail(res, "no overlap", "the fine correlation found no overlap");
    return NAN;
  }
  res.integer_offset_s = r.peak.integer_d;
  res.parabolic_offset_s = r.peak.parabolic_d;
  res.norm_offset_s = r.norm_d;
  res.fine_curve = r.peak.curve;
  res.three_axis = opt.three_axis;
  res.R_reference_other = r.fit.R;
  res.bias_difference = r.fit.b;
  res.samples_used = r.fit.n;
  res.residual_rms_rad_s = std::sqrt(r.fit.sse / (3.0 * r.fit.n));
  res.sigma_formal_s = formal_sigma(p, r.d, opt.three_axis, r.fit, 0.1 * hf);
  res.mean_offset_s = r.d;
  return r.d;
}

// One drift window [ws, ws + W] of the other clock: its offset by the fine correlation around
// the whole overlap's offset d (grid steps hf fine, hc coarse).
WindowOffset window_offset(const Streams& s, double ws, double W, double d, double hf, double hc,
                           const TimeSyncOptions& opt) {
  WindowOffset wo;
  wo.t_other_s = ws + 0.5 * W - s.epoch_other_s;
  // The window's samples, in both streams (the other clock).
  Series rw = slice(s.ref, ws + d - 0.2, ws + d + W + 0.2), ow = slice(s.oth, ws, ws + W);
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
  const Refined wr = refine(wa, wb, hf, wp, d, std::min(0.1, 3 * hc), opt.three_axis,
                            static_cast<size_t>(0.8 * W / hf), /*norm_stage=*/false);
  wo.ncc = wr.peak.peak;
  if (std::isnan(wr.d) || wr.peak.at_edge || !(wr.peak.peak >= opt.min_peak_ncc)) {
    wo.note = std::isnan(wr.d) ? "no overlap"
                               : (wr.peak.at_edge ? "peak at the edge" : "poor correlation");
    return wo;
  }
  wo.offset_s = wr.d;
  wo.sigma_s = formal_sigma(wp, wr.d, opt.three_axis, wr.fit, 0.1 * hf);
  wo.used = true;
  return wo;
}

// Drift: offsets in consecutive windows along the other stream, over the overlap at offset d.
void drift_windows(const Streams& s, double d, const TimeSyncOptions& opt, TimeSyncResult& res) {
  const Series &ref = s.ref, &oth = s.oth;
  const double hc = 1.0 / res.coarse_hz, hf = 1.0 / res.grid_hz;
  const double t0 = std::max(ref.t.front() - d, oth.t.front());
  const double t1 = std::min(ref.t.back() - d, oth.t.back());
  res.window_s = opt.window_s > 0 ? opt.window_s : std::max(20.0, (t1 - t0) / 10.0);
  const double W = res.window_s;
  std::vector<double> starts;
  for (double ws = t0; ws + W <= t1 + 1e-9; ws += W) starts.push_back(ws);
  // The windows are independent and run in parallel.
  res.windows.resize(starts.size());
  tbb::parallel_for(size_t(0), starts.size(), [&](size_t k) {
    res.windows[k] = window_offset(s, starts[k], W, d, hf, hc, opt);
  });
}

// The line offset = o0 + drift * t through the used windows (other clock, seconds since the
// epoch) and its sigmas.
struct Line {
  double o0 = 0.0, s = 0.0, sd_o0 = 0.0, sd_s = 0.0, rms = 0.0;
};

Line fit_line(const std::vector<WindowOffset>& windows) {
  double n = 0, St = 0, So = 0, Stt = 0, Sto = 0;
  for (const WindowOffset& w : windows) {
    if (!w.used) continue;
    n += 1, St += w.t_other_s, So += w.offset_s, Stt += w.t_other_s * w.t_other_s,
        Sto += w.t_other_s * w.offset_s;
  }
  const double det = n * Stt - St * St;
  const double s = (n * Sto - St * So) / det;
  const double o0 = (So - s * St) / n;
  double sse = 0;
  for (const WindowOffset& w : windows) {
    if (w.used) sse += std::pow(w.offset_s - o0 - s * w.t_other_s, 2);
  }
  const double sigma2 = n > 2 ? sse / (n - 2) : NAN;
  const double rms = std::sqrt(sse / n);
  // From the scatter about the line, and from the windows' own sigmas propagated (few windows
  // can scatter less than their noise by chance): the larger.
  double W = 0, Wt = 0, Wtt = 0;
  for (const WindowOffset& w : windows) {
    if (!w.used || !(w.sigma_s > 0)) continue;
    const double k = 1.0 / (w.sigma_s * w.sigma_s);
    W += k, Wt += k * w.t_other_s, Wtt += k * w.t_other_s * w.t_other_s;
  }
  const double wdet = W * Wtt - Wt * Wt;
  const double formal_s2 = wdet > 0 ? W / wdet : 0.0, formal_o02 = wdet > 0 ? Wtt / wdet : 0.0;
  const double sd_s = std::sqrt(std::max(sigma2 * n / det, formal_s2));
  const double sd_o0 = std::sqrt(std::max(sigma2 * Stt / det, formal_o02));
  return {o0, s, sd_o0, sd_s, rms};
}

size_t used_windows(const std::vector<WindowOffset>& windows) {
  size_t used = 0;
  for (const WindowOffset& w : windows) used += w.used;
  return used;
}

// One pass of outlier rejection about the line (5 x 1.4826 MAD).
void reject_outliers(std::vector<WindowOffset>& windows, const Line& line) {
  const double o0 = line.o0, s = line.s;
  std::vector<double> dev;
  for (const WindowOffset& w : windows) {
    if (w.used) dev.push_back(std::abs(w.offset_s - o0 - s * w.t_other_s));
  }
  const double mad = 1.4826 * median(dev);
  for (WindowOffset& w : windows) {
    // A window is an outlier beyond 5 MAD of the line, but never within 4 of its own sigma
    // (windows agreeing to a microsecond would otherwise reject their own noise).
    const double limit = std::max({5 * mad, 4 * w.sigma_s, 1e-6});
    if (w.used && std::abs(w.offset_s - o0 - s * w.t_other_s) > limit) {
      w.used = false;
      w.note = "outlier in the drift fit";
    }
  }
}

// The drift line through the windows' offsets (after one pass of outlier rejection) and the
// result's offset and sigma: the line's at the epoch when the drift is significant, else the
// whole overlap's offset d.
void fit_drift(TimeSyncResult& res, double d) {
  if (used_windows(res.windows) >= 4) reject_outliers(res.windows, fit_line(res.windows));
  const size_t used = used_windows(res.windows);
  if (used >= 4) {
    const Line line = fit_line(res.windows);
    const double o0 = line.o0, s = line.s, sd_o0 = line.sd_o0, sd_s = line.sd_s, rms = line.rms;
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
      return;
    }
  }
  res.offset_s = d;
  res.sigma_s = std::max(res.sigma_formal_s, res.sigma_windows_s);
}

// One pass: the offset over the whole overlap, then the windows and the drift line.
TimeSyncResult estimate_pass(const AngularRates& reference_in, const AngularRates& other_in,
                             const TimeSyncOptions& opt) {
  TimeSyncResult res;
  const Streams s = make_streams(reference_in, other_in, res);
  if (!check_excitation(s, opt, res)) return res;
  const double span = std::min(s.ref.t.back() - s.ref.t.front(), s.oth.t.back() - s.oth.t.front());
  const double min_overlap_s = opt.min_overlap * span;
  if (!coarse_pass(s, opt, min_overlap_s, res)) return res;
  const double d = fine_pass(s, opt, min_overlap_s, res);
  if (std::isnan(d)) return res;
  drift_windows(s, d, opt, res);
  fit_drift(res, d);
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
