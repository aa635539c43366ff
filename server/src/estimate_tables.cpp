#include "dynid/server/estimate_tables.hpp"

#include <algorithm>
#include <cmath>

#include "dynid/report/estimate_report.hpp"
#include "dynid/report/json.hpp"

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

bool same_columns(const std::vector<model::ParameterInfo>& parameters, const residual::IvFit& iv) {
  if (iv.parameters.size() != parameters.size() || iv.value.size() != static_cast<Eigen::Index>(parameters.size()))
    return false;
  for (std::size_t k = 0; k < parameters.size(); ++k)
    if (iv.parameters[k].name != parameters[k].name) return false;
  return true;
}

}  // namespace

void apply_iv(dds::EstimateTable& table, const std::vector<model::ParameterInfo>& parameters,
              const ls::WeightedEstimate& estimate, const residual::IvFit& iv, std::uint64_t through) {
  if (!same_columns(parameters, iv)) return;
  table.bias_test = iv.statement();
  table.bias_through = through;
  if (!iv.replaces_least_squares()) return;
  ls::WeightedEstimate replaced = estimate;
  ls::Estimate& e = replaced.estimate;
  for (Eigen::Index j = 0; j < e.value.size(); ++j) {
    if (!std::isfinite(iv.value(j)) || !std::isfinite(e.value(j))) continue;
    e.value(j) = iv.value(j);
    e.standard_deviation(j) = iv.hac_std(j);
    e.relative_std_percent(j) = 100.0 * iv.hac_std(j) / std::abs(iv.value(j));
  }
  // Only the rows (and the model's note) change: the fit's figures stay least squares', whose
  // residual the rows' weights come from.
  dds::EstimateTable by_iv = table_of(table.vehicle, table.source, table.model, parameters, replaced);
  for (std::size_t k = 0; k < by_iv.parameters.size(); ++k) {
    const auto j = static_cast<Eigen::Index>(k);
    if (!std::isfinite(iv.value(j)) || !std::isfinite(estimate.estimate.value(j))) continue;
    by_iv.parameters[k].least_squares_value = estimate.estimate.value(j);
    by_iv.parameters[k].least_squares_std = estimate.estimate.standard_deviation(j);
  }
  table.parameters = std::move(by_iv.parameters);
  table.not_excited = std::move(by_iv.not_excited);
  table.estimator = dds::kInstrumentalVariables;
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
