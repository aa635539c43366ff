#pragma once
// SimexFit: one model (with its enabled effects) identified on a whole recorded run by weighted
// least squares corrected for the noise in its regressors by simulation-extrapolation (SIMEX:
// Cook and Stefanski 1994; Carroll, Ruppert, Stefanski and Crainiceanu, "Measurement Error in
// Nonlinear Models", ch. 5).
//
// Why: the regressors are built from measured channels (the differentiated speed, the yaw rate
// and its derivative, the slip angles, the engine speed's derivative), and their noise attenuates
// least squares' parameters (errors in variables; docs/ACCURACY.md measures the bias growing with
// the noise variance). Instrumental variables (iv_fit.hpp) remove it without a noise model, but
// with a larger scatter, and the Durbin-Wu-Hausman test that decides when to use them has little
// power where the bias is below one std of one run (the longitudinal and clutch models): there
// least squares stays, biased by about half to one of its std. SIMEX uses what the product
// already measures, each channel's noise (noise_floor.hpp, measure_channel_noise, or declared
// in the profile), to estimate that bias and take it away, at nearly least squares' scatter.
//
// Method: let theta(lambda) be the weighted LS estimate when every noisy channel c carries
// (1 + lambda) sigma_c^2 of noise. theta(0) is the table's estimate. For each lambda of
// `lambdas`, copies of the raw run get white noise of variance lambda sigma_c^2 on every
// contributing channel at once (the channels' noises are independent, and the bias of a column
// mixes all that reach it), are preprocessed as the server does (ingest::preprocess_channel_again,
// one channel after the other), and the model's rows are built on the run's own rows (the same
// kept rows, fold_rows' `only`) and solved with the run's own LS weights 1/sigma_j (held, so that
// every lambda is the same linear estimator and only the columns' noise differs between them).
// A quadratic in lambda is fitted by least squares to (0, theta(0)) and the theta(lambda_i), and
// evaluated at lambda = -1 (no noise). The fit is linear in the points: value = sum_i c_i
// theta(lambda_i), sum_i c_i = 1.
// Draws, `draws` of them: each is one standard normal realization z per channel, used for every
// lambda (common random numbers: the lambdas' estimates then differ by the noise's scale alone,
// so the extrapolation, whose weights c_i reach a few in magnitude, does not amplify independent
// draws' scatter) and with both signs, +sqrt(lambda) sigma z and -sqrt(lambda) sigma z
// (antithetic: theta's departure from theta(0) is to first order linear in the added noise, zero
// mean and the largest part of one draw; the pair's mean cancels it exactly and keeps the
// second-order part, the bias). Each draw gives one extrapolated value; their mean is the
// estimate, their scatter its Monte Carlo std. 2 x lambdas x draws refits in all.
// A channel contributes when noise on it alone (one antithetic pair at lambda = 1) changes the
// solution; that pair's mean minus theta(0) is also the channel's share of the bias, used for the
// `level` std below. Without any contributing channel the value is least squares' and nothing is
// corrected.
// The noise is white at the grid rate with the measured sigma, the level that
// measure_channel_noise reports for the band the model sees (its contract), so lambda scales the
// in-band noise variance as the method requires. Deterministic: one generator seeded by `seed`.
//
// Standard deviation, per parameter: sqrt(hac^2 + mc^2 + level^2), where
//   hac   is least squares' HAC std on the run's rows (hac_wald.hpp, as hac_parameters gives it).
//         Why it stands for SIMEX's sampling error: value = theta(0) + sum_i c_i (theta(lambda_i)
//         - theta(0)), and the second term, the estimated bias, is a smooth function of the
//         signal whose own sampling variation is of the order of the bias times LS's relative
//         std (second order while the correction is small against the value); the first term's
//         is LS's. HAC rather than the table's sigma^2 (W'W)^-1: the rows are low-passed and
//         decimated, their errors correlated (docs/ACCURACY.md: HAC's std is close to the
//         seed-to-seed scatter where the bias is small).
//   mc    is the Monte Carlo std of the estimate: the draws' extrapolated values' std / sqrt(draws).
//   level is the correction's uncertainty from the noise levels themselves: a channel's share of
//         the bias is proportional to its sigma^2 to first order, so sqrt(sum_c share_c^2 v_c),
//         v_c the relative variance of the measured sigma_c^2 (ChannelNoise::
//         level_relative_variance, a bootstrap over the measurement's windows; 0 when declared),
//         the channels' measurements independent.
//
// Limits: the quadratic extrapolant is exact for a bias linear or quadratic in the noise
// variance; attenuation of one column is 1 / (1 + k (1 + lambda)), convex in lambda, which the
// quadratic under-corrects when k is large (corrections of more than ~10 % of the value: their
// size is `relative_correction`; nothing checks it; the coverage benchmark's reach about 3 % at
// its noise x1 and 12 % at x2). Noise that is not white at the grid rate (a sensor that filters
// internally), or correlated between channels, is not what is simulated. Noise on the measured side only (y) costs Monte Carlo variance but biases nothing.
// Rows whose selection depends on a noisy channel (thresholds) are held at the run's selection.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/ingest/recorded_run.hpp"
#include "dynid/model/model.hpp"
#include "dynid/residual/model_fit.hpp"
#include "dynid/residual/noise_floor.hpp"

