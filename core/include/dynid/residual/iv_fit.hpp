#pragma once
// IvFit: one model (with its enabled effects) identified on a whole recorded run by instrumental
// variables (Gautier, Janot and Vandanjon's IDIM-IV), with the Durbin-Wu-Hausman test that says
// whether the weighted least-squares estimate on the same rows is biased.
//
// Why: least squares is unbiased only when the regressors carry no noise. Here many do: the
// differentiated speed d_vx of the longitudinal models, the yaw rate, its derivative and the
// slip angles of the lateral one are built from measured channels, and the noise in those
// columns attenuates their parameters (errors in variables; docs/ACCURACY.md measures it growing
// with the noise variance). An instrument is anything correlated with the regressors' signal and
// not with the noise; IV then solves Z' (y - W theta) = 0 instead of W' (y - W theta) = 0.
//
// Instruments, generic for every model: the model's own rows built L, L + 1 and L + 2 decimated
// rows earlier and later (six blocks of the row's columns; a block reads 0 where that partner is
// not a row of the same group in the same valid segment, and a row with no partner at all is left
// out). The channels' noise, low-passed by the run's zero-phase Butterworth, is correlated over
// the filter's impulse response only, while the manoeuvre's signal persists over seconds; beyond
// that span the lagged rows carry the signal and none of the row's noise. Nothing is
// model-specific: the rows are fold_rows' (as fit_model builds them, effects included), and a
// column without noise (an offset, a known input) instruments itself.
// Why lags and leads as separate instruments, several of them (two-stage least squares through
// the first stage's projection P_Z W): one lag, or the mean of a lag and a lead, carries a
// sinusoid of frequency f with the factor cos(2 pi f L), and a multisine manoeuvre (the lateral
// run's steer) can cancel itself out in it (measured: the mean of lag and lead left the lateral
// model with a smallest canonical correlation of 0.02). Lags and leads span the sine and cosine
// parts of each frequency, and three consecutive ones per side let the first stage interpolate
// each column across the noise's gap (value, slope and curvature on each side); no more, because
// 2SLS's small-sample bias towards LS grows with the number of instruments.
//
// The lag L (instrument_lag): the smallest number of decimated rows from which on the
// autocorrelation of the preprocessed noise, |rho(l odmf)|, stays within `noise_correlation_bound`
// for both the filtered channels and their central differences (the two kinds of noisy column),
// white sensor noise at the grid rate put through the run's own filter and derivative code (the
// contract of Preprocessing::channel_noise). Why this rule: the IV estimate's bias from noise left
// in the instruments is rho(L) / r(L) times least squares' (r: the instruments' correlation with
// the signal), so rho <= 0.01 keeps IV's bias within about 1 % of the one it removes. A sensor
// whose noise is not white at the grid rate (one that filters internally) needs its own lag:
// IvOptions::lag_rows.
//
// Estimate: every row weighted by its group's 1/sigma_j from the weighted LS fit of the same
// configuration (DYCARO's weights, as the estimate table), columns scaled to unit norm for the
// solves. With Z^ = P_Z W, theta_IV = (Z^'W)^-1 Z^'y (= (Z'W)^-1 Z'y when there are as many
// instruments as columns), solved as the least-squares problem Z^ theta = y by a column-pivoting
// QR (Z^'W = Z^'Z^). Only the columns the LS fit identifies (its base parameters) are estimated;
// the others read NaN.
//
// Standard deviations, both given (Z^ in place of Z): `std` is the textbook s^2 (Z'W)^-1 Z'Z
// (W'Z)^-1, s^2 the IV residual's variance (comparable to the estimate table's sigma^2 (W'W)^-1);
// `hac_std` is the sandwich (Z'W)^-1 S (W'Z)^-1 with S the long-run covariance of the scores
// z_k e_k, taken as hac_wald.hpp takes it (VAR(1)-prewhitened Newey-West, Andrews' bandwidth):
// the rows are low-passed and decimated, their errors correlated, and the textbook formula
// counts each row as independent.
//
// Durbin-Wu-Hausman: d = theta_IV - theta_LS (LS weighted alike, on the same rows), H = d' V_d^+ d,
// chi-square with rank(V_d) degrees of freedom under "the regressors' noise does not bias LS".
// V_d is the HAC long-run covariance of the difference's own scores, (Z'W)^-1 z_k e_k -
// (W'W)^-1 w_k e_k at the LS residual e (consistent under the null), not the textbook V_IV -
// V_LS: that difference is a covariance only when LS is efficient, which correlated rows deny
// (it can then be indefinite and H negative); the difference's own covariance is positive
// semi-definite by construction. Rank: singular values of the unit-diagonal V_d above 1e-10 of
// the largest.
//
// Weak instruments: with weak instruments IV is biased towards LS and its std is unreliable. The
// check is the Cragg-Donald statistic F = (n - K) / K * r^2 / (1 - r^2) of the smallest canonical
// correlation r between the K weighted instruments (distinct ones: the rank of Z) and the k
// regressors (the least well instrumented direction of the parameters); IV is refused below
// `min_instrument_f` (10, Staiger and Stock's rule), naming the parameter that direction weighs
// most. The rows' correlation makes n overstate
// the information: a stated limit, the check is a floor, not a guarantee.
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/ingest/recorded_run.hpp"
#include "dynid/ingest/run_announcement.hpp"
#include "dynid/model/model.hpp"
#include "dynid/residual/model_fit.hpp"

