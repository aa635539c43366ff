#pragma once
// EstimateTable: what the server publishes about one model of one vehicle (wire type Estimate)
// and what engineers print: one row per standard parameter (value, standard deviation,
// relative standard deviation %, status, regrouping relation) and the fit's figures.
//
// make_estimate_table() builds it from an ls::Estimate; `names` and `units` are the model's
// parameter names and units, in its column order (InputError if their sizes differ from the
// estimate's). Relations are filled for regrouped parameters (BaseParameterAnalysis::relation).
// Statuses are the base-parameter analysis' until the caller refines them
// (apply_verdict(), with model::classify_parameters: poorly identified, not excited, implausible).
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "dynid/ls/base_parameters.hpp"
#include "dynid/ls/estimate.hpp"
#include "dynid/model/parameter_status.hpp"

namespace dynid::dds {

struct ParameterEntry {
  std::string name;
  std::string unit;
  double value = 0.0;                 ///< NaN when not identifiable
  double standard_deviation = 0.0;    ///< NaN when not identifiable
  double relative_std_percent = 0.0;  ///< 100 sigma / |value|
  ls::ParameterStatus status = ls::ParameterStatus::kIdentified;
  std::string relation;  ///< for kRegrouped: the base-parameter combination
  std::string reason = {};  ///< why the status (model/parameter_status.hpp); "" when identified
  /// When the table's estimator is not kLeastSquares: the least-squares value and standard
  /// deviation the row's replace (NaN for a row the estimator does not replace, and under least
  /// squares).
  double least_squares_value = std::numeric_limits<double>::quiet_NaN();
  double least_squares_std = std::numeric_limits<double>::quiet_NaN();
};

/// EstimateTable::estimator: least squares (the fold's estimate, and what an older server
/// publishes), instrumental variables where the live bias test rejects least squares, or SIMEX
/// (least squares corrected for the measured sensor noise, residual/simex.hpp) where the test
/// does not reject and that noise reaches the rows, or where it rejects and Hausman's comparison
/// lets SIMEX stand in for IV (residual/simex_against_iv.hpp).
inline constexpr const char* kLeastSquares = "least squares";
inline constexpr const char* kInstrumentalVariables = "instrumental variables";
inline constexpr const char* kSimex = "SIMEX";

struct GroupResidual {
  std::string group;
  std::uint64_t rows = 0;
  double residual_rms = 0.0;
};

struct EstimateTable {
  std::string vehicle;
  std::string model;
  std::string source;          ///< run id or pool id
  std::uint64_t revision = 0;  ///< increases with every publication for (vehicle, model)
  std::vector<ParameterEntry> parameters;
  std::uint64_t rows = 0;
  double effective_rows = 0.0;
  double sigma = 0.0;
  double condition_number = 0.0;
  double residual_rms = 0.0;
  double relative_residual_norm = 0.0;
  std::vector<GroupResidual> groups;
  /// "" unless the source excites none of the parameters; then what would ("needs d_vx (...)").
  std::string not_excited = {};
  /// "" unless a channel the model reads is unhealthy on the run (ingest/channel_health.hpp);
  /// then why, one line. The rows stay (JSON) but no status, verdict or advice is given. Set by
  /// the server's replies; not carried on the Estimate topic.
  std::string not_identified = {};
  /// The residual loop's verdict on the run so far (residual/diagnosis.hpp), kept current by a
  /// server started with a live-residual interval: "adequate", "explained" or "structure left";
  /// "" when not computed (off, a pool, no row yet). The statement says why (cut to the wire's
  /// bound); `residual_through` is the last chunk it includes.
  std::string residual_verdict = {};
  std::string residual_statement = {};
  std::uint64_t residual_through = 0;
  /// Whose values the rows are (kLeastSquares, kInstrumentalVariables or kSimex:
  /// residual/publication.hpp) and the bias test's one line (residual/iv_fit.hpp
  /// IvFit::statement(); "" when not computed: the live judgement off, a pool, too few rows),
  /// `bias_through` the last chunk the test includes.
  std::string estimator = kLeastSquares;
  std::string bias_test = {};
  std::uint64_t bias_through = 0;
};

EstimateTable make_estimate_table(const std::string& vehicle, const std::string& model,
                                  const std::string& source,
                                  const std::vector<std::string>& names,
                                  const std::vector<std::string>& units,
                                  const ls::Estimate& estimate);

/// Puts the statuses, reasons and model-level note of a classification on the table (sizes must
/// match: InputError).
void apply_verdict(EstimateTable& table, const model::ModelVerdict& verdict);

}  // namespace dynid::dds
