#pragma once
// Clock offset and drift between two sensors that see the same rotation (two IMUs, or an IMU and
// a pose trajectory), from their angular velocities (doc/time-offset.md).
//
// The offset is defined as in ../shared/DESIGN.md for time_offset: what is added to the other
// stream's stamps to put them on the reference clock,
//     t_reference = t_other + offset_s + drift_ppm * 1e-6 * (t_other - epoch).
//
// Method: the norm of the angular velocity does not depend on the unknown rotation between the
// sensors. Both norms are resampled on common grids (the faster stream box-filtered to the slower
// one's averaging interval when that is a pose-derived rate), a masked normalized
// cross-correlation computed by FFT finds the peak over the search range at a coarse rate, a
// direct correlation at the fine rate and a parabola refine it, and a 1-D minimization (Brent)
// on the interpolated signals gives the continuous offset. Then, optionally, the relative
// rotation and the gyro bias difference are estimated (Kabsch) and the offset is refined on all
// three axes. Offsets in sliding windows give the drift by a linear fit.
#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

#include "rigcal/core/time.h"
#include "rigcal/core/trajectory.h"

namespace rigcal::time_sync {

// Angular-velocity samples of one sensor, on its own clock.
struct AngularRates {
  std::vector<Time> stamps;            // strictly increasing
  std::vector<Eigen::Vector3d> rates;  // rad/s, in the sensor frame
  // 0: instantaneous gyro samples. > 0: each sample is the mean rate over an interval about
  // this long (seconds), centred on its stamp (rates derived from consecutive poses).
  double averaging_s = 0.0;
};

// The body angular velocity between consecutive poses, log(R_k^T R_k+1) / dt, stamped at the
// midpoint; averaging_s is the median pose interval. Pose pairs with dt <= 0 are skipped.
AngularRates angular_rates_from_trajectory(const Trajectory& T_world_body);

// Samples with equal stamps (logs printed with too few digits) become one sample, their mean.
// Returns how many samples were merged away. Throws rigcal::Error when stamps go backwards.
size_t merge_equal_stamps(AngularRates& rates);

// Gyroscope samples beyond this (rad/s) are refused by the readers.
inline constexpr double kMaxGyroRate = 100.0;
// Isolated spikes: a sample further than kSpikeFactor times the series' typical step from the
// mean of its two neighbours, while the neighbours agree with each other (within a quarter of
// that distance), is replaced by that mean; such samples come from rows swapped or damaged in a
// log, and a correlation would otherwise lock onto them. Returns how many were replaced.
inline constexpr double kSpikeFactor = 20.0;
size_t repair_spikes(AngularRates& rates);

struct TimeSyncOptions {
  // Offsets searched: |offset| <= max_offset_s. Infinity: every lag with enough overlap.
  double max_offset_s = 1.0;
  // The overlap a lag must leave, as a fraction of the shorter stream's span.
  double min_overlap = 0.5;
  double coarse_hz = 20.0;     // the FFT pass
  double fine_hz_max = 200.0;  // the fine grid: the faster stream's rate, at most this
  bool three_axis = true;      // estimate the relative rotation and refine on all three axes
  // Drift: offsets in consecutive windows this long (0: the overlap / 10, at least 20 s).
  double window_s = 0.0;
  // Not enough excitation: the standard deviation of |w| below this in either stream (rad/s).
  double min_excitation_rad_s = 0.05;
  // Ambiguous: a second correlation peak within the search range this high relative to the main.
  double max_peak_ratio = 0.9;
  double min_peak_ncc = 0.5;  // below: the streams do not see the same motion
};

struct WindowOffset {
  double t_other_s = 0.0;  // the window's centre, seconds since the epoch, other clock
  double offset_s = NAN, sigma_s = NAN;  // NaN where the window gave no offset
  double ncc = 0.0;
  bool used = false;  // in the drift fit
  std::string note;   // why not used
};

struct CorrelationPoint {
  double offset_s = 0.0, ncc = 0.0;
};

struct TimeSyncResult {
  // "ok", or what makes the data unusable: "not enough excitation", "ambiguous", "no overlap",
  // "poor correlation". When not "ok", offset_s is not an answer (NaN) and `reason` says why.
  std::string verdict = "ok";
  std::string reason;
  Time epoch;             // other clock: the first stamp of the other stream
  double offset_s = 0.0;  // at the epoch when drift is significant, else the mean offset
  double sigma_s = 0.0;   // 1-sigma
  double sigma_formal_s = 0.0, sigma_windows_s = 0.0;  // the two estimates sigma_s is the larger of
  double coarse_offset_s = 0.0, integer_offset_s = 0.0, parabolic_offset_s = 0.0,
         norm_offset_s = 0.0;  // the successive stages
  double peak_ncc = 0.0, second_peak_ncc = 0.0, second_peak_offset_s = 0.0, peak_ratio = 0.0;
  double excitation_reference_rad_s = 0.0, excitation_other_rad_s = 0.0;  // std of |w|
  double grid_hz = 0.0, coarse_hz = 0.0, overlap_s = 0.0;
  double reference_rate_hz = 0.0, other_rate_hz = 0.0;  // median
  bool three_axis = false;
  Eigen::Matrix3d R_reference_other = Eigen::Matrix3d::Identity();  // w_ref = R w_other + b
  Eigen::Vector3d bias_difference = Eigen::Vector3d::Zero();
  double residual_rms_rad_s = 0.0;  // three-axis (or norm) residual at the optimum
  size_t samples_used = 0;
  // Drift.
  std::vector<WindowOffset> windows;
  double window_s = 0.0;
  bool drift_estimated = false, drift_significant = false;
  double drift_ppm = 0.0, drift_sigma_ppm = 0.0, window_residual_rms_s = 0.0;
  // Significant: |drift| above this many drift sigmas (Student's t at 99.73 %, windows - 2 dof).
  double drift_significance_sigma = 0.0;
  double mean_offset_s = 0.0;  // the offset without a drift model
  // For plots: the correlation around the peak (fine grid) and over the search range (coarse).
  std::vector<CorrelationPoint> fine_curve, coarse_curve;
};

// Throws rigcal::Error on unusable input (fewer than 10 samples, stamps not increasing).
TimeSyncResult estimate_time_offset(const AngularRates& reference, const AngularRates& other,
                                    const TimeSyncOptions& options = {});

}  // namespace rigcal::time_sync
