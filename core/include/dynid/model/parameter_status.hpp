#pragma once
// Parameter status: what one run's estimate says about each parameter of a model, so that a
// table never calls "identified" a number the run knows nothing about (issue 16).
//
// Inputs: the model's parameters (ParameterInfo: bounds, typical magnitude, the signal that
// excites each column), the estimate (values, std, relative std, the base-parameter structure)
// and the norm of each column of the system the estimate was solved from (column_norms(): the
// weighted system of ls::EquationGroups, where the residual norm is that system's too).
//
// Rules, in this order; the first that applies decides. Dependent, eliminated and regrouped
// parameters keep the status of the base-parameter analysis (ls/base_parameters.hpp); only an
// identified one is refined.
//
// 1. Not excited: the run carries (almost) no information about the parameter. Judged against
//    its excitation scale s (excitation_scale(): |a priori| when not zero, else the declared
//    typical magnitude, else the width of a finite bound interval; without a scale this rule is
//    not applied). Either
//    a. the term it puts in the equations at magnitude s is below the residual,
//       ||W(:, j)|| s < ||Y - W X||, and the estimate is within 2 std of zero: the signal its
//       column reads does not move beyond what the model leaves unexplained, and the run cannot
//       tell the parameter from zero (a road-grade mass on a flat road). A value 2 std or more
//       from zero is information, however small its term: the residual may be model error (a
//       drag area under a missing road grade reads "poorly identified", not "not excited"); or
//    b. its standard deviation is at least s: the run cannot tell the parameter's typical
//       magnitude from zero (its column moves, but only together with others: drag and rolling
//       resistance at constant speed).
//    No tuned threshold: both compare the run's information with the quantity's own size.
// 2. Implausible: the value lies outside the physical bounds (ParameterInfo::lower/upper) by
//    more than `implausible_sigmas` (2) standard deviations, the 95 % interval of DYCARO
//    (Venture 2003 L1609, seeds/venture-2003.en.md §4.1). Within 2 std of a bound it is not.
// 3. Poorly identified (DYCARO's quality rule, seeds/venture-2003.en.md §4.1, L1615): a relative
//    std above `poor_relative_std_percent` (10 %), or above `k_smallest` (10, the low end of
//    the thesis' k = 10..50) times the smallest relative std among the model's parameters still
//    identified after rules 1 and 2. The k rule applies only above `well_estimated_percent`
//    (1 %, the thesis' "well estimated", L2893, L3501): a parameter at 0.5 % is not poor
//    because another is at 0.02 %.
// 4. Identified otherwise.
//
// A model whose run excites none of its parameters (every one not excited, dependent or
// eliminated, at least one not excited or eliminated) gets a one-line note naming what would
// excite it (ModelVerdict::not_excited): tables print that line instead of numbers.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "dynid/ls/accumulator.hpp"
#include "dynid/ls/estimate.hpp"
#include "dynid/model/model.hpp"

namespace dynid::model {

struct StatusRules {
  double poor_relative_std_percent = 10.0;  ///< rule 3, absolute limit (%)
  double k_smallest = 10.0;                 ///< rule 3, k times the smallest relative std
  double well_estimated_percent = 1.0;      ///< rule 3: the k rule applies above this (%)
  double implausible_sigmas = 2.0;          ///< rule 2: std outside a bound
};

struct ParameterVerdict {
  ls::ParameterStatus status = ls::ParameterStatus::kIdentified;
  std::string reason;  ///< why, one line; "" for identified, dependent, eliminated
};

struct ModelVerdict {
  std::vector<ParameterVerdict> parameters;  ///< per parameter, in column order
  /// "" unless the run excites none of the parameters; then what would: "needs d_vx (...)".
  std::string not_excited;
};

/// |a priori| when not zero, else `typical`, else upper - lower when both bounds are finite;
/// nullopt when none (rule 1 is then not applied).
std::optional<double> excitation_scale(const ParameterInfo& parameter);

/// ||W(:, j)|| of every column of the accumulated system (from its R: R^T R = W^T W).
Eigen::VectorXd column_norms(const ls::Accumulator& accumulator);

/// The rules above. InputError when the sizes of `parameters`, the estimate and `norms` differ.
ModelVerdict classify_parameters(const std::vector<ParameterInfo>& parameters,
                                 const ls::Estimate& estimate,
                                 const Eigen::Ref<const Eigen::VectorXd>& norms,
                                 const StatusRules& rules = {});

}  // namespace dynid::model
