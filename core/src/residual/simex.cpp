#include "dynid/residual/simex.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <set>

#include <Eigen/QR>

#include "dynid/cancellation.hpp"
#include "dynid/error.hpp"
#include "folded_rows.hpp"
#include "hac_wald.hpp"

namespace dynid::residual {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void validate(const SimexOptions& o, const std::vector<ChannelNoise>& noise) {
  if (o.draws < 2) throw InputError("simex_fit: draws " + std::to_string(o.draws) + " < 2");
  std::set<double> distinct;
  for (double l : o.lambdas) {
    if (!(l > 0.0) || !std::isfinite(l)) throw InputError("simex_fit: every lambda must be positive and finite");
    distinct.insert(l);
  }
  if (distinct.size() < 2) throw InputError("simex_fit: at least two distinct lambdas are needed (a quadratic)");
  for (const ChannelNoise& c : noise)
    if (!(c.sigma >= 0.0) || !std::isfinite(c.sigma))
      throw InputError("simex_fit: the noise of '" + c.channel + "' is not a finite sigma >= 0");
}

// A channel given noise: its column in the run and its sigma.
struct Noisy {
  Eigen::Index column = -1;
  double sigma = 0.0;
  double level_relative_variance = 0.0;
  std::string channel;
};

std::vector<Noisy> announced_noisy(const ingest::RecordedRun& run, const std::vector<ChannelNoise>& noise) {
  std::vector<Noisy> out;
  for (const ChannelNoise& c : noise) {
    if (!(c.sigma > 0.0)) continue;
    const auto& channels = run.announcement.channels;
    for (std::size_t j = 0; j < channels.size(); ++j)
      if (channels[j].name == c.channel)
        out.push_back({static_cast<Eigen::Index>(j), c.sigma, c.level_relative_variance, c.channel});
  }
  return out;
}

// Standard normal noise for every sample of every channel of `noisy` (one column each).
Eigen::MatrixXd standard_noise(Eigen::Index samples, std::size_t channels, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::MatrixXd z(samples, static_cast<Eigen::Index>(channels));
  for (Eigen::Index c = 0; c < z.cols(); ++c)
    for (Eigen::Index i = 0; i < samples; ++i) z(i, c) = normal(rng);
  return z;
}

// The run with `scale` sigma_c z_c added to every channel c of `noisy`, preprocessed as
// preprocess_offline would (only those channels filtered again).
std::vector<ingest::PreprocessedSegment> noisy_copy(
    const ingest::RecordedRun& run, const std::vector<ingest::PreprocessedSegment>& segments,
    const std::vector<Noisy>& noisy, const Eigen::MatrixXd& z, double scale) {
  std::vector<ingest::PreprocessedSegment> out = segments;
  for (std::size_t c = 0; c < noisy.size(); ++c) {
    const Eigen::VectorXd values = run.samples.col(noisy[c].column) +
                                   (scale * noisy[c].sigma) * z.col(static_cast<Eigen::Index>(c));
    out = ingest::preprocess_channel_again(run, std::move(out), noisy[c].column, values);
  }
  return out;
}

// Weighted LS on the collected rows, columns `used` only, each group weighted by the held
// weights; columns scaled to unit norm for the solve. Returns the model's width, NaN elsewhere.
Eigen::VectorXd weighted_solution(const detail::FoldedRows& rows, const std::vector<Eigen::Index>& used,
                                  const std::vector<double>& weights) {
  const auto width = static_cast<Eigen::Index>(rows.parameters.size());
  const auto k = static_cast<Eigen::Index>(used.size());
  Eigen::Index n = 0;
  for (const std::vector<double>& values : rows.collected.values) n += static_cast<Eigen::Index>(values.size()) / (width + 1);
  Eigen::MatrixXd w(n, k);
  Eigen::VectorXd y(n);
  Eigen::Index r = 0;
  for (std::size_t g = 0; g < rows.collected.values.size(); ++g) {
    const std::vector<double>& values = rows.collected.values[g];
    const auto group_rows = static_cast<Eigen::Index>(values.size()) / (width + 1);
    for (Eigen::Index i = 0; i < group_rows; ++i, ++r) {
      const double* row = values.data() + i * (width + 1);
      for (Eigen::Index j = 0; j < k; ++j) w(r, j) = weights[g] * row[used[static_cast<std::size_t>(j)]];
      y(r) = weights[g] * row[width];
    }
  }
  const Eigen::VectorXd scale = w.colwise().norm().transpose().cwiseMax(std::numeric_limits<double>::min()).cwiseInverse();
  const Eigen::VectorXd x = (w * scale.asDiagonal()).colPivHouseholderQr().solve(y);
  Eigen::VectorXd out = Eigen::VectorXd::Constant(width, kNaN);
  for (Eigen::Index j = 0; j < k; ++j) out(used[static_cast<std::size_t>(j)]) = x(j) * scale(j);
  return out;
}

// The base rows, held: their selection, their weights and the columns LS identifies.
struct Base {
  detail::FoldedRows rows;
  detail::RowSelection selection;
  std::vector<double> weights;
  std::vector<Eigen::Index> used;
  Eigen::VectorXd value;
};

// theta of one noisy copy, on the base's rows and weights.
Eigen::VectorXd refit(const model::Model& model, const std::vector<std::string>& effects,
                      const std::vector<ingest::PreprocessedSegment>& noisy, const ingest::RecordedRun& run,
                      const FitOptions& options, const Base& base) {
  const detail::FoldedRows rows =
      detail::fold_rows(model, effects, noisy, run.announcement.sample_rate_hz, run.announcement.preprocessing.odmf,
                        options, true, &base.selection);
  return weighted_solution(rows, base.used, base.weights);
}

// The mean of theta with +scale z and -scale z added (an antithetic pair). Why pairs: theta's
// departure from theta(0) is, to first order, linear in the added noise (zero mean, and by far
// the largest part of one draw) and, to second order, the bias SIMEX measures; the pair's mean
// cancels the first-order part exactly and keeps the bias.
Eigen::VectorXd antithetic(const model::Model& model, const std::vector<std::string>& effects,
                           const ingest::RecordedRun& run, const std::vector<ingest::PreprocessedSegment>& segments,
                           const std::vector<Noisy>& noisy, const Eigen::MatrixXd& z, double scale,
                           const FitOptions& options, const Base& base) {
  return 0.5 * (refit(model, effects, noisy_copy(run, segments, noisy, z, scale), run, options, base) +
                refit(model, effects, noisy_copy(run, segments, noisy, z, -scale), run, options, base));
}

// A channel with its share of the bias: theta with its noise alone added once more (lambda = 1,
// one antithetic pair) minus theta(0), about the bias its own noise puts in theta(0).
struct Share {
  Noisy channel;
  Eigen::VectorXd bias;
};

// The channels whose noise alone changes the solution: the others would only cost refits.
std::vector<Share> contributing(const model::Model& model, const std::vector<std::string>& effects,
                                const ingest::RecordedRun& run, const std::vector<ingest::PreprocessedSegment>& segments,
                                const std::vector<Noisy>& noisy, const FitOptions& options, const Base& base,
                                std::mt19937_64& rng) {
  std::vector<Share> out;
  for (const Noisy& c : noisy) {
    const Eigen::MatrixXd z = standard_noise(run.samples.rows(), 1, rng);
    const Eigen::VectorXd x = antithetic(model, effects, run, segments, {c}, z, 1.0, options, base);
    bool changed = false;
    for (Eigen::Index j : base.used) changed = changed || x(j) != base.value(j);
    if (changed) out.push_back({c, x - base.value});
  }
  return out;
}

// The weights c_i of the quadratic least-squares fit through (lambda_i, theta_i), evaluated at
// lambda = -1: value = sum_i c_i theta_i. The points are lambda = 0 then `lambdas`.
Eigen::VectorXd extrapolation_weights(const std::vector<double>& lambdas) {
  const auto m = static_cast<Eigen::Index>(lambdas.size()) + 1;
  Eigen::MatrixXd x(m, 3);
  x.row(0) << 1.0, 0.0, 0.0;
  for (Eigen::Index i = 1; i < m; ++i) {
    const double l = lambdas[static_cast<std::size_t>(i - 1)];
    x.row(i) << 1.0, l, l * l;
  }
  const Eigen::RowVector3d at(1.0, -1.0, 1.0);
  // c' = at (X'X)^-1 X', by QR: (X'X)^-1 X' = R^-1 Q'.
  const Eigen::MatrixXd pseudo_inverse = x.colPivHouseholderQr().solve(Eigen::MatrixXd::Identity(m, m));
  return (at * pseudo_inverse).transpose();
}

Base base_of(const model::Model& model, const std::vector<std::string>& effects,
             const std::vector<ingest::PreprocessedSegment>& segments, const ingest::RecordedRun& run,
             const FitOptions& options) {
  const double rate = run.announcement.sample_rate_hz;
  const int odmf = run.announcement.preprocessing.odmf;
  Base base{detail::fold_rows(model, effects, segments, rate, odmf, options, true),
            detail::kept_rows(model, effects, segments, rate, odmf), {}, {}, {}};
  const detail::Evaluation ls = detail::evaluate(base.rows, {}, {});
  base.weights = ls.estimator_weights;
  for (Eigen::Index j = 0; j < ls.all.value.size(); ++j)
    if (std::isfinite(ls.all.value(j))) base.used.push_back(j);
  // theta(0) by the same solve as every draw's, so that the differences are the noise's alone.
  base.value = base.used.empty() ? ls.all.value : weighted_solution(base.rows, base.used, base.weights);
  return base;
}

// The draws: per pair b one noise realization z_b for every lambda (common random numbers: the
// lambdas' estimates then differ by the noise's scale alone, and the extrapolation, a difference
// of them with weights |c_i| up to a few, does not amplify independent draws' scatter). Fills
// fit.lambda_value (the pairs' mean per lambda) and returns each pair's extrapolated value
// (parameters x pairs): their mean is the estimate, their scatter its Monte Carlo std.
Eigen::MatrixXd simulate(const model::Model& model, const std::vector<std::string>& effects,
                         const ingest::RecordedRun& run, const std::vector<ingest::PreprocessedSegment>& segments,
                         const std::vector<Noisy>& noisy, const SimexOptions& options, const Base& base,
                         const Eigen::VectorXd& c, std::mt19937_64& rng, SimexFit& fit) {
  const auto width = base.value.size();
  const auto m = static_cast<Eigen::Index>(options.lambdas.size());
  fit.lambda_value = Eigen::MatrixXd::Zero(width, m);
  Eigen::MatrixXd extrapolated(width, options.draws);
  for (int b = 0; b < options.draws; ++b) {
    cancellation_point();
    const Eigen::MatrixXd z = standard_noise(run.samples.rows(), noisy.size(), rng);
    Eigen::VectorXd e = c(0) * base.value;
    for (Eigen::Index i = 0; i < m; ++i) {
      const double scale = std::sqrt(options.lambdas[static_cast<std::size_t>(i)]);
      const Eigen::VectorXd theta = antithetic(model, effects, run, segments, noisy, z, scale, options.fit, base);
      fit.lambda_value.col(i) += theta / options.draws;
      e += c(i + 1) * theta;
    }
    extrapolated.col(b) = e;
  }
  return extrapolated;
}

std::string format(const char* pattern, double a) {
  char buf[120];
  std::snprintf(buf, sizeof buf, pattern, a);
  return buf;
}

}  // namespace

