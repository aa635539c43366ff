#pragma once
// Internal: where a parameter changes. The screen detects a step of a parameter at its
// cross-validation block boundaries (varying_parameter.hpp: one candidate per boundary, a
// test each); this locates the step on the rows themselves, the least-squares change point
// (Bai 1997): the time t0 whose step column W_j [t >= t0] removes the most weighted residual
// sum of squares from the declared model's rows.
//
// Why by cumulative sums and not one fit per time: with e the declared fit's residual and Q an
// orthonormal basis of its columns, a column c removes (c'e)^2 / (c'c - |Q'c|^2) from the sum
// of squares. For a step column every one of those sums runs over the rows after t0, so one
// pass over the rows from the last to the first gives every t0: O(rows x columns) for the
// whole search, against a refold per candidate time.
//
// Resolution: one decimated row. Where the rows have a gap (a stop whose rows the model masks,
// an invalid stretch), every t0 in it is the same column: the step lies between the last row
// before and the first row after, and both are reported. Trimming: each side keeps at least
// `trim` of the rows where the parameter's column is not zero (a change point needs data on
// both sides; the screen's own steps keep one block on each side).
//
// Its uncertainty: where the column is small (a scale of a signal crossing zero) many times fit
// almost alike. The 95 % confidence set is every t0 whose likelihood ratio against the best,
// (SS(t0) - SS(t^)) / s^2, stays within 7.35 (Hansen 2000, "Sample splitting and threshold
// estimation": c = -2 log(1 - sqrt(0.95)), the change point's own asymptotic distribution, not
// chi-square); s^2 is the residual variance per row times how much the rows' correlation
// inflates the variance of the step's own coefficient (its HAC variance over its textbook one,
// at the time found: the robust likelihood ratio of a quasi-likelihood), because the rows are
// low-passed and decimated and their errors correlated; never less than 1, so that no row counts
// for more than one (a HAC variance below the textbook one is a finite-sample estimate, and took
// the true time out of the set on a synthetic step). Reported as its hull.
#include <optional>
#include <string>
#include <vector>

#include "dynid/ingest/recorded_run.hpp"
#include "folded_rows.hpp"

namespace dynid::residual::detail {

struct LocatedStep {
  double time_s = 0.0;          ///< the first row at or after the change: the step's t0
  double previous_row_s = 0.0;  ///< the last row before it (the change lies in between)
  double ss_removed = 0.0;      ///< weighted in-sample sum of squares the step removes
  double earliest_s = 0.0;      ///< the 95 % set's hull (set_interval): the change lies after
  double latest_s = 0.0;        ///< this row, and at or before this one
  struct Time {
    double time_s, previous_row_s, removed;
  };
  std::vector<Time> tried;      ///< every time the search tried
  double rss_min = 0.0;         ///< weighted in-sample sum of squares with the step
  Eigen::Index rows = 0;
};

/// The change point of column `column` on `rows` (collected; every column is the declared
/// model's), each group's rows weighted by `weights`; its interval is the located time alone until
/// set_interval. Nothing when no time keeps `trim` of the
/// column's rows on each side or no step column is independent of the declared ones.
std::optional<LocatedStep> locate_step(const FoldedRows& rows, Eigen::Index column, const std::vector<double>& weights,
                                       double trim = 0.05);

/// The step's 95 % set from its search, with `inflation` the step coefficient's HAC variance
/// over its textbook variance at the time found (see above; at least 1).
void set_interval(LocatedStep& step, double inflation);

/// What happened on the run between `from_s` and `to_s` (widened by `margin_s` each way) that
/// an engineer would tie a change to: stretches where the car stood still (vx below 0.5 m/s),
/// gear changes (channel "gear"), stretches without valid data. Empty when nothing did.
std::string events_near(const std::vector<ingest::PreprocessedSegment>& run, double sample_rate_hz, double from_s,
                        double to_s, double margin_s);

}  // namespace dynid::residual::detail
