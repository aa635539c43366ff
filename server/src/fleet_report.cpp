#include "dynid/server/fleet_report.hpp"

#include <fmt/format.h>

#include <cmath>

#include "dynid/report/json.hpp"

namespace dynid::server {

namespace {

using report::json_number;
using report::json_string;

std::string join(const std::vector<std::string>& items, const std::string& separator,
                 std::string (*quote)(std::string_view) = nullptr) {
  std::string out;
  for (const auto& item : items) out += (out.empty() ? "" : separator) + (quote ? quote(item) : item);
  return out;
}

std::string label(const ls::FleetParameterEstimate& p) {
  return p.vehicle.empty() ? p.name : p.vehicle + "/" + p.name;
}

std::string text(const FleetReply& r) {
  const ls::FleetEstimate& e = r.estimate;
  std::string out = fmt::format("fleet {} over {} vehicles, shared: {}\n", r.model, e.vehicles.size(),
                                join(r.shared, ", "));
  out += fmt::format("rows {} (sparse system {} x {}), rank {}, sigma {:.6g}, residual {:.6g}\n", e.rows,
                     e.sparse_rows, e.unknowns, e.rank, e.sigma, e.residual_norm);
  if (e.rank_deficient())
    out += fmt::format("RANK DEFICIENT: rank {} of {} (tau {:.3g}); unidentified parameters have no value, "
                       "the others are conditional on them being 0\n",
                       e.rank, e.unknowns, e.tolerance);
  out += fmt::format("{:<32} {:<10} {:>16} {:>12} {:>9}  {}\n", "parameter", "unit", "value", "std", "std %", "status");
  for (const auto& p : e.parameters)
    out += fmt::format("{:<32} {:<10} {:>16.8g} {:>12.4g} {:>9.3g}  {}\n", label(p), p.unit, p.value,
                       p.standard_deviation, 100.0 * p.standard_deviation / std::abs(p.value),
                       ls::to_string(p.status));
  out += fmt::format("{:<24} {:>10} {:>14}  {}\n", "vehicle", "rows", "residual rms", "runs");
  for (std::size_t v = 0; v < e.vehicles.size(); ++v)
    out += fmt::format("{:<24} {:>10} {:>14.6g}  {}\n", e.vehicles[v].vehicle, e.vehicles[v].rows,
                       e.vehicles[v].residual_rms, join(r.runs.at(v), ","));
  return out;
}

std::string json(const FleetReply& r) {
  const ls::FleetEstimate& e = r.estimate;
  std::vector<std::string> parameters, vehicles;
  for (const auto& p : e.parameters)
    parameters.push_back(fmt::format("{{\"vehicle\":{},\"name\":{},\"unit\":{},\"value\":{},\"std\":{},\"status\":{}}}",
                                     p.vehicle.empty() ? "null" : json_string(p.vehicle), json_string(p.name),
                                     json_string(p.unit), json_number(p.value), json_number(p.standard_deviation),
                                     json_string(ls::to_string(p.status))));
  for (std::size_t v = 0; v < e.vehicles.size(); ++v)
    vehicles.push_back(fmt::format("{{\"vehicle\":{},\"runs\":[{}],\"rows\":{},\"residual_rms\":{}}}",
                                   json_string(e.vehicles[v].vehicle), join(r.runs.at(v), ",", json_string),
                                   e.vehicles[v].rows, json_number(e.vehicles[v].residual_rms)));
  return fmt::format(
      "{{\"model\":{},\"shared\":[{}],\"rows\":{},\"sparse_rows\":{},\"unknowns\":{},\"rank\":{},"
      "\"rank_deficient\":{},\"tolerance\":{},\"sigma\":{},\"residual_norm\":{},\"parameters\":[{}],"
      "\"vehicles\":[{}]}}",
      json_string(r.model), join(r.shared, ",", json_string), e.rows, e.sparse_rows, e.unknowns, e.rank,
      e.rank_deficient(), json_number(e.tolerance), json_number(e.sigma), json_number(e.residual_norm),
      join(parameters, ","), join(vehicles, ","));
}

}  // namespace

std::string render_fleet(const FleetReply& reply, bool as_json) {
  return as_json ? json(reply) : text(reply);
}

}  // namespace dynid::server
