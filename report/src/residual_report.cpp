#include "dynid/report/residual_report.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cells.hpp"
#include "dynid/report/text_wrap.hpp"
#include "dynid/residual/road_profile.hpp"

namespace dynid::report {
namespace {

using detail::number;
std::string percent(double v) { return std::isfinite(v) ? fmt::format("{:.2f}", v) : "-"; }
// A road profile's knot parameter: <profile effect>[@group]@<distance>m. Other names with '@'
// (a dictionary term's coefficient in one equation group) are listed.
bool is_profile_knot(const residual::ParameterChange& p) {
  return residual::is_road_profile_effect(p.name.substr(0, p.name.find('@')));
}

// "not excited -> identified", or one status when the effect did not change it.
std::string status_change(const residual::ParameterChange& p) {
  const std::string after = ls::to_string(p.status_after);
  if (!p.status_before) return "-> " + after;
  const std::string before = ls::to_string(*p.status_before);
  return before == after ? after : before + " -> " + after;
}

}  // namespace

std::string format_screen_text(const residual::ScreenResult& screen, std::size_t top) {
  std::string out = fmt::format("model {} (effects: {})\n", screen.fit.model,
                                screen.fit.effects.empty() ? "none" : fmt::format("{}", fmt::join(screen.fit.effects, ", ")));
  for (const residual::GroupFit& g : screen.fit.groups)
    out += fmt::format("group {}: {} rows, residual RMS {} (held out {}), relative norm {:.4f}\n", g.group, g.rows,
                       number(g.rms_in_sample), number(g.rms_held_out), g.relative_norm_in_sample);
  out += fmt::format("{:<34} {:<12} {:>10} {:>11} {:>10} {:>9} {:>6}  {}\n", "candidate", "kind", "in-sample%",
                     "held-out%", "HAC Wald", "p", "folds", "significant");
  std::size_t shown = 0;
  std::map<std::string, std::size_t> untested;
  for (const residual::CandidateScore& c : screen.candidates) {
    if (!c.evaluated) {
      ++untested[c.note];
      continue;
    }
    if (shown++ >= top) continue;
    out += fmt::format("{:<34} {:<12} {:>10.2f} {:>11.2f} {:>10.3g} {:>9.2g} {:>3}/{:<2}  {}{}\n", c.effect,
                       residual::kind_name(c.kind), 100.0 * c.in_sample_drop, 100.0 * c.held_out_drop,
                       c.wald_statistic, c.p_value, c.folds_improved, c.folds,
                       c.significant ? "yes" : (c.testable ? "no" : "not identifiable"),
                       c.rows_outside > 0 ? fmt::format(" (on the declared rows; {} rows of its own left out)",
                                                        c.rows_outside)
                                          : "");
  }
  out += fmt::format("each candidate tested at level {:.2g} ({} candidates, family error rate {:.2g})\n",
                     screen.level, screen.tests, screen.level * screen.tests);
  if (shown > top) out += fmt::format("... and {} more tested\n", shown - top);
  for (const residual::CandidateScore& c : screen.candidates)
    if (!c.finding.empty()) out += fmt::format("{}: {}\n", c.effect, c.finding);
  for (const auto& [reason, count] : untested) out += fmt::format("not tested ({}): {}\n", count, reason);
  return out + "verdict: " + screen.verdict() + "\n";
}

std::string format_comparison_text(const residual::EffectComparison& c) {
  std::string out = fmt::format("add {} to {}\n", c.effect, c.before.model);
  out += fmt::format("{:<30} {:>14} {:>12} {:>9} | {:>14} {:>12} {:>9}  {}\n", "parameter", "before", "std", "err %",
                     "after", "std", "err %", "status");
  std::size_t knots = 0;
  for (const residual::ParameterChange& p : c.parameters) {
    if (is_profile_knot(p) && !p.truth) {
      ++knots;
      continue;
    }
    out += fmt::format("{:<30} {:>14} {:>12} {:>9} | {:>14} {:>12} {:>9}  {}\n", p.name, number(p.before),
                       number(p.std_before), percent(p.error_before_percent()), number(p.after),
                       number(p.std_after), percent(p.error_after_percent()), status_change(p));
  }
  if (knots > 0)
    out += fmt::format("({} road-profile knot parameters, every {:.0f} m, not listed)\n", knots,
                       c.after.profile_knots_m.size() > 1 ? c.after.profile_knots_m[1] : 0.0);
  for (std::size_t g = 0; g < c.before.groups.size() && g < c.after.groups.size(); ++g) {
    const residual::GroupFit& b = c.before.groups[g];
    const residual::GroupFit& a = c.after.groups[g];
    out += wrap_text(
        "group " + b.group + ": ",
        fmt::format("residual RMS in sample {} -> {}, held out {} -> {}; relative norm {:.4f} -> "
                    "{:.4f} (held out {:.4f} -> {:.4f})",
                    number(b.rms_in_sample), number(a.rms_in_sample), number(b.rms_held_out),
                    number(a.rms_held_out), b.relative_norm_in_sample, a.relative_norm_in_sample,
                    b.relative_norm_held_out, a.relative_norm_held_out),
        4);
  }
  return out + fmt::format("weighted residual RMS: {:.1f} % lower in sample, {:.1f} % lower held out\n",
                           100.0 * c.in_sample_drop(), 100.0 * c.held_out_drop());
}

// The block-sum tests of a group (noise_floor.hpp, 4.), one line.
std::string scales_text(const residual::GroupFloor& g) {
  if (g.scales.empty()) return {};
  std::string out = "  over blocks of";
  for (const residual::ScaleFloor& s : g.scales)
    out += fmt::format("{} {:.2g} s: ratio {:.3g} (up to {:.3g}{})", &s == &g.scales.front() ? "" : ";", s.block_seconds,
                       s.ratio, s.upper_ratio, s.at_floor ? "" : ", ABOVE");
  return out + "\n";
}

std::string format_diagnosis_text(const residual::Diagnosis& d, std::size_t top) {
  std::string out;
  for (const residual::GroupFloor& g : d.floor.groups)
    if (g.rows > 0)
      out +=
          wrap_text("group " + g.group + ": ",
                    fmt::format(
                        "residual RMS {} against a noise floor of {} (ratio of squares {:.3g}; at "
                        "the floor up to {:.3g}, {:.0f} effective rows)",
                        number(g.residual_rms), number(g.floor_rms), g.ratio, g.upper_ratio,
                        g.effective_rows),
                    4) +
          scales_text(g);
  std::string noise;
  for (const residual::ChannelNoise& c : d.floor.channels)
    if (std::find(d.floor.contributing.begin(), d.floor.contributing.end(), c.channel) != d.floor.contributing.end())
      noise += fmt::format("{}{} {:.4g} ({})", noise.empty() ? "" : ", ", c.channel, c.sigma, c.source);
  if (!noise.empty()) out += wrap_text("noise of the channels the rows read: ", noise, 4);
  out += format_screen_text(d.screen, top);
  for (const residual::RefusedCandidate& r : d.refused)
    out += wrap_text("refused: " + r.effect + ": ", r.reason, 4);
  for (const residual::Inseparable& i : d.inseparable) out += wrap_text("", i.statement(), 4);
  for (const residual::CorrelationFinding& f : d.signature.correlations)
    out += fmt::format("residual of {} correlates with {} at lag {:+.0f} ms: r = {:.2f} (bound {:.2f})\n", f.group,
                       f.channel, 1000.0 * f.lag_s, f.correlation, f.bound);
  return out + wrap_clauses("diagnosis: ", d.statement(), 4);
}

namespace {

// A model's name in the consistency table, with " (IV)" where its values are IV's.
std::string by_estimator(const std::string& model, const std::string& estimator) {
  return estimator.empty() || estimator == "least squares" ? model : model + " (" + estimator + ")";
}

}  // namespace

std::string format_consistency_text(const residual::Consistency& c, const std::vector<std::string>& left_out) {
  // The answer first, one finding per line; the comparisons after it are the evidence.
  std::string out = wrap_clauses("consistency: ", c.statement(), 2);
  if (!c.comparisons.empty())
    out += fmt::format("{:<22} {:<22} {:>14} {:>10} {:<22} {:>14} {:>10} {:>7}\n", "parameter", "model", "value", "std",
                       "against", "value", "std", "z");
  for (const residual::ParameterAgreement& a : c.comparisons)
    out += fmt::format("{:<22} {:<22} {:>14} {:>10} {:<22} {:>14} {:>10} {:>+7.2f}{}\n",
                       a.parameter + " [" + a.unit + "]", by_estimator(a.first, a.first_estimator),
                       number(a.first_value), number(a.first_std),
                       by_estimator(a.second, a.second_estimator), number(a.second_value),
                       a.second == residual::kReference ? "-" : number(a.second_std), a.z,
                       a.significant ? " *" : "");
  if (!c.comparisons.empty())
    out += fmt::format("(* beyond the level {:.2g}: family error rate 1 % over {} comparisons; std are HAC)\n", c.level,
                       c.tests);
  for (const std::string& n : c.not_compared) out += wrap_text("not compared: ", n, 4);
  for (const std::string& l : left_out) out += wrap_text("left out: ", l, 4);
  return out;
}

std::string format_trace_text(const residual::Trace& t) {
  std::string out = fmt::format("trace of {} (declared effects: {})\n", t.model,
                                t.declared.empty() ? "none" : fmt::format("{}", fmt::join(t.declared, ", ")));
  for (std::size_t i = 0; i < t.rounds.size(); ++i) {
    const residual::TraceRound& r = t.rounds[i];
    out += fmt::format("\n== round {} (effects: {}) ==\n", i + 1,
                       r.effects.empty() ? "none" : fmt::format("{}", fmt::join(r.effects, ", "))) +
           wrap_clauses("", r.diagnosis.statement(), 4);
    for (const residual::Inseparable& ins : r.diagnosis.inseparable)
      out += wrap_text("", ins.statement(), 4);
    if (r.added) out += format_comparison_text(*r.added);
  }
  const std::vector<std::string> added = t.added();
  return out +
         fmt::format("\nadded: {}\n",
                     added.empty() ? "nothing" : fmt::format("{}", fmt::join(added, ", "))) +
         wrap_text("stopped: ", t.stopped, 4);
}

namespace {

using nlohmann::json;

using detail::finite;

json sensor_agreement_json(const residual::SensorAgreement& a, bool reaches) {
  json compared = json::array();
  for (const residual::ComparedParameter& c : a.compared)
    compared.push_back({{"name", c.name},
                        {"unit", c.unit},
                        {"published", finite(c.published)},
                        {"published_std", finite(c.published_std)},
                        {"with_sensor", finite(c.with_sensor)},
                        {"with_sensor_std", finite(c.with_sensor_std)},
                        {"moved", finite(c.moved)}});
  return {{"effect", a.effect},   {"offsets", a.offsets},           {"estimator", a.estimator},
          {"compared", compared}, {"not_compared", a.not_compared}, {"bound", finite(a.bound)},
          {"agrees", a.agrees()}, {"reaches_its_floor", reaches},   {"statement", a.statement()}};
}

json candidate_json(const residual::CandidateScore& c) {
  return {{"effect", c.effect},
          {"kind", residual::kind_name(c.kind)},
          {"description", c.description},
          {"evaluated", c.evaluated},
          {"note", c.note},
          {"columns", c.columns},
          {"rows", c.rows},
          {"rows_outside", c.rows_outside},
          {"in_sample_drop", finite(c.in_sample_drop)},
          {"held_out_drop", finite(c.held_out_drop)},
          {"wald_statistic", finite(c.wald_statistic)},
          {"p_value", finite(c.p_value)},
          {"testable", c.testable},
          {"significant", c.significant},
          {"finding", c.finding},
          {"located_from_s", finite(c.located_from_s)},
          {"located_to_s", finite(c.located_to_s)},
          {"coefficient", finite(c.coefficient)},
          {"coefficient_std", finite(c.coefficient_std)},
          {"coefficient_unit", c.coefficient_unit},
          {"detectable", finite(c.detectable)}};
}

json scales_json(const residual::GroupFloor& g) {
  json out = json::array();
  for (const residual::ScaleFloor& s : g.scales)
    out.push_back({{"block_rows", s.block_rows},
                   {"block_seconds", finite(s.block_seconds)},
                   {"ratio", finite(s.ratio)},
                   {"upper_ratio", finite(s.upper_ratio)},
                   {"effective_blocks", finite(s.effective_blocks)},
                   {"at_floor", s.at_floor}});
  return out;
}

json diagnosis_object(const residual::Diagnosis& d) {
  json groups = json::array();
  for (const residual::GroupFloor& g : d.floor.groups)
    groups.push_back({{"group", g.group},
                      {"rows", g.rows},
                      {"residual_rms", finite(g.residual_rms)},
                      {"floor_rms", finite(g.floor_rms)},
                      {"ratio", finite(g.ratio)},
                      {"upper_ratio", finite(g.upper_ratio)},
                      {"log_ratio_std", finite(g.log_ratio_std)},
                      {"effective_rows", finite(g.effective_rows)},
                      {"scales", scales_json(g)},
                      {"at_floor", g.at_floor}});
  json noise = json::array();
  for (const residual::ChannelNoise& c : d.floor.channels)
    noise.push_back({{"channel", c.channel}, {"sigma", finite(c.sigma)}, {"source", c.source}});
  json candidates = json::array();
  for (const residual::CandidateScore& c : d.screen.candidates) candidates.push_back(candidate_json(c));
  json refused = json::array();
  for (const residual::RefusedCandidate& r : d.refused) refused.push_back({{"effect", r.effect}, {"reason", r.reason}});
  json inseparable = json::array();
  for (const residual::Inseparable& i : d.inseparable)
    inseparable.push_back({{"effect", i.effect},
                           {"identifiable", i.identifiable},
                           {"detectable", finite(i.detectable)},
                           {"unit", i.unit},
                           {"parameter", i.parameter},
                           {"shift", finite(i.shift)},
                           {"shift_relative", finite(i.shift_relative)},
                           {"shift_in_std", finite(i.shift_in_std)},
                           {"separated_by", i.separated_by},
                           {"statement", i.statement()}});
  json correlations = json::array();
  for (const residual::CorrelationFinding& f : d.signature.correlations)
    correlations.push_back({{"group", f.group},
                            {"channel", f.channel},
                            {"lag_s", f.lag_s},
                            {"correlation", finite(f.correlation)},
                            {"bound", finite(f.bound)}});
  return {
      {"model", d.screen.fit.model},
      {"effects", d.screen.fit.effects},
      {"verdict", residual::verdict_name(d.verdict)},
      {"statement", d.statement()},
      {"accepted", d.accepted ? json(d.accepted->effect) : json(nullptr)},
      // The accepted candidate explains a part only: its model stays above its own floor.
      {"partial", d.partial ? json({{"group", d.partial->group},
                                    {"ratio", finite(d.partial->ratio)},
                                    {"upper_ratio", finite(d.partial->upper_ratio)},
                                    {"masked", d.masked}})
                            : json(nullptr)},
      // Structure a better sensor shows under the declared floor, too small to matter: a note.
      {"hidden", d.hidden ? json({{"sensor", d.hidden->sensor},
                                  {"group", d.hidden->group},
                                  {"residual_rms", finite(d.hidden->residual_rms)},
                                  {"floor_rms", finite(d.hidden->floor_rms)},
                                  {"share", finite(d.hidden->share)},
                                  {"resolution", finite(d.hidden->resolution)},
                                  {"statement", d.hidden->statement()}})
                          : json(nullptr)},
      // A better sensor refused because it agrees with the published parameters.
      {"sensor_error",
       d.sensor_error ? sensor_agreement_json(*d.sensor_error, d.sensor_reaches) : json(nullptr)},
      {"floor", {{"groups", groups}, {"channels", noise}, {"contributing", d.floor.contributing}}},
      {"candidate_level", finite(d.screen.level)},
      {"candidates", candidates},
      {"refused", refused},
      {"inseparable", inseparable},
      {"implausible", d.implausible},
      {"signature",
       {{"correlations", correlations},
        {"span_group", d.signature.span_group},
        {"span_start_s", d.signature.span_start_s},
        {"span_end_s", d.signature.span_end_s},
        {"span_ratio", finite(d.signature.span_ratio)},
        {"peak_frequency_hz", finite(d.signature.peak_frequency_hz)}}}};
}

json fit_groups(const residual::ModelFit& f) {
  json out = json::array();
  for (const residual::GroupFit& g : f.groups)
    out.push_back({{"group", g.group},
                   {"rows", g.rows},
                   {"rms_in_sample", finite(g.rms_in_sample)},
                   {"rms_held_out", finite(g.rms_held_out)},
                   {"relative_norm_in_sample", finite(g.relative_norm_in_sample)},
                   {"relative_norm_held_out", finite(g.relative_norm_held_out)}});
  return out;
}

// The added effect's fitted contribution row by row, with the rows' run times (a road profile's:
// g sin(grade), centred): what a caller compares with an independent measurement of the effect.
json effect_series(const residual::ModelFit& after) {
  json out = json::array();
  for (const residual::ResidualSeries& s : after.series) {
    if (s.effect_contribution.size() != static_cast<Eigen::Index>(s.time_s.size())) continue;
    json contribution = json::array();
    for (Eigen::Index i = 0; i < s.effect_contribution.size(); ++i) contribution.push_back(finite(s.effect_contribution(i)));
    out.push_back({{"group", s.group}, {"time_s", s.time_s}, {"contribution", contribution}});
  }
  return out;
}

json comparison_object(const residual::EffectComparison& c, bool series) {
  json parameters = json::array();
  for (const residual::ParameterChange& p : c.parameters)
    parameters.push_back({{"name", p.name},
                          {"unit", p.unit},
                          {"before", finite(p.before)},
                          {"std_before", finite(p.std_before)},
                          {"after", finite(p.after)},
                          {"std_after", finite(p.std_after)},
                          {"reference", p.truth ? finite(*p.truth) : json(nullptr)},
                          {"error_before_percent", finite(p.error_before_percent())},
                          {"error_after_percent", finite(p.error_after_percent())},
                          {"status_before", p.status_before ? json(ls::to_string(*p.status_before)) : json(nullptr)},
                          {"status_after", ls::to_string(p.status_after)}});
  json out{{"effect", c.effect},
           {"parameters", parameters},
           {"groups_before", fit_groups(c.before)},
           {"groups_after", fit_groups(c.after)},
           {"in_sample_drop", finite(c.in_sample_drop())},
           {"held_out_drop", finite(c.held_out_drop())}};
  if (series) out["effect_series"] = effect_series(c.after);
  return out;
}

}  // namespace

std::string diagnosis_json(const residual::Diagnosis& d) { return diagnosis_object(d).dump(); }
std::string comparison_json(const residual::EffectComparison& c, bool series) {
  return comparison_object(c, series).dump();
}

std::string consistency_json(const residual::Consistency& c, const std::vector<std::string>& left_out) {
  json comparisons = json::array();
  for (const residual::ParameterAgreement& a : c.comparisons)
    comparisons.push_back({{"parameter", a.parameter},
                           {"unit", a.unit},
                           {"model", a.first},
                           {"estimator", a.first_estimator},
                           {"value", finite(a.first_value)},
                           {"std", finite(a.first_std)},
                           {"against", a.second},
                           {"against_estimator", a.second_estimator},
                           {"against_value", finite(a.second_value)},
                           {"against_std", finite(a.second_std)},
                           {"z", finite(a.z)},
                           {"p_value", finite(a.p_value)},
                           {"significant", a.significant}});
  json scales = json::array();
  for (const residual::ScaleFinding& f : c.scales)
    scales.push_back({{"model", f.first},
                      {"against", f.second},
                      {"parameters", f.parameters},
                      {"ratio", finite(f.ratio)},
                      {"ratio_std", finite(f.ratio_std)},
                      {"homogeneity_p", finite(f.homogeneity_p)},
                      {"one_ratio", f.one_ratio},
                      {"off", f.off},
                      {"statement", f.statement}});
  return json{{"consistent", c.consistent()},   {"level", finite(c.level)},
              {"comparisons", comparisons},     {"scales", scales},
              {"not_compared", c.not_compared}, {"left_out", left_out},
              {"statement", c.statement()}}
      .dump();
}

std::string trace_json(const residual::Trace& t, bool series) {
  json rounds = json::array();
  for (const residual::TraceRound& r : t.rounds)
    rounds.push_back({{"effects", r.effects},
                      {"diagnosis", diagnosis_object(r.diagnosis)},
                      {"added", r.added ? comparison_object(*r.added, series) : json(nullptr)}});
  return json{{"model", t.model}, {"declared", t.declared}, {"rounds", rounds}, {"added", t.added()},
              {"stopped", t.stopped}}
      .dump();
}

}  // namespace dynid::report
