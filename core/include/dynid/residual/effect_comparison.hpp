#pragma once
// EffectComparison: "add effect" and the before/after report (DESIGN.md "Residual loop" step
// 3): the model as declared and the model with the effect, each fitted on its own rows of the
// whole run (model_fit.hpp); their residual RMS and relative norms in sample and held out; the
// parameters with standard deviations before and after; and, where the truth is known (a
// simulated run, a weighed car), the parameter errors before and after.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "dynid/residual/effect_screen.hpp"
#include "dynid/residual/model_fit.hpp"

namespace dynid::residual {

struct ParameterChange {
  std::string name;
  std::string unit;
  double before = 0.0;  ///< NaN when the parameter is the added effect's (or not identifiable)
  double std_before = 0.0;
  double after = 0.0;
  double std_after = 0.0;
  std::optional<double> truth;
  /// Statuses (model/parameter_status.hpp) in each fit; before: nullopt for the effect's own.
  std::optional<ls::ParameterStatus> status_before = std::nullopt;
  ls::ParameterStatus status_after = ls::ParameterStatus::kIdentified;
  double error_before_percent() const;  ///< 100 (value - truth) / |truth|; NaN without truth
  double error_after_percent() const;
};

/// Hausman's comparison of one parameter's two values (trace.hpp, sensor_agreement.hpp): how far
/// `after` lies from `before` in std of their difference. `sharpens`: `after` is the efficient
/// estimate under the hypothesis (a better sensor), the difference's variance std_before^2 -
/// std_after^2; else (a column more) std_after^2 - std_before^2. Where that is not positive, the
/// sum (conservative). NaN when either value is not finite or no variance is positive.
double hausman_distance(const ParameterChange& p, bool sharpens);

/// The bound on the largest hausman_distance over `compared` parameters at a 1 % family error
/// rate: the two-sided normal quantile at 1 % / compared (Bonferroni).
double hausman_bound(std::size_t compared);

struct EffectComparison {
  std::string effect;
  ModelFit before;
  ModelFit after;
  std::vector<ParameterChange> parameters;  ///< the model's, then the effect's
  /// Relative drops (1 - after/before) of the weighted RMS, in sample and held out.
  double in_sample_drop() const;
  double held_out_drop() const;
};

/// `truth`: parameter name -> true value, for the parameters where it is known.
EffectComparison compare_effect(const model::Model& model, const std::vector<std::string>& declared,
                                const std::string& effect,
                                const std::vector<ingest::PreprocessedSegment>& run,
                                double sample_rate_hz, int odmf, const FitOptions& options = {},
                                const std::map<std::string, double>& truth = {});

}  // namespace dynid::residual
