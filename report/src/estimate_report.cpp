#include "dynid/report/estimate_report.hpp"

#include <fmt/format.h>

#include <cmath>
#include <string>
#include <vector>

#include "dynid/report/json.hpp"
#include "dynid/report/text_wrap.hpp"

namespace dynid::report {

namespace {

// "-" where the data cannot identify a value (NaN); 6 significant digits otherwise.
std::string cell(double value) {
  if (std::isnan(value)) return "-";
  return fmt::format("{:.6g}", value);
}

std::string parameter_line(const dds::ParameterEntry& p) {
  std::string line =
      fmt::format("  {:<24} {:<12} {:>14} {:>12} {:>9} {:<17}", p.name, p.unit, cell(p.value),
                  cell(p.standard_deviation), cell(p.relative_std_percent), status_name(p.status));
  if (!p.relation.empty()) line += "  = " + p.relation;
  if (!p.reason.empty()) line += "  " + p.reason;
  if (!std::isnan(p.least_squares_value))
    line += fmt::format("  (least squares {} +- {})", cell(p.least_squares_value),
                        cell(p.least_squares_std));
  while (!line.empty() && line.back() == ' ') line.pop_back();
  return line + "\n";
}

// On a table whose model reads an unhealthy channel every row is "not identified" with the
// table's reason: its value is a number, not an estimate.
std::string parameter_json(const dds::ParameterEntry& p, const std::string& not_identified) {
  const bool judged = not_identified.empty();
  return fmt::format(
      "{{\"name\":{},\"unit\":{},\"value\":{},\"std\":{},\"relative_std_percent\":{},"
      "\"status\":{},\"relation\":{},\"reason\":{},\"least_squares_value\":{},\"least_squares_"
      "std\":{}}}",
      json_string(p.name), json_string(p.unit), json_number(p.value),
      json_number(p.standard_deviation), json_number(p.relative_std_percent),
      json_string(judged ? status_name(p.status) : "not identified"), json_string(p.relation),
      json_string(judged ? p.reason : not_identified), json_number(p.least_squares_value),
      json_number(p.least_squares_std));
}

// What the live verdict says the model lacks, in a few words ("" without a verdict): the
// explaining effect by name, nothing, or something no candidate names. Diagnosis::statement()
// is "<verdict>: ...; <effect> (<kind>...) explains it..." for an explained residual.
std::string lacks(const dds::EstimateTable& t) {
  const std::vector<std::string> parts = clauses(t.residual_statement);
  if (t.residual_verdict == "adequate")
    return parts.front().find("is at the noise floor") != std::string::npos
               ? "lacks nothing its noise would not hide"
               : "lacks nothing, but a declared signal is in error";
  if (t.residual_verdict == "explained" && parts.size() > 1)
    return "lacks " + parts[1].substr(0, parts[1].find(' '));
  if (t.residual_verdict == "structure left")
    return "lacks something no candidate effect explains in full";
  return {};
}

// The model's answer in one line, before its table: what it lacks, then what the run identifies.
std::string headline(const dds::EstimateTable& t) {
  std::size_t identified = 0;
  std::string implausible;
  for (const auto& p : t.parameters) {
    if (p.status == ls::ParameterStatus::kIdentified) ++identified;
    if (p.status == ls::ParameterStatus::kImplausible)
      implausible += (implausible.empty() ? "" : ", ") + p.name;
  }
  std::string out = fmt::format("{} of {} parameters identified", identified, t.parameters.size());
  if (!implausible.empty()) out += "; implausible: " + implausible;
  const std::string what = lacks(t);
  return wrap_text("  answer: ", what.empty() ? out : what + "; " + out, 4);
}

}  // namespace

const char* status_name(ls::ParameterStatus status) {
  switch (status) {
    case ls::ParameterStatus::kIdentified:
      return "identified";
    case ls::ParameterStatus::kRegrouped:
      return "regrouped";
    case ls::ParameterStatus::kDependent:
      return "dependent";
    case ls::ParameterStatus::kEliminated:
      return "eliminated";
    case ls::ParameterStatus::kPoorlyIdentified:
      return "poorly identified";
    case ls::ParameterStatus::kNotExcited:
      return "not excited";
    case ls::ParameterStatus::kImplausible:
      return "implausible";
  }
  return "unknown";
}

std::string format_estimate_text(const dds::EstimateTable& t) {
  // Revision 0: a table no publication carried (a reprocessing, a stored history).
  std::string out =
      t.revision == 0
          ? fmt::format("{} / {}  ({}, not published)\n", t.vehicle, t.model, t.source)
          : fmt::format("{} / {}  ({}, revision {})\n", t.vehicle, t.model, t.source, t.revision);
  // A model read from an unhealthy channel, or one the run does not excite: one line, no
  // numbers that would read as estimates.
  if (!t.not_identified.empty())
    return out +
           wrap_text("  not identified: ",
                     fmt::format("{} ({} rows; --json has the numbers)", t.not_identified, t.rows),
                     4);
  if (!t.not_excited.empty())
    return out +
           wrap_text("  not excited by this run: ",
                     fmt::format("{} ({} rows; --json has the numbers)", t.not_excited, t.rows), 4);
  out += headline(t);
  if (t.estimator == dds::kSimex)
    out +=
        "  values by SIMEX where marked (least squares corrected for the measured sensor noise)\n";
  else if (t.estimator != dds::kLeastSquares)
    out += fmt::format(
        "  values by {} (least squares is biased on this run: see the bias test below)\n",
        t.estimator);
  out += fmt::format("  {:<24} {:<12} {:>14} {:>12} {:>9} {}\n", "parameter", "unit", "value",
                     "std", "rel.std%", "status");
  for (const auto& p : t.parameters) out += parameter_line(p);
  out += fmt::format("  rows {}  sigma {}  cond {}  residual RMS {}  relative residual {}\n",
                     t.rows, cell(t.sigma), cell(t.condition_number), cell(t.residual_rms),
                     cell(t.relative_residual_norm));
  for (const auto& g : t.groups)
    out += fmt::format("  group {:<28} rows {:>8}  residual RMS {}\n", g.group, g.rows,
                       cell(g.residual_rms));
  if (!t.residual_verdict.empty()) {
    // The answer first; its evidence (refused candidates, the residual's signature) is in the
    // JSON and in `dynid residual`, which prints each on its own line.
    const std::vector<std::string> parts = clauses(t.residual_statement);
    out += wrap_text(fmt::format("  residual loop (chunks through #{}): ", t.residual_through),
                     parts.front(), 4);
    if (parts.size() > 1)
      out += wrap_text("    ",
                       fmt::format("and {} more finding{} (`dynid residual --model {}`, or --json)",
                                   parts.size() - 1, parts.size() > 2 ? "s" : "", t.model),
                       4);
  }
  if (!t.bias_test.empty())
    out += wrap_text(fmt::format("  bias test (chunks through #{}): ", t.bias_through), t.bias_test,
                     4);
  return out;
}

std::string estimate_json(const dds::EstimateTable& t) {
  std::string parameters;
  for (const auto& p : t.parameters)
    parameters += (parameters.empty() ? "" : ",") + parameter_json(p, t.not_identified);
  std::string groups;
  for (const auto& g : t.groups)
    groups += (groups.empty() ? "" : ",") +
              fmt::format("{{\"group\":{},\"rows\":{},\"residual_rms\":{}}}", json_string(g.group),
                          g.rows, json_number(g.residual_rms));
  return fmt::format(
      "{{\"vehicle\":{},\"model\":{},\"source\":{},\"revision\":{},\"parameters\":[{}],"
      "\"rows\":{},\"effective_rows\":{},\"sigma\":{},\"condition_number\":{},"
      "\"residual_rms\":{},\"relative_residual_norm\":{},\"groups\":[{}],\"not_excited\":{},\"not_"
      "identified\":{},"
      "\"residual_verdict\":{},\"residual_statement\":{},\"residual_through\":{},"
      "\"estimator\":{},\"bias_test\":{},\"bias_through\":{}}}",
      json_string(t.vehicle), json_string(t.model), json_string(t.source), t.revision, parameters,
      t.rows, json_number(t.effective_rows), json_number(t.sigma), json_number(t.condition_number),
      json_number(t.residual_rms), json_number(t.relative_residual_norm), groups,
      json_string(t.not_excited), json_string(t.not_identified), json_string(t.residual_verdict),
      json_string(t.residual_statement), t.residual_through, json_string(t.estimator),
      json_string(t.bias_test), t.bias_through);
}

std::string estimates_json(const std::vector<dds::EstimateTable>& tables) {
  std::string out = "[";
  for (std::size_t k = 0; k < tables.size(); ++k) out += (k ? "," : "") + estimate_json(tables[k]);
  return out + "]";
}

}  // namespace dynid::report
