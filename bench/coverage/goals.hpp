#pragma once
// Issue 16's goals, said per parameter in words: a std covers the error when at least 90 % of the
// seeds have |error| <= 2 std and the mean error (the bias no std of one run can show) is at most
// a third of the mean std; and the accuracy goals of the estimates themselves (mass within
// 0.5 %, engine inertia within 3 %, SCx and the cornering stiffnesses within 3 %).
#include <string>
#include <vector>

#include "summary.hpp"

namespace dynid::benchcoverage {

inline constexpr double kCoverageGoal = 0.9;
inline constexpr double kBiasOverStdGoal = 1.0 / 3.0;

/// The accuracy goal of the parameter, in %; NaN when it sets none.
double accuracy_goal_pct(const std::string& parameter);

/// One line per row: whether each std meets the coverage goals, and the accuracy goal when there is one.
std::string verdicts(const std::vector<ParameterCoverage>& rows);

/// The same for the instrumental-variable estimate, with its refusals and DWH rejection rate.
std::string iv_verdicts(const std::vector<ParameterCoverage>& rows);

/// The same for what the product's table publishes (IV where the bias test rejects LS).
std::string without_simex_verdicts(const std::vector<ParameterCoverage>& rows);

/// The same for the SIMEX estimate.
std::string simex_verdicts(const std::vector<ParameterCoverage>& rows);

/// The same for what the server publishes (IV where DWH rejects, else SIMEX where it improves).
std::string published_verdicts(const std::vector<ParameterCoverage>& rows);

}  // namespace dynid::benchcoverage
