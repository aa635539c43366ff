#include "dynid/residual/effect_comparison.hpp"

#include <cmath>
#include <limits>

#include <boost/math/distributions/normal.hpp>

#include "dynid/model/parameter_status.hpp"

namespace dynid::residual {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double error_percent(double value, const std::optional<double>& truth) {
  if (!truth || *truth == 0.0 || !std::isfinite(value)) return kNaN;
  return 100.0 * (value - *truth) /
         std::abs(*truth);  // signed as the error, whatever the truth's sign
}

double drop(double before, double after) { return before > 0.0 ? 1.0 - after / before : 0.0; }

}  // namespace

double ParameterChange::error_before_percent() const { return error_percent(before, truth); }
double ParameterChange::error_after_percent() const { return error_percent(after, truth); }

double EffectComparison::in_sample_drop() const {
  return drop(before.weighted_rms_in_sample, after.weighted_rms_in_sample);
}
double EffectComparison::held_out_drop() const {
  return drop(before.weighted_rms_held_out, after.weighted_rms_held_out);
}

double hausman_distance(const ParameterChange& p, bool sharpens) {
  if (!std::isfinite(p.before) || !std::isfinite(p.after)) return kNaN;
  const double difference = p.std_before * p.std_before - p.std_after * p.std_after;
  double variance = sharpens ? difference : -difference;
  if (!(variance > 0.0)) variance = p.std_before * p.std_before + p.std_after * p.std_after;
  if (!(variance > 0.0)) return kNaN;
  return std::abs(p.after - p.before) / std::sqrt(variance);
}

double hausman_bound(std::size_t compared) {
  constexpr double kFamilyErrorRate = 0.01;
  return boost::math::quantile(boost::math::complement(
      boost::math::normal(), kFamilyErrorRate / (2.0 * static_cast<double>(compared))));
}

EffectComparison compare_effect(const model::Model& model, const std::vector<std::string>& declared,
                                const std::string& effect,
                                const std::vector<ingest::PreprocessedSegment>& run,
                                double sample_rate_hz, int odmf, const FitOptions& options,
                                const std::map<std::string, double>& truth) {
  EffectComparison c;
  c.effect = effect;
  c.before = fit_model(model, declared, run, sample_rate_hz, odmf, options);
  std::vector<std::string> with = declared;
  with.push_back(effect);
  FitOptions same_scale = options;  // the declared model's weights: one scale for both fits
  same_scale.group_weights.clear();
  for (const GroupFit& g : c.before.groups) same_scale.group_weights.push_back(g.sigma > 0.0 ? 1.0 / g.sigma : 0.0);
  c.after = fit_model(model, with, run, sample_rate_hz, odmf, same_scale);
  const ls::Estimate& b = c.before.estimate;
  const ls::Estimate& a = c.after.estimate;
  const auto status_b = model::classify_parameters(c.before.parameters, b, c.before.column_norms);
  const auto status_a = model::classify_parameters(c.after.parameters, a, c.after.column_norms);
  for (std::size_t i = 0; i < c.after.parameters.size(); ++i) {
    const model::ParameterInfo& p = c.after.parameters[i];
    ParameterChange change{p.name, p.unit, kNaN, kNaN, a.value(static_cast<Eigen::Index>(i)),
                           a.standard_deviation(static_cast<Eigen::Index>(i)), std::nullopt};
    change.status_after = status_a.parameters[i].status;
    if (i < c.before.parameters.size()) {
      change.before = b.value(static_cast<Eigen::Index>(i));
      change.std_before = b.standard_deviation(static_cast<Eigen::Index>(i));
      change.status_before = status_b.parameters[i].status;
    }
    if (const auto t = truth.find(p.name); t != truth.end()) change.truth = t->second;
    c.parameters.push_back(change);
  }
  return c;
}

}  // namespace dynid::residual
