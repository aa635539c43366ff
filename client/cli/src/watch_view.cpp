#include "dynid/cli/watch_view.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "dynid/report/estimate_report.hpp"
#include "dynid/report/json.hpp"

namespace dynid::cli {

namespace {

std::string cell(double value) {
  if (std::isnan(value)) return "-";
  return fmt::format("{:.6g}", value);
}

// The move since the previous publication; nullopt when there is none to compare with.
std::optional<double> change_of(const std::map<std::string, double>& before, const dds::ParameterEntry& p) {
  const auto it = before.find(p.name);
  if (it == before.end() || std::isnan(it->second) || std::isnan(p.value)) return std::nullopt;
  return p.value - it->second;
}

double in_std(double change, const dds::ParameterEntry& p) {
  return p.standard_deviation > 0.0 ? change / p.standard_deviation
                                    : std::numeric_limits<double>::quiet_NaN();
}

std::string change_text(const std::map<std::string, double>& before, const dds::ParameterEntry& p) {
  const auto change = change_of(before, p);
  if (!change) return std::isnan(p.value) ? "-" : "new";
  if (*change == 0.0) return "0";
  const double sigmas = in_std(*change, p);
  return std::isnan(sigmas) ? fmt::format("{:+.3g}", *change)
                            : fmt::format("{:+.3g} ({:+.2g} std)", *change, sigmas);
}

}  // namespace

std::size_t line_count(const std::string& text) {
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

std::map<std::string, double> WatchView::advance(const dds::EstimateTable& table) {
  auto& slot = previous_[table.model];
  std::map<std::string, double> before = slot;
  slot.clear();
  for (const auto& p : table.parameters) slot[p.name] = p.value;
  return before;
}

std::string WatchView::text(const dds::EstimateTable& t) {
  const auto before = advance(t);
  std::string out = fmt::format("{} / {}  source {}, revision {}, rows {}\n", t.vehicle, t.model,
                                t.source, t.revision, t.rows);
  if (!t.not_excited.empty()) return out + "  not excited by this run: " + t.not_excited + "\n";
  if (!t.residual_verdict.empty())
    out += fmt::format("  residual (chunks through #{}): {}\n", t.residual_through, t.residual_verdict);
  if (t.estimator == dds::kSimex)
    out += fmt::format("  values by SIMEX (chunks through #{}): least squares corrected for the sensor noise\n",
                       t.bias_through);
  else if (t.estimator != dds::kLeastSquares)
    out += fmt::format("  values by {} (chunks through #{}): least squares is biased on this run\n", t.estimator,
                       t.bias_through);
  out += fmt::format("  {:<26} {:>12} {:>11} {:>8}  {:<17}  {}\n", "parameter", "value", "std",
                     "rel.std%", "status", "moved since last");
  for (const auto& p : t.parameters)
    out += fmt::format("  {:<26} {:>12} {:>11} {:>8}  {:<17}  {}\n", p.name, cell(p.value),
                       cell(p.standard_deviation), cell(p.relative_std_percent),
                       report::status_name(p.status), change_text(before, p));
  return out;
}

std::string WatchView::redraw(const dds::EstimateTable& table) {
  const std::string block = text(table);
  std::string out;
  if (shown_lines_ > 0) out = fmt::format("\x1b[{}A\x1b[J", shown_lines_);
  shown_lines_ = line_count(block);
  return out + block;
}

std::string WatchView::json_line(const dds::EstimateTable& t) {
  using report::json_number;
  using report::json_string;
  const auto before = advance(t);
  std::string parameters;
  for (const auto& p : t.parameters) {
    const auto change = change_of(before, p);
    parameters += fmt::format(
        "{}{{\"name\":{},\"unit\":{},\"value\":{},\"std\":{},\"relative_std_percent\":{},"
        "\"status\":{},\"reason\":{},\"change\":{},\"change_in_std\":{}}}",
        parameters.empty() ? "" : ",", json_string(p.name), json_string(p.unit),
        json_number(p.value), json_number(p.standard_deviation),
        json_number(p.relative_std_percent), json_string(report::status_name(p.status)),
        json_string(p.reason), change ? json_number(*change) : "null",
        change ? json_number(in_std(*change, p)) : "null");
  }
  return fmt::format(
      "{{\"vehicle\":{},\"model\":{},\"source\":{},\"revision\":{},\"rows\":{},"
      "\"not_excited\":{},\"residual_verdict\":{},\"residual_statement\":{},\"residual_through\":{},"
      "\"estimator\":{},\"bias_test\":{},\"bias_through\":{},\"parameters\":[{}]}}\n",
      json_string(t.vehicle), json_string(t.model), json_string(t.source), t.revision, t.rows,
      json_string(t.not_excited), json_string(t.residual_verdict), json_string(t.residual_statement),
      t.residual_through, json_string(t.estimator), json_string(t.bias_test), t.bias_through, parameters);
}

}  // namespace dynid::cli
