#include "dynid/report/iv_report.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "cells.hpp"

namespace dynid::report {
namespace {

using detail::finite;
using detail::number;

// (IV - LS) in standard deviations of the difference: how surely this parameter moves.
double apart(const residual::IvFit& f, Eigen::Index j) {
  const double d = f.value(j) - f.ls_value(j);
  return f.difference_std(j) > 0.0 ? d / f.difference_std(j) : std::nan("");
}

}  // namespace

std::string format_iv_text(const residual::IvFit& f) {
  std::string out = fmt::format("instrumental variables: {} (effects: {})\n", f.model,
                                f.effects.empty() ? "none" : fmt::format("{}", fmt::join(f.effects, ", ")));
  out += fmt::format("  instruments: the model's own rows {} to {} decimated rows before and after; {} rows ({} left out: "
                     "no such row in their segment)\n",
                     f.lag_rows, f.lag_rows + 2, f.rows, f.rows_without_partner);
  out += fmt::format("  first stage: smallest canonical correlation {}, Cragg-Donald F {} (IV refused below 10)\n",
                     number(f.smallest_canonical_correlation), number(f.instrument_f));
  if (!f.refused) {
    out += fmt::format("  {:<26} {:<10} {:>13} {:>13} {:>11} {:>11} {:>8}\n", "parameter", "unit", "least squares",
                       "IV", "IV std HAC", "IV std", "IV-LS z");
    for (std::size_t k = 0; k < f.parameters.size(); ++k) {
      const auto j = static_cast<Eigen::Index>(k);
      const double z = apart(f, j);
      out += fmt::format("  {:<26} {:<10} {:>13} {:>13} {:>11} {:>11} {:>8}\n", f.parameters[k].name,
                         f.parameters[k].unit, number(f.ls_value(j)), number(f.value(j)), number(f.hac_std(j)),
                         number(f.std(j)), std::isfinite(z) ? fmt::format("{:+.2f}", z) : "-");
    }
    out += fmt::format("  Durbin-Wu-Hausman: H = {}, {} dof, p = {:.3g} (level {}), Newey-West bandwidth {} rows\n",
                       number(f.dwh.statistic), f.dwh.degrees_of_freedom, f.dwh.p_value, f.dwh.level, f.dwh.bandwidth);
  }
  return out + "  verdict: " + f.statement() + "\n";
}

std::string iv_json(const residual::IvFit& f) {
  nlohmann::json parameters = nlohmann::json::array();
  for (std::size_t k = 0; k < f.parameters.size(); ++k) {
    const auto j = static_cast<Eigen::Index>(k);
    parameters.push_back({{"name", f.parameters[k].name},
                          {"unit", f.parameters[k].unit},
                          {"least_squares", finite(f.ls_value(j))},
                          {"iv", finite(f.value(j))},
                          {"iv_std", finite(f.std(j))},
                          {"iv_hac_std", finite(f.hac_std(j))},
                          {"difference_std", finite(f.difference_std(j))},
                          {"z", finite(apart(f, j))}});
  }
  return nlohmann::json{
      {"model", f.model},
      {"effects", f.effects},
      {"lag_rows", f.lag_rows},
      {"rows", f.rows},
      {"residual_rms", finite(f.residual_rms)},
      {"ls_residual_rms", finite(f.ls_residual_rms)},
      {"rows_without_partner", f.rows_without_partner},
      {"refused", f.refused},
      {"reason", f.reason},
      {"smallest_canonical_correlation", finite(f.smallest_canonical_correlation)},
      {"instrument_f", finite(f.instrument_f)},
      {"parameters", parameters},
      {"dwh",
       {{"statistic", finite(f.dwh.statistic)},
        {"degrees_of_freedom", f.dwh.degrees_of_freedom},
        {"p_value", finite(f.dwh.p_value)},
        {"level", f.dwh.level},
        {"bandwidth", f.dwh.bandwidth},
        {"rejects", f.dwh.rejects}}},
      {"replaces_least_squares", f.replaces_least_squares()},
      {"statement", f.statement()}}
      .dump();
}

}  // namespace dynid::report
