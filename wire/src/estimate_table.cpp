#include "dynid/dds/estimate_table.hpp"

#include <algorithm>

#include "dynid/error.hpp"

namespace dynid::dds {

namespace {

/// The relation of a regrouped parameter (its position among the base columns), else "".
std::string relation_of(const ls::BaseParameterAnalysis& structure, Eigen::Index parameter,
                        const std::vector<std::string>& names) {
  const auto& base = structure.base;
  const auto found = std::find(base.begin(), base.end(), parameter);
  if (found == base.end()) return {};
  return structure.relation(found - base.begin(), names);
}

}  // namespace

EstimateTable make_estimate_table(const std::string& vehicle, const std::string& model,
                                  const std::string& source,
                                  const std::vector<std::string>& names,
                                  const std::vector<std::string>& units,
                                  const ls::Estimate& estimate) {
  const auto n = static_cast<std::size_t>(estimate.value.size());
  if (names.size() != n || units.size() != n || estimate.structure.status.size() != n)
    throw InputError("make_estimate_table " + vehicle + "/" + model + ": " +
                     std::to_string(names.size()) + " names and " + std::to_string(units.size()) +
                     " units for " + std::to_string(n) + " parameters");
  EstimateTable table;
  table.vehicle = vehicle;
  table.model = model;
  table.source = source;
  for (std::size_t j = 0; j < n; ++j) {
    const auto index = static_cast<Eigen::Index>(j);
    const auto status = estimate.structure.status[j];
    table.parameters.push_back(
        {names[j], units[j], estimate.value(index), estimate.standard_deviation(index),
         estimate.relative_std_percent(index), status,
         status == ls::ParameterStatus::kRegrouped ? relation_of(estimate.structure, index, names)
                                                   : std::string()});
  }
  table.rows = estimate.rows;
  table.effective_rows = estimate.effective_rows;
  table.sigma = estimate.sigma;
  table.condition_number = estimate.condition_number;
  table.residual_rms = estimate.residual_rms;
  table.relative_residual_norm = estimate.relative_residual_norm;
  return table;
}

void apply_verdict(EstimateTable& table, const model::ModelVerdict& verdict) {
  if (verdict.parameters.size() != table.parameters.size())
    throw InputError("apply_verdict " + table.vehicle + "/" + table.model + ": " +
                     std::to_string(verdict.parameters.size()) + " verdicts for " +
                     std::to_string(table.parameters.size()) + " parameters");
  for (std::size_t j = 0; j < verdict.parameters.size(); ++j) {
    table.parameters[j].status = verdict.parameters[j].status;
    table.parameters[j].reason = verdict.parameters[j].reason;
  }
  table.not_excited = verdict.not_excited;
}

}  // namespace dynid::dds
