#include "dynid/report/simex_report.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "cells.hpp"
#include "dynid/error.hpp"

namespace dynid::report {
namespace {

using detail::finite;
using detail::number;


// (SIMEX - LS) in SIMEX's std: how large the correction is against its own uncertainty.
double correction_z(const residual::SimexFit& f, Eigen::Index j) {
  return f.std(j) > 0.0 ? (f.value(j) - f.ls_value(j)) / f.std(j) : std::nan("");
}

void check_flags(const residual::SimexFit& f, const std::vector<bool>& by_simex) {
  if (by_simex.size() != f.parameters.size())
    throw InputError("SIMEX report: " + std::to_string(by_simex.size()) +
                     " publication flags for " + std::to_string(f.parameters.size()) +
                     " parameters of " + f.model);
}

}  // namespace

std::string format_simex_text(const residual::SimexFit& f, const std::vector<bool>& by_simex) {
  check_flags(f, by_simex);
  std::string out = fmt::format("SIMEX: {} (effects: {})\n", f.model,
                                f.effects.empty() ? "none" : fmt::format("{}", fmt::join(f.effects, ", ")));
  if (!f.corrected()) return out + "  verdict: " + f.statement() + "\n";
  out += fmt::format("  noise of {} added at lambda = {} times each one's measured variance, {} draws each; {} rows; "
                     "extrapolated to lambda = -1\n",
                     fmt::join(f.contributing, ", "), fmt::join(f.lambdas, ", "), f.draws, f.rows);
  out += fmt::format("  {:<26} {:<10} {:>13} {:>11} {:>13} {:>11} {:>11} {:>11} {:>8}  {}\n", "parameter", "unit",
                     "least squares", "LS std HAC", "SIMEX", "SIMEX std", "of it MC", "noise lvl", "corr. z",
                     "published");
  for (std::size_t k = 0; k < f.parameters.size(); ++k) {
    const auto j = static_cast<Eigen::Index>(k);
    const double z = correction_z(f, j);
    out += fmt::format("  {:<26} {:<10} {:>13} {:>11} {:>13} {:>11} {:>11} {:>11} {:>8}  {}\n",
                       f.parameters[k].name, f.parameters[k].unit, number(f.ls_value(j)),
                       number(f.ls_hac_std(j)), number(f.value(j)), number(f.std(j)),
                       number(f.monte_carlo_std(j)), number(f.level_std(j)),
                       std::isfinite(z) ? fmt::format("{:+.2f}", z) : "-",
                       by_simex[k] ? "SIMEX" : "least squares");
  }
  out += "  published: SIMEX for every identified parameter; where the bias test sends the model to IV (dynid iv), "
         "SIMEX only if Hausman's comparison with IV lets it stand (dynid estimates says which)\n";
  return out + "  verdict: " + f.statement() + "\n";
}

std::string simex_json(const residual::SimexFit& f, const std::vector<bool>& by_simex) {
  check_flags(f, by_simex);
  nlohmann::json parameters = nlohmann::json::array();
  for (std::size_t k = 0; k < f.parameters.size(); ++k) {
    const auto j = static_cast<Eigen::Index>(k);
    parameters.push_back({{"name", f.parameters[k].name},
                          {"unit", f.parameters[k].unit},
                          {"least_squares", finite(f.ls_value(j))},
                          {"least_squares_hac_std", finite(f.ls_hac_std(j))},
                          {"simex", finite(f.value(j))},
                          {"simex_std", finite(f.std(j))},
                          {"monte_carlo_std", finite(f.monte_carlo_std(j))},
                          {"level_std", finite(f.level_std(j))},
                          {"correction_z", finite(correction_z(f, j))},
                          {"simex_published", static_cast<bool>(by_simex[k])}});
  }
  return nlohmann::json{{"model", f.model},
                        {"effects", f.effects},
                        {"corrected", f.corrected()},
                        {"channels", f.contributing},
                        {"lambdas", f.lambdas},
                        {"draws", f.draws},
                        {"rows", f.rows},
                        {"parameters", parameters},
                        {"statement", f.statement()}}
      .dump();
}

}  // namespace dynid::report
