#pragma once
// The clock offset between an auxiliary source and the bus, estimated from a quantity both carry
// (an acceleration, a speed, or a speed against an acceleration with reference_derivative).
//
// Method: both series are interpolated onto a common grid (step `step`, 10 ms), smoothed by a
// moving mean of `smooth` (0.1 s), high-passed by subtracting a moving mean of `high_pass` (3 s:
// a slow difference such as a gravity-compensated against a raw accelerometer does not count),
// the reference optionally differentiated. The offset is the lag L in [-max_offset, max_offset]
// that maximises the Pearson correlation of reference(t) and source(t - L), refined by a
// parabola through the peak: bus time = source time + L. The run is cut into `segments` (8)
// equal pieces, L estimated on each; pieces whose peak correlation is below min_correlation
// (0.3: no excitation there) are left out. The offset is the median of the pieces' L (the
// whole overlap's peak, whole_run, is reported beside it: its strongest part dominates it). std is
// 1.4826 x the median absolute deviation of the pieces' L over sqrt(pieces), at least the grid's
// resolution step / sqrt(12 pieces). Drift: a straight line through the pieces' L against their
// time (least squares); start and end are the line at the first and the last piece, with their
// std; drifting() is true when its slope exceeds the 1 % two-sided t quantile (pieces - 2
// degrees of freedom) times its standard error and the line moves by more than two grid steps
// over the run: a fixed offset cannot align such a clock.
//
// Contract: estimate_clock_offset() throws InputError (naming `what`) when the series overlap
// for less than 10 s plus twice max_offset, when fewer than 2 pieces of each half correlate, or
// when a series is not sorted by time or holds a non-finite number.
#include <string>
#include <vector>

namespace dynid::car {

struct TimeSeries {
  std::vector<double> t;  ///< seconds, increasing
  std::vector<double> v;
};

struct ClockOffsetOptions {
  double max_offset = 2.0;
  bool reference_derivative = false;
  double step = 0.01;
  double smooth = 0.1;
  double high_pass = 3.0;
  int segments = 8;
  double min_correlation = 0.3;
};

struct ClockEstimate {
  double offset = 0.0;       ///< bus time = source time + offset (seconds): the pieces' median
  double whole_run = 0.0;    ///< the peak of the whole overlap (dominated by its strongest part)
  double std = 0.0;
  double correlation = 0.0;  ///< at the peak, whole overlap
  double start = 0.0, start_std = 0.0;  ///< the drift line at the first piece
  double end = 0.0, end_std = 0.0;      ///< at the last piece
  double drift = 0.0, drift_std = 0.0;  ///< slope of the pieces' offsets (s per s) and its std
  bool drift_found = false;
  int pieces = 0;            ///< pieces that correlated
  bool drifting() const;
};

ClockEstimate estimate_clock_offset(const TimeSeries& reference, const TimeSeries& source,
                                    const ClockOffsetOptions& options, const std::string& what);

}  // namespace dynid::car
