#include "dynid/server/estimate_tables.hpp"

#include <algorithm>
#include <cmath>

#include "dynid/model/registry.hpp"
#include "dynid/report/estimate_report.hpp"
#include "dynid/report/json.hpp"
#include "dynid/residual/publication.hpp"

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

const char* name_of(residual::PublishedEstimator estimator) {
  switch (estimator) {
    case residual::PublishedEstimator::kLeastSquares:
      return dds::kLeastSquares;
    case residual::PublishedEstimator::kInstrumentalVariables:
      return dds::kInstrumentalVariables;
    case residual::PublishedEstimator::kSimex:
      return dds::kSimex;
  }
  return dds::kLeastSquares;
}

}  // namespace

void apply_publication(dds::EstimateTable& table,
                       const std::vector<model::ParameterInfo>& parameters,
                       const ls::WeightedEstimate& estimate, const residual::IvFit* iv,
                       const residual::SimexFit* simex, std::uint64_t through) {
  const residual::Publication published = residual::publish(
      parameters, estimate.estimate, model::column_norms(estimate.weighted), iv, simex);
  if (published.bias_tested) {
    table.bias_test = published.bias_test;
    table.bias_through = through;
  }
  if (published.estimator == residual::PublishedEstimator::kLeastSquares) return;
  replace_rows(table, parameters, estimate, published.value, published.std, published.replaced,
               name_of(published.estimator));
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

void apply_health(EstimateTables& tables, const ingest::RunHealth& health,
                  const ingest::RunAnnouncement& announcement) {
  for (const ingest::ChannelFinding& f : health.findings)
    tables.notes.push_back("channel health: " + f.statement);
  for (dds::EstimateTable& table : tables.tables) {
    const auto spec =
        std::find_if(announcement.models.begin(), announcement.models.end(),
                     [&](const ingest::ModelSpec& m) { return m.model == table.model; });
    if (spec == announcement.models.end()) continue;  // a pool's or a reprocessing's own spec
    const auto model = model::make_model(spec->model, spec->constants);
    const auto reason = ingest::unhealthy_reason(health, announcement, *model, spec->effects);
    if (!reason) continue;
    table.not_identified = *reason;
    table.not_excited.clear();
    table.residual_verdict.clear();
    table.residual_statement.clear();
    table.bias_test.clear();
  }
}

report::ExcitationReport excitation_of(const std::string& vehicle, const std::string& run,
                                       const std::vector<ingest::ModelEstimate>& estimates,
                                       const ingest::RunHealth& health,
                                       const ingest::RunAnnouncement& announcement) {
  report::ExcitationReport out{vehicle, run, {}, {}};
  EstimateTables tables = tables_of(vehicle, run, estimates);
  apply_health(tables, health, announcement);
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
