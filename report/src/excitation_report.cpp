#include "dynid/report/excitation_report.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "dynid/report/estimate_report.hpp"
#include "dynid/report/json.hpp"
#include "dynid/report/text_wrap.hpp"

namespace dynid::report {
namespace {

using ls::ParameterStatus;

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& i : items) out += (out.empty() ? "" : ", ") + i;
  return out;
}

ManoeuvreNeed& need_for(std::vector<ManoeuvreNeed>& needs, const std::string& excited_by) {
  const auto it = std::find_if(needs.begin(), needs.end(),
                               [&](const ManoeuvreNeed& n) { return n.excited_by == excited_by; });
  if (it != needs.end()) return *it;
  needs.push_back({excited_by, {}, {}});
  return needs.back();
}

// The lines of one model: what it identifies, then each kind of what it cannot, with why.
std::string model_text(const ModelExcitation& m) {
  const dds::EstimateTable& t = m.table;
  // Read from an unhealthy channel: a manoeuvre cannot help, and nothing it says is a result.
  if (!t.not_identified.empty())
    return wrap_text("  " + t.model + ": ", "not identified: " + t.not_identified, 4);
  std::vector<std::string> identified, poor, not_excited, implausible, structure;
  for (std::size_t j = 0; j < t.parameters.size(); ++j) {
    const dds::ParameterEntry& p = t.parameters[j];
    const std::string& by = j < m.excited_by.size() ? m.excited_by[j] : std::string();
    switch (p.status) {
      case ParameterStatus::kIdentified: identified.push_back(p.name); break;
      case ParameterStatus::kPoorlyIdentified:
        poor.push_back(fmt::format("{} ({:.3g} %{})", p.name, p.relative_std_percent, by.empty() ? "" : "; needs more " + by));
        break;
      case ParameterStatus::kNotExcited: not_excited.push_back(p.name + (by.empty() ? "" : " (needs " + by + ")")); break;
      case ParameterStatus::kImplausible: implausible.push_back(p.name + " (" + p.reason + ")"); break;
      default: structure.push_back(p.name + " " + status_name(p.status) + (p.relation.empty() ? "" : " = " + p.relation));
    }
  }
  std::string out = wrap_text(
      fmt::format("  {}: identifies {} of {}", t.model, identified.size(), t.parameters.size()),
      identified.empty() ? "" : ": " + join(identified), 6);
  if (!t.not_excited.empty())
    out += wrap_text("    not excited by this run at all: ", t.not_excited, 6);
  if (!not_excited.empty()) out += wrap_text("    not excited: ", join(not_excited), 6);
  if (!poor.empty()) out += wrap_text("    poorly identified: ", join(poor), 6);
  if (!implausible.empty())
    out += wrap_text(
        "    implausible, a model error or a missing effect rather than the manoeuvre (dynid "
        "residual): ",
        join(implausible), 6);
  if (!structure.empty())
    out += wrap_text("    not separable by this model on any run: ", join(structure), 6);
  return out;
}

std::string strings_json(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& i : items) out += (out.empty() ? "" : ",") + json_string(i);
  return "[" + out + "]";
}

std::string model_json(const ModelExcitation& m) {
  std::string parameters;
  for (std::size_t j = 0; j < m.table.parameters.size(); ++j) {
    const dds::ParameterEntry& p = m.table.parameters[j];
    parameters += (parameters.empty() ? "" : ",") +
                  fmt::format("{{\"name\":{},\"status\":{},\"relative_std_percent\":{},\"reason\":{},\"excited_by\":{}}}",
                              json_string(p.name), json_string(status_name(p.status)),
                              json_number(p.relative_std_percent), json_string(p.reason),
                              json_string(j < m.excited_by.size() ? m.excited_by[j] : ""));
  }
  return fmt::format(
      "{{\"model\":{},\"not_excited\":{},\"not_identified\":{},\"parameters\":[{}]}}",
      json_string(m.table.model), json_string(m.table.not_excited),
      json_string(m.table.not_identified), parameters);
}

}  // namespace

std::vector<ManoeuvreNeed> manoeuvre_needs(const ExcitationReport& report) {
  std::vector<ManoeuvreNeed> needs;
  for (const ModelExcitation& m : report.models)
    for (std::size_t j = 0;
         m.table.not_identified.empty() && j < m.table.parameters.size() && j < m.excited_by.size();
         ++j) {
      const dds::ParameterEntry& p = m.table.parameters[j];
      if (m.excited_by[j].empty()) continue;
      const std::string name = m.table.model + "." + p.name;
      if (p.status == ParameterStatus::kNotExcited) need_for(needs, m.excited_by[j]).not_excited.push_back(name);
      if (p.status == ParameterStatus::kPoorlyIdentified)
        need_for(needs, m.excited_by[j]).poorly_identified.push_back(name);
    }
  return needs;
}

std::string format_excitation_text(const ExcitationReport& report) {
  std::string out = fmt::format("{} / run {}: what this run identifies\n", report.vehicle, report.run);
  for (const ModelExcitation& m : report.models) out += model_text(m);
  for (const std::string& n : report.notes) out += wrap_text("  ", n, 4);
  const std::vector<ManoeuvreNeed> needs = manoeuvre_needs(report);
  if (needs.empty()) return out + "Every parameter this run can excite is identified.\n";
  out += "To identify what this run cannot, a run with:\n";
  for (const ManoeuvreNeed& n : needs) {
    std::string what = join(n.not_excited);
    if (!n.poorly_identified.empty())
      what +=
          std::string(n.not_excited.empty() ? "" : "; ") + "better: " + join(n.poorly_identified);
    out += wrap_text("  " + n.excited_by + ": ", what, 4);
  }
  return out;
}

std::string excitation_json(const ExcitationReport& report) {
  std::string models, needs;
  for (const ModelExcitation& m : report.models) models += (models.empty() ? "" : ",") + model_json(m);
  for (const ManoeuvreNeed& n : manoeuvre_needs(report))
    needs += (needs.empty() ? "" : ",") +
             fmt::format("{{\"excited_by\":{},\"not_excited\":{},\"poorly_identified\":{}}}",
                         json_string(n.excited_by), strings_json(n.not_excited), strings_json(n.poorly_identified));
  return fmt::format("{{\"vehicle\":{},\"run\":{},\"models\":[{}],\"notes\":{},\"manoeuvres\":[{}]}}",
                     json_string(report.vehicle), json_string(report.run), models, strings_json(report.notes), needs);
}

}  // namespace dynid::report
