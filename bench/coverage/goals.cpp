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

std::string accuracy_verdict(const std::string& parameter, double mean_error_pct, const std::vector<double>& errors_pct) {
  const double goal = accuracy_goal_pct(parameter);
  if (std::isnan(goal)) return "no accuracy goal";
  int within = 0;
  for (double e : errors_pct) within += std::abs(e) <= goal ? 1 : 0;
  char b[200];
  std::snprintf(b, sizeof b, "accuracy goal %.1f %%: mean error %+.2f %% %s, %d of %zu runs within", goal,
                mean_error_pct, std::abs(mean_error_pct) <= goal ? "within" : "OUTSIDE", within, errors_pct.size());
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
           "; " + accuracy_verdict(r.parameter, r.mean_error_pct, r.errors_pct) + "\n";
  return out;
}

std::string iv_verdicts(const std::vector<ParameterCoverage>& rows) {
  std::string out;
  for (const ParameterCoverage& r : rows) {
    char b[120];
    std::snprintf(b, sizeof b, "; %d runs refused; DWH rejects at 1 %% in %.0f %%", r.iv.refused,
                  100.0 * r.iv.dwh_rejections);
    out += "- " + r.model + " " + r.parameter + " by IV: " + std_verdict("IV", r.iv.textbook) + "; " +
           std_verdict("IV HAC", r.iv.hac) + "; " + accuracy_verdict(r.parameter, r.iv.mean_error_pct, r.iv.errors_pct) +
           b + "\n";
  }
  return out;
}

namespace {

// One verdict line of an estimate of row r: "- model parameter <how>: <std verdict>; <accuracy>".
std::string estimate_line(const ParameterCoverage& r, const std::string& how, const char* which, const StdCoverage& c,
                          double mean_error_pct, const std::vector<double>& errors_pct) {
  return "- " + r.model + " " + r.parameter + " " + how + ": " + std_verdict(which, c) + "; " +
         accuracy_verdict(r.parameter, mean_error_pct, errors_pct) + "\n";
}

}  // namespace

std::string without_simex_verdicts(const std::vector<ParameterCoverage>& rows) {
  std::string out;
  for (const ParameterCoverage& r : rows) {
    const PublishedCoverage& p = r.without_simex;
    out += estimate_line(r, "without SIMEX (" + std::to_string(p.by_iv) + " of " + std::to_string(p.seeds) +
                                " runs by IV, the others least squares)",
                         "that table's", p.std, p.mean_error_pct, p.errors_pct);
  }
  return out;
}

std::string simex_verdicts(const std::vector<ParameterCoverage>& rows) {
  std::string out;
  for (const ParameterCoverage& r : rows) {
    const SimexCoverage& s = r.simex;
    out += estimate_line(r, "by SIMEX (" + std::to_string(s.corrected) + " of " + std::to_string(s.seeds) + " runs corrected)",
                         "SIMEX", s.std, s.mean_error_pct, s.errors_pct);
  }
  return out;
}

std::string published_verdicts(const std::vector<ParameterCoverage>& rows) {
  std::string out;
  for (const ParameterCoverage& r : rows) {
    const PublishedCoverage& p = r.published;
    out += estimate_line(r, "as published (" + std::to_string(p.by_iv) + " by IV, " + std::to_string(p.by_simex) +
                                " by SIMEX of " + std::to_string(p.seeds) + " runs)",
                         "published", p.std, p.mean_error_pct, p.errors_pct);
  }
  return out;
}

}  // namespace dynid::benchcoverage
