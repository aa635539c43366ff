#include "goals.hpp"

#include <cmath>
#include <cstdio>
#include <map>

namespace dynid::benchcoverage {
namespace {

std::string std_verdict(const char* which, const StdCoverage& c) {
  const bool covers = c.within_2std >= kCoverageGoal;
  const bool unbiased = c.error_over_std <= kBiasOverStdGoal;
  char b[200];
  std::snprintf(b, sizeof b, "%s std %s (%.0f %% within 2 std%s, mean error %.2f std%s)", which,
                covers && unbiased ? "meets both" : "FAILS", 100.0 * c.within_2std, covers ? "" : " < 90 %",
                c.error_over_std, unbiased ? "" : " > 1/3");
  return b;
}

std::string accuracy_verdict(const ParameterCoverage& r) {
  const double goal = accuracy_goal_pct(r.parameter);
  if (std::isnan(goal)) return "no accuracy goal";
  int within = 0;
  for (double e : r.errors_pct) within += std::abs(e) <= goal ? 1 : 0;
  char b[200];
  std::snprintf(b, sizeof b, "accuracy goal %.1f %%: mean error %+.2f %% %s, %d of %d seeds within", goal,
                r.mean_error_pct, std::abs(r.mean_error_pct) <= goal ? "within" : "OUTSIDE", within, r.seeds);
  return b;
}

}  // namespace

double accuracy_goal_pct(const std::string& parameter) {
  static const std::map<std::string, double> goals = {{"mass", 0.5},
                                                      {"engine_inertia", 3.0},
                                                      {"SCx", 3.0},
                                                      {"front_cornering_stiffness", 3.0},
                                                      {"rear_cornering_stiffness", 3.0}};
  const auto it = goals.find(parameter);
  return it == goals.end() ? std::nan("") : it->second;
}

std::string verdicts(const std::vector<ParameterCoverage>& rows) {
  std::string out;
  for (const ParameterCoverage& r : rows)
    out += "- " + r.model + " " + r.parameter + ": " + std_verdict("table", r.table) + "; " + std_verdict("HAC", r.hac) +
           "; " + accuracy_verdict(r) + "\n";
  return out;
}

}  // namespace dynid::benchcoverage