double SimexFit::relative_correction(Eigen::Index i) const {
  if (!corrected() || !std::isfinite(value(i))) return 0.0;
  return (value(i) - ls_value(i)) / std::abs(value(i));
}

std::string SimexFit::statement() const {
  if (!corrected()) return "no measured noise reaches the regressors: the least-squares values stand";
  std::string channels;
  for (const std::string& c : contributing) channels += (channels.empty() ? "" : ", ") + c;
  double largest = 0.0;  // the largest correction in its std
  std::string which;
  for (Eigen::Index j = 0; j < value.size(); ++j) {
    if (!std::isfinite(value(j)) || !(std(j) > 0.0)) continue;
    const double z = std::abs(value(j) - ls_value(j)) / std(j);
    if (z >= largest) largest = z, which = parameters[static_cast<std::size_t>(j)].name;
  }
  return "corrected for the noise of " + channels + " by SIMEX (" + std::to_string(lambdas.size()) + " lambdas x " +
         std::to_string(draws) + " draws); largest correction '" + which + "' " + format("%.2g std", largest);
}

SimexFit simex_fit(const model::Model& model, const std::vector<std::string>& effects, const ingest::RecordedRun& run,
                   const std::vector<ingest::PreprocessedSegment>& segments, const std::vector<ChannelNoise>& noise,
                   const SimexOptions& options) {
  validate(options, noise);
  if (segments.empty()) throw InputError("simex_fit of " + model.name() + ": the run has no valid segment");
  FitOptions fit_options = options.fit;
  fit_options.series = false;
  const Base base = base_of(model, effects, segments, run, fit_options);
  const auto width = static_cast<Eigen::Index>(base.rows.parameters.size());
  SimexFit fit;
  fit.model = model.name();
  fit.effects = effects;
  fit.parameters = base.rows.parameters;
  fit.rows = base.rows.rows();
  fit.lambdas = options.lambdas;
  fit.draws = options.draws;
  fit.ls_value = base.value;
  const detail::WaldTest hac =
      detail::hac_wald_test(base.rows, base.value, base.weights, 0, width, run.announcement.preprocessing.odmf);
  fit.ls_hac_std = hac.stds.size() == width ? hac.stds : Eigen::VectorXd::Constant(width, kNaN);
  std::mt19937_64 rng(options.seed);
  const std::vector<Share> shares =
      base.used.empty() ? std::vector<Share>{}
                        : contributing(model, effects, run, segments, announced_noisy(run, noise), fit_options, base, rng);
  std::vector<Noisy> noisy;
  for (const Share& s : shares) {
    noisy.push_back(s.channel);
    fit.contributing.push_back(s.channel.channel);
  }
  fit.value = base.value;
  fit.std = fit.ls_hac_std;
  fit.monte_carlo_std = fit.level_std = Eigen::VectorXd::Zero(width);
  fit.lambda_value = base.value.replicate(1, static_cast<Eigen::Index>(options.lambdas.size()));
  if (noisy.empty()) return fit;
  SimexOptions simulation = options;
  simulation.fit = fit_options;
  const Eigen::VectorXd c = extrapolation_weights(options.lambdas);
  const Eigen::MatrixXd extrapolated = simulate(model, effects, run, segments, noisy, simulation, base, c, rng, fit);
  fit.value = extrapolated.rowwise().mean();
  const Eigen::MatrixXd centred = extrapolated.colwise() - fit.value;
  fit.monte_carlo_std = (centred.rowwise().squaredNorm() / ((options.draws - 1.0) * options.draws)).cwiseSqrt();
  // Each channel's share of the bias is proportional to its sigma^2: its relative variance
  // carries over to the share (independent measurements per channel).
  Eigen::VectorXd level_variance = Eigen::VectorXd::Zero(width);
  for (const Share& s : shares) level_variance += s.bias.cwiseAbs2() * s.channel.level_relative_variance;
  fit.level_std = level_variance.cwiseSqrt();
  fit.std = (fit.ls_hac_std.cwiseAbs2() + fit.monte_carlo_std.cwiseAbs2() + fit.level_std.cwiseAbs2()).cwiseSqrt();
  return fit;
}

}  // namespace dynid::residual
