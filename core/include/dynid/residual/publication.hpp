#pragma once
// The publication rule: which estimator's values a model's table publishes, least squares,
// instrumental variables or SIMEX (docs/ACCURACY.md, "What is published"). One home: the
// server's tables (server/estimate_tables.hpp) and the coverage benchmark (bench/coverage) both
// call it, so the benchmark measures what is published.
//
// Rule, one estimator per table:
//   1. Least squares, unless an IV fit of the same columns is given and its Durbin-Wu-Hausman
//      test rejects least squares (IvFit::replaces_least_squares): then IV on every row both
//      estimate. The bias test's line is IV's statement whenever an IV fit is given.
//   2. Where IV was chosen and a SIMEX fit of the same columns is given: SIMEX in IV's place on
//      every row all three estimate when Hausman's comparison lets it stand
//      (simex_against_iv.hpp); its statement is appended to the bias test's line either way.
//   3. Where least squares stands and SIMEX corrected the rows: SIMEX on every row both estimate
//      that least squares' own classification calls identified.
// Rows the chosen estimator does not replace keep least squares' value and std.
//
// Contract: a pure function of its arguments; never throws for fits of other columns (they are
// ignored, as if absent).
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "dynid/ls/estimate.hpp"
#include "dynid/model/model.hpp"
#include "dynid/residual/iv_fit.hpp"
#include "dynid/residual/simex.hpp"

namespace dynid::residual {

enum class PublishedEstimator { kLeastSquares, kInstrumentalVariables, kSimex };

struct Publication {
  PublishedEstimator estimator = PublishedEstimator::kLeastSquares;
  /// Per parameter: true where `value` and `std` come from `estimator`, not least squares.
  std::vector<bool> replaced;
  Eigen::VectorXd value;     ///< the published values (least squares' where not replaced)
  Eigen::VectorXd std;       ///< and their std
  bool bias_tested = false;  ///< an IV fit of the same columns was given
  std::string bias_test;     ///< IV's statement, then "; " and SIMEX against IV's where compared
};

/// The published rows of one model: `least_squares` (DYCARO's weighted estimate) with the
/// column norms of its weighted system (for model::classify_parameters), and the optional IV
/// and SIMEX fits of the same run and configuration (null: not computed).
Publication publish(const std::vector<model::ParameterInfo>& parameters,
                    const ls::Estimate& least_squares, const Eigen::VectorXd& column_norms,
                    const IvFit* iv, const SimexFit* simex);

}  // namespace dynid::residual
