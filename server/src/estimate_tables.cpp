#include "dynid/server/estimate_tables.hpp"

#include <algorithm>

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
