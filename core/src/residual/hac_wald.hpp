#pragma once
// Internal: the Wald test of a block of columns in the weighted least-squares fit of collected
// rows, with a heteroskedasticity and autocorrelation consistent (HAC) covariance: Newey and
// West (1987), Bartlett kernel, bandwidth by Andrews' (1991) AR(1) plug-in rule, on scores
// prewhitened by a VAR(1) (Andrews and Monahan 1992).
//
// Why not the textbook F test: the rows are low-passed, differentiated and decimated signals, so
// neighbouring residuals are correlated; the F test counts every row as independent evidence
// and calls nearly any column significant (measured: every dictionary term of a clean run). The
// HAC covariance counts what the correlated rows really carry, so the statistic is chi-square
// with q degrees of freedom under "the columns add nothing" and a stated error rate holds.
//
// Scores of rows of different equation groups at one time (one grid index) are summed before
// the lags are taken: the groups of one model see the same disturbances at the same instant.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "folded_rows.hpp"

namespace dynid::residual::detail {

struct WaldTest {
  bool testable = false;  ///< false: no tested column is identifiable on these rows
  double statistic = 0.0; ///< b' V^-1 b, chi-square(q) under the null
  int degrees_of_freedom = 0;  ///< the tested columns that are identifiable
  double p_value = 1.0;
  int bandwidth = 0;      ///< Newey-West lags, in decimated rows
  double first_std = 0.0; ///< HAC standard deviation of the first tested coefficient
  /// HAC standard deviation of every tested column, in column order (NaN: not identifiable).
  Eigen::VectorXd stds;
};

/// Scores summed per grid index (rows of several groups at one time add up), in grid order.
struct TimeScores {
  std::vector<Eigen::Index> grid;
  std::vector<Eigen::VectorXd> score;
};

/// Row i's score is scores.row(i), at run grid index grid[i] (any order).
TimeScores sum_by_grid(const std::vector<Eigen::Index>& grid, const Eigen::MatrixXd& scores);

/// The long-run covariance sum_{l} E[s_t s_{t-l}'] of the scores, as the Wald test takes it:
/// VAR(1) prewhitening, Newey-West with Andrews' bandwidth (returned in `bandwidth`, decimated
/// rows), recoloured. `odmf`: grid steps between two rows.
Eigen::MatrixXd long_run_covariance(TimeScores scores, int odmf, int& bandwidth);

/// Tests columns [first, end) of `rows` (collected: fold_rows with collect) at the weighted
/// solution `x` (NaN entries: not identifiable, left out of the covariance), each group's rows
/// weighted by `weights` (the estimator's 1/sigma_j). `odmf`: grid steps between two rows.
WaldTest hac_wald_test(const FoldedRows& rows, const Eigen::VectorXd& x, const std::vector<double>& weights,
                       Eigen::Index first, Eigen::Index end, int odmf);

}  // namespace dynid::residual::detail
