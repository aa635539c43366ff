#include "dynid/server/estimate_tables.hpp"

#include <algorithm>
#include <cmath>

#include "dynid/report/estimate_report.hpp"
#include "dynid/report/json.hpp"
#include "dynid/residual/simex_against_iv.hpp"

namespace dynid::server {

dds::EstimateTable table_of(const std::string& vehicle, const std::string& source,
                            const std::string& model,
                            const std::vector<model::ParameterInfo>& parameters,
                            const ls::WeightedEstimate& estimate) {
  std::vector<std::string> names, units;
  for (const auto& p : parameters) {
    names.push_back(p.name);
    units.push_back(p.unit);
  }
  dds::EstimateTable table =
      dds::make_estimate_table(vehicle, model, source, names, units, estimate.estimate);
  for (const auto& g : estimate.groups) table.groups.push_back({g.name, g.rows, g.residual_rms});
  dds::apply_verdict(table, model::classify_parameters(parameters, estimate.estimate,
                                                       model::column_norms(estimate.weighted)));
  return table;
}

namespace {

bool same_columns(const std::vector<model::ParameterInfo>& parameters,
                  const std::vector<model::ParameterInfo>& fitted, const Eigen::VectorXd& value) {
  if (fitted.size() != parameters.size() || value.size() != static_cast<Eigen::Index>(parameters.size()))
    return false;
  for (std::size_t k = 0; k < parameters.size(); ++k)
    if (fitted[k].name != parameters[k].name) return false;
  return true;
}

// The rows `replace` marks get `value` and `std` in place of least squares', which is kept beside
// them; the statuses are classified again on the new values; the table names `estimator`.
void replace_rows(dds::EstimateTable& table, const std::vector<model::ParameterInfo>& parameters,
                  const ls::WeightedEstimate& estimate, const Eigen::VectorXd& value, const Eigen::VectorXd& std,
                  const std::vector<bool>& replace, const char* estimator) {
  ls::WeightedEstimate replaced = estimate;
  ls::Estimate& e = replaced.estimate;
  for (Eigen::Index j = 0; j < e.value.size(); ++j) {
    if (!replace[static_cast<std::size_t>(j)]) continue;
    e.value(j) = value(j);
    e.standard_deviation(j) = std(j);
    e.relative_std_percent(j) = 100.0 * std(j) / std::abs(value(j));
  }
  // Only the rows (and the model's note) change: the fit's figures stay least squares', whose
  // residual the rows' weights come from.
  dds::EstimateTable by = table_of(table.vehicle, table.source, table.model, parameters, replaced);
  for (std::size_t k = 0; k < by.parameters.size(); ++k) {
    if (!replace[k]) continue;
    const auto j = static_cast<Eigen::Index>(k);
    by.parameters[k].least_squares_value = estimate.estimate.value(j);
    by.parameters[k].least_squares_std = estimate.estimate.standard_deviation(j);
  }
  table.parameters = std::move(by.parameters);
  table.not_excited = std::move(by.not_excited);
  table.estimator = estimator;
}

// Where IV replaced least squares: SIMEX takes every row IV took when Hausman's comparison says
// its noise model holds (residual/simex_against_iv.hpp); the bias test's line says which way.
void simex_in_place_of_iv(dds::EstimateTable& table, const std::vector<model::ParameterInfo>& parameters,
                          const ls::WeightedEstimate& estimate, const residual::SimexFit& simex,
                          const residual::IvFit& iv) {
  const residual::SimexAgainstIv comparison = residual::compare_simex_with_iv(iv, simex);
  if (!comparison.compared) return;
  table.bias_test += "; " + comparison.statement();
  if (!comparison.simex_stands) return;
  std::vector<bool> replace(parameters.size());
  for (std::size_t k = 0; k < replace.size(); ++k) {
    const auto j = static_cast<Eigen::Index>(k);
    replace[k] = std::isfinite(iv.value(j)) && std::isfinite(simex.value(j)) && std::isfinite(estimate.estimate.value(j));
  }
  replace_rows(table, parameters, estimate, simex.value, simex.std, replace, dds::kSimex);
}

}  // namespace

void apply_iv(dds::EstimateTable& table, const std::vector<model::ParameterInfo>& parameters,
              const ls::WeightedEstimate& estimate, const residual::IvFit& iv, std::uint64_t through) {
  if (!same_columns(parameters, iv.parameters, iv.value)) return;
  table.bias_test = iv.statement();
  table.bias_through = through;
  if (!iv.replaces_least_squares()) return;
  std::vector<bool> replace(parameters.size());
  for (std::size_t k = 0; k < replace.size(); ++k) {
    const auto j = static_cast<Eigen::Index>(k);
    replace[k] = std::isfinite(iv.value(j)) && std::isfinite(estimate.estimate.value(j));
  }
  replace_rows(table, parameters, estimate, iv.value, iv.hac_std, replace, dds::kInstrumentalVariables);
}

void apply_simex(dds::EstimateTable& table, const std::vector<model::ParameterInfo>& parameters,
                 const ls::WeightedEstimate& estimate, const residual::SimexFit& simex, const residual::IvFit* iv) {
  if (!same_columns(parameters, simex.parameters, simex.value)) return;
  if (table.estimator == dds::kInstrumentalVariables) {
    if (iv != nullptr) simex_in_place_of_iv(table, parameters, estimate, simex, *iv);
    return;
  }
  if (table.estimator != dds::kLeastSquares) return;
  std::vector<bool> replace(parameters.size());
  bool any = false;
  for (std::size_t k = 0; k < replace.size(); ++k) {
    const auto j = static_cast<Eigen::Index>(k);
    replace[k] = simex.corrected() && std::isfinite(simex.value(j)) && std::isfinite(estimate.estimate.value(j)) &&
                 table.parameters[k].status == ls::ParameterStatus::kIdentified;
    any = any || replace[k];
  }
  if (any) replace_rows(table, parameters, estimate, simex.value, simex.std, replace, dds::kSimex);
}

EstimateTables tables_of(const std::string& vehicle, const std::string& source,
                         const std::vector<ingest::ModelEstimate>& estimates,
                         const std::optional<std::string>& model) {
  EstimateTables out;
  for (const auto& e : estimates) {
    if (model && e.model != *model) continue;
    if (e.estimate)
      out.tables.push_back(table_of(vehicle, source, e.model, e.parameters, *e.estimate));
    else
      out.notes.push_back(e.model + ": " + (e.note.empty() ? "no estimate yet" : e.note));
  }
  return out;
}

report::ExcitationReport excitation_of(const std::string& vehicle, const std::string& run,
                                       const std::vector<ingest::ModelEstimate>& estimates) {
  report::ExcitationReport out{vehicle, run, {}, {}};
  const EstimateTables tables = tables_of(vehicle, run, estimates);
  out.notes = tables.notes;
  for (const dds::EstimateTable& table : tables.tables) {
    const auto e = std::find_if(estimates.begin(), estimates.end(),
                                [&](const ingest::ModelEstimate& m) { return m.model == table.model; });
    report::ModelExcitation m{table, {}};
    if (e != estimates.end())  // always: the tables are made from these estimates
      for (const auto& p : e->parameters) m.excited_by.push_back(p.excited_by);
    out.models.push_back(std::move(m));
  }
  return out;
}

std::string render(const EstimateTables& t, bool json) {
  if (json) {
    std::string notes;
    for (const auto& n : t.notes) notes += (notes.empty() ? "" : ",") + report::json_string(n);
    return "{\"tables\":" + report::estimates_json(t.tables) + ",\"notes\":[" + notes + "]}";
  }
  std::string text;
  for (const auto& table : t.tables) text += report::format_estimate_text(table) + "\n";
  for (const auto& n : t.notes) text += "note: " + n + "\n";
  return text;
}

}  // namespace dynid::server