namespace dynid::residual {

struct IvOptions {
  FitOptions fit;  ///< the rows' options as fit_model takes them (series unused)
  /// The run's preprocessing (RunAnnouncement::preprocessing): its filter sets the lag.
  ingest::Preprocessing preprocessing;
  int lag_rows = 0;                       ///< > 0: this lag, in decimated rows; 0: instrument_lag
  double noise_correlation_bound = 0.01;  ///< instrument_lag's bound on |rho|
  double min_instrument_f = 10.0;         ///< Cragg-Donald F below which IV is refused
  double level = 0.01;                    ///< DWH level of DurbinWuHausman::rejects
};

struct DurbinWuHausman {
  double statistic = 0.0;  ///< d' V_d^+ d
  int degrees_of_freedom = 0;
  double p_value = 1.0;
  int bandwidth = 0;       ///< Newey-West lags of V_d, decimated rows
  double level = 0.01;     ///< IvOptions::level
  bool rejects = false;    ///< p_value < level: LS is biased on these rows
};

struct IvFit {
  std::string model;
  std::vector<std::string> effects;
  std::vector<model::ParameterInfo> parameters;
  int lag_rows = 0;
  std::uint64_t rows = 0;                ///< rows with an instrument (the rows of both estimates)
  std::uint64_t rows_without_partner = 0;  ///< rows left out: no lagged row in their segment
  /// True when IV was not estimated (weak instruments, too few rows); `reason` says why and the
  /// values are NaN.
  bool refused = false;
  std::string reason;
  double smallest_canonical_correlation = 0.0;
  double instrument_f = 0.0;  ///< Cragg-Donald F
  Eigen::VectorXd value;      ///< theta_IV, NaN where LS identifies nothing
  Eigen::VectorXd std;        ///< textbook
  Eigen::VectorXd hac_std;    ///< HAC sandwich
  Eigen::VectorXd ls_value;   ///< weighted LS on the same rows
  /// RMS of the weighted rows' IV residual y - W theta_IV, and of least squares' on the same rows
  /// (never above IV's), in the rows' weighted units: this configuration's own least-squares
  /// 1/sigma, so least squares' reads about 1 and IV's says how much IV's residual exceeds least
  /// squares' on the same configuration. Not a fit's absolute size: two configurations (a step at
  /// two times) are weighted by two sigmas, and their residual_rms values are not comparable as
  /// fits (docs/results/RESIDUAL.md, a load taken off at a stop). NaN when IV was refused (JSON
  /// null), as the values.
  double residual_rms = std::numeric_limits<double>::quiet_NaN();
  double ls_residual_rms = std::numeric_limits<double>::quiet_NaN();
  /// HAC std of value - ls_value (the square root of V_d's diagonal): per parameter, how far
  /// apart the two may lie by chance under DWH's null; NaN where LS identifies nothing.
  Eigen::VectorXd difference_std;
  DurbinWuHausman dwh;

  /// True when the IV values are the ones to use: IV estimated and DWH rejects least squares.
  bool replaces_least_squares() const { return !refused && dwh.rejects; }
  /// One line an engineer reads: LS biased (use IV), no evidence of bias (LS stands), or why IV
  /// was refused; with the test's figures.
  std::string statement() const;
};

/// The lag rule above, in decimated rows (>= 1), for a run at `sample_rate_hz` preprocessed by
/// `preprocessing` (its order, cut-off and odmf). InputError as signal::butterworth_lowpass.
int instrument_lag(const ingest::Preprocessing& preprocessing, double sample_rate_hz, double bound = 0.01);

/// `model` with `effects` on `run` (preprocessed segments), rows on the decimation grid `odmf`,
/// by instrumental variables. InputError as fit_model, and for options out of range (lag_rows
/// < 0, a bound or level outside (0, 1), min_instrument_f < 0). A refusal is IvFit::refused, not
/// an exception.
IvFit iv_fit(const model::Model& model, const std::vector<std::string>& effects,
             const std::vector<ingest::PreprocessedSegment>& run, double sample_rate_hz, int odmf,
             const IvOptions& options = {});

}  // namespace dynid::residual
