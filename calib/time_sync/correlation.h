#pragma once
// Internal to time_sync: normalized cross-correlation of the two streams' |w| (by FFT over every
// lag, directly for one lag, continuously on the interpolated signals), its peaks, and the 1-D
// minimization that refines them (correlation.cpp).
#include <cmath>
#include <vector>

#include "rigcal/time_sync/signals.h"
#include "rigcal/time_sync/time_sync.h"

namespace rigcal::time_sync {

// Masked normalized cross-correlation (Padfield 2010) for every lag k = n_a - n_b (offset k*h)
// by FFT: the Pearson correlation of the overlapping valid samples. Entries with fewer than
// min_count overlapping samples are NaN. Returns values for k in [k_first, k_first + size).
std::vector<double> masked_ncc_fft(const Grid& a, const Grid& b, size_t min_count, long& k_first);

// The same correlation for one lag, directly; also returns the overlap count.
double masked_ncc_direct(const Grid& a, const Grid& b, long k, size_t& count);

// Pearson correlation of |w_ref| and |w_other| at offset d, over the pairing's points (NaN with
// fewer than 3 pairs or no variance).
double norm_ncc(const Pairing& p, double d);

// The peaks of a correlation whose entry i is the lag k_first + i, among the entries with lag in
// [k_lo, k_hi] that are not NaN (the valid ones).
struct Peaks {
  long best = -1;           // the highest valid entry; -1: none
  std::vector<long> valid;  // the valid entries, in order
  bool at_edge = false;     // a neighbour of best is not valid: the optimum may lie outside
  // The highest local maximum outside best's main lobe (outwards from best while the correlation
  // keeps falling); -1 and second_ncc = -1: none.
  long second = -1;
  double second_ncc = -1;
};
Peaks find_peaks(const std::vector<double>& ncc, long k_first, long k_lo, long k_hi);

// The direct correlation on the lattice of step h over lags d0 +- half_range (lags leaving fewer
// than min_count samples of overlap are NaN), its highest lag and the parabola's vertex there.
struct FinePeak {
  double integer_d = NAN, parabolic_d = NAN, peak = NAN;  // NaN: no lag had enough overlap
  bool at_edge = false;                                   // the highest lag ends the range
  std::vector<CorrelationPoint> curve;                    // every lag of the range
};
FinePeak fine_peak(const Grid& a, const Grid& b, double h, double d0, double half_range,
                   size_t min_count);

// The vertex of the parabola through (-1, y0), (0, y1), (1, y2), in [-1, 1].
double parabola_vertex(double y0, double y1, double y2);

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

}  // namespace rigcal::time_sync