namespace dynid::residual {

struct SimexOptions {
  FitOptions fit;  ///< the rows' options as fit_model takes them (series unused)
  /// The added noise variances, in units of each channel's sigma^2: positive, at least two
  /// distinct (with lambda = 0 the quadratic needs three points).
  std::vector<double> lambdas{0.5, 1.0, 1.5, 2.0};
  int draws = 8;           ///< antithetic pairs, each used for every lambda; >= 2 (the Monte Carlo std needs two)
  std::uint64_t seed = 1;  ///< of the one generator of every draw
};

struct SimexFit {
  std::string model;
  std::vector<std::string> effects;
  std::vector<model::ParameterInfo> parameters;
  std::vector<std::string> contributing;  ///< channels whose noise reaches the rows
  std::uint64_t rows = 0;
  std::vector<double> lambdas;
  int draws = 0;
  Eigen::VectorXd ls_value;      ///< theta(0): weighted LS, the table's value; NaN: not identifiable
  Eigen::VectorXd ls_hac_std;    ///< its HAC std
  Eigen::MatrixXd lambda_value;  ///< parameters x lambdas: theta(lambda_i), the draws' mean
  Eigen::VectorXd value;         ///< extrapolated to lambda = -1 (= ls_value without contributing channels)
  Eigen::VectorXd std;           ///< sqrt(hac^2 + mc^2 + level^2), see the header
  Eigen::VectorXd monte_carlo_std;
  Eigen::VectorXd level_std;     ///< from the noise levels' own uncertainty

  /// True when some channel's noise reaches the rows: value is corrected.
  bool corrected() const { return !contributing.empty(); }
  /// (value - ls_value) / |value| of parameter i (0 when not corrected).
  double relative_correction(Eigen::Index i) const;
  /// One line an engineer reads: which channels' noise was corrected, with the largest
  /// correction in std, or that no noise reaches the rows.
  std::string statement() const;
};

/// `model` with `effects` on `run` (raw) and `segments` = preprocess_offline(run), corrected for
/// the noise `noise` (channel -> sigma, as measure_channel_noise gives it; channels the run does
/// not announce or with sigma 0 are skipped). InputError as fit_model, and for options out of
/// range (fewer than two distinct positive lambdas, draws < 2) or a negative or non-finite sigma.
SimexFit simex_fit(const model::Model& model, const std::vector<std::string>& effects, const ingest::RecordedRun& run,
                   const std::vector<ingest::PreprocessedSegment>& segments, const std::vector<ChannelNoise>& noise,
                   const SimexOptions& options = {});

}  // namespace dynid::residual
