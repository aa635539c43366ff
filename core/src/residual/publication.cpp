#include "dynid/residual/publication.hpp"

#include <cmath>

#include "dynid/model/parameter_status.hpp"
#include "dynid/residual/simex_against_iv.hpp"

namespace dynid::residual {
namespace {

bool same_columns(const std::vector<model::ParameterInfo>& parameters,
                  const std::vector<model::ParameterInfo>& fitted, const Eigen::VectorXd& value) {
  if (fitted.size() != parameters.size() ||
      value.size() != static_cast<Eigen::Index>(parameters.size()))
    return false;
  for (std::size_t k = 0; k < parameters.size(); ++k)
    if (fitted[k].name != parameters[k].name) return false;
  return true;
}

// Least squares' rows, with `estimator`'s value and std on the rows `replace` marks.
void choose(Publication& out, const ls::Estimate& least_squares, PublishedEstimator estimator,
            const Eigen::VectorXd& value, const Eigen::VectorXd& std,
            const std::vector<bool>& replace) {
  out.estimator = estimator;
  out.replaced = replace;
  out.value = least_squares.value;
  out.std = least_squares.standard_deviation;
  for (Eigen::Index j = 0; j < out.value.size(); ++j) {
    if (!replace[static_cast<std::size_t>(j)]) continue;
    out.value(j) = value(j);
    out.std(j) = std(j);
  }
}

}  // namespace

Publication publish(const std::vector<model::ParameterInfo>& parameters,
                    const ls::Estimate& least_squares, const Eigen::VectorXd& column_norms,
                    const IvFit* iv, const SimexFit* simex) {
  Publication out;
  const std::size_t n = parameters.size();
  choose(out, least_squares, PublishedEstimator::kLeastSquares, least_squares.value,
         least_squares.standard_deviation, std::vector<bool>(n, false));
  const auto finite = [](const Eigen::VectorXd& v, std::size_t k) {
    return std::isfinite(v(static_cast<Eigen::Index>(k)));
  };

  const bool iv_usable = iv != nullptr && same_columns(parameters, iv->parameters, iv->value);
  if (iv_usable) {
    out.bias_tested = true;
    out.bias_test = iv->statement();
    if (iv->replaces_least_squares()) {
      std::vector<bool> replace(n);
      for (std::size_t k = 0; k < n; ++k)
        replace[k] = finite(iv->value, k) && finite(least_squares.value, k);
      choose(out, least_squares, PublishedEstimator::kInstrumentalVariables, iv->value, iv->hac_std,
             replace);
    }
  }
  if (simex == nullptr || !same_columns(parameters, simex->parameters, simex->value)) return out;

  if (out.estimator == PublishedEstimator::kInstrumentalVariables) {
    const SimexAgainstIv comparison = compare_simex_with_iv(*iv, *simex);
    if (!comparison.compared) return out;
    out.bias_test += "; " + comparison.statement();
    if (!comparison.simex_stands) return out;
    std::vector<bool> replace(n);
    for (std::size_t k = 0; k < n; ++k)
      replace[k] =
          finite(iv->value, k) && finite(simex->value, k) && finite(least_squares.value, k);
    choose(out, least_squares, PublishedEstimator::kSimex, simex->value, simex->std, replace);
    return out;
  }

  // Least squares stands: SIMEX on the rows least squares' own classification calls identified.
  const model::ModelVerdict verdict =
      model::classify_parameters(parameters, least_squares, column_norms);
  std::vector<bool> replace(n);
  bool any = false;
  for (std::size_t k = 0; k < n; ++k) {
    replace[k] = simex->corrected() && finite(simex->value, k) && finite(least_squares.value, k) &&
                 verdict.parameters[k].status == ls::ParameterStatus::kIdentified;
    any = any || replace[k];
  }
  if (any)
    choose(out, least_squares, PublishedEstimator::kSimex, simex->value, simex->std, replace);
  return out;
}

}  // namespace dynid::residual
