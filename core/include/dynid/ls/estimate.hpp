#pragma once
// Estimate: parameter values with standard deviations from an accumulator
// (Venture 2003 §2.B.1; seeds/venture-2003.en.md §4.1).
//
//   X = argmin ||Y - W X|| over the base parameters,
//   sigma_rho^2 = ||Y - W X||^2 / (r - n_B),   C_XX = sigma_rho^2 (W_B^T W_B)^-1,
//   sigma_Xj = sqrt(C_XX(j, j)),   relative std % = 100 sigma_Xj / |X_j|,
//   Cond(W) = Sigma_1 / Sigma_nB of the base columns.
// Everything comes from R_aug alone, so it equals a batch solve of all rows to rounding error.
// Parameters that are dependent or eliminated get NaN values and standard deviations; the
// value reported for a regrouped parameter is its base-parameter combination (see
// BaseParameterAnalysis::relation).
#include <Eigen/Core>
#include <cstdint>

#include "dynid/ls/accumulator.hpp"
#include "dynid/ls/base_parameters.hpp"

namespace dynid::ls {

struct EstimateOptions {
  BaseParameterOptions base;
};

struct Estimate {
  Eigen::VectorXd value;                 ///< per standard parameter (NaN if not identifiable)
  Eigen::VectorXd standard_deviation;    ///< per standard parameter (NaN if not identifiable)
  Eigen::VectorXd relative_std_percent;  ///< 100 sigma / |value| (Inf for a zero value)
  Eigen::MatrixXd covariance;            ///< n x n, NaN rows/columns where not identifiable
  BaseParameterAnalysis structure;       ///< base parameters, regrouping, statuses
  double sigma = 0.0;                    ///< residual standard deviation sigma_rho
  double residual_norm = 0.0;            ///< ||Y - W X||
  double relative_residual_norm = 0.0;   ///< ||Y - W X|| / ||Y||
  double residual_rms = 0.0;             ///< ||Y - W X|| / sqrt(r)
  double condition_number = 0.0;         ///< Cond(W) of the base columns
  double effective_rows = 0.0;           ///< r (with forgetting: the sum of row weights)
  std::uint64_t rows = 0;                ///< rows folded
  double degrees_of_freedom = 0.0;       ///< r - n_B (sigma is NaN when <= 0)
};

/// Solves the accumulated least-squares problem. Throws InputError when no row was folded.
Estimate estimate(const Accumulator& accumulator, const EstimateOptions& options = {});

}  // namespace dynid::ls
