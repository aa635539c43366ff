#include "dynid/server/residual_requests.hpp"

#include <algorithm>
#include <map>
#include <memory>
#include <set>

#include "dynid/error.hpp"
#include "dynid/ingest/channel_health.hpp"
#include "dynid/ingest/recorded_run.hpp"
#include "dynid/model/registry.hpp"
#include "dynid/report/iv_report.hpp"
#include "dynid/report/json.hpp"
#include "dynid/report/residual_html.hpp"
#include "dynid/report/residual_report.hpp"
#include "dynid/report/simex_report.hpp"
#include "dynid/residual/consistency.hpp"
#include "dynid/residual/diagnosis.hpp"
#include "dynid/residual/effect_comparison.hpp"
#include "dynid/residual/effect_screen.hpp"
#include "dynid/residual/model_fit.hpp"
#include "dynid/residual/publication.hpp"
#include "dynid/residual/trace.hpp"
#include "dynid/server/export_request.hpp"

namespace dynid::server {
namespace {

const ingest::ModelSpec& announced_model(const ingest::RunAnnouncement& a, const std::string& model) {
  for (const ingest::ModelSpec& spec : a.models)
    if (spec.model == model) return spec;
  std::string known;
  for (const ingest::ModelSpec& spec : a.models) known += (known.empty() ? "" : ", ") + spec.model;
  throw InputError("run " + a.vehicle + "/" + a.run + " has no model '" + model + "' (its models: " + known + ")");
}

// A reference value must name a parameter that a model of the request has, declared or through
// one of its candidate effects: a misspelt name would otherwise be ignored and the report would
// print no error where the engineer expects one. One model's trace takes its parameters' names;
// consistency, across models, the quantity a parameter measures where it declares one
// (ParameterInfo::reference_key: "ax_sensor_scale", not the "sensor_scale" of two sensors).
void check_reference_names(const std::map<std::string, double>& reference,
                           const std::vector<std::unique_ptr<model::Model>>& models,
                           bool by_quantity) {
  std::set<std::string> known;
  std::string owners;
  const auto key = [by_quantity](const model::ParameterInfo& p) {
    return by_quantity ? p.reference_key() : p.name;
  };
  for (const auto& m : models) {
    for (const model::ParameterInfo& p : m->parameters()) known.insert(key(p));
    for (const model::Effect& e : m->candidate_effects())
      for (const model::ParameterInfo& p : e.parameters) known.insert(key(p));
    owners += (owners.empty() ? "" : ", ") + m->name();
  }
  std::string unknown;
  for (const auto& entry : reference)
    if (known.count(entry.first) == 0)
      unknown += (unknown.empty() ? "'" : ", '") + entry.first + "'";
  if (unknown.empty()) return;
  std::string names;
  for (const auto& name : known) names += (names.empty() ? "" : ", ") + name;
  throw InputError("--reference " + unknown + ": no parameter of " + owners +
                   " or their effects has this " + (by_quantity ? "quantity or name (" : "name (") +
                   names + ")");
}

}  // namespace

namespace {

ResidualReply diagnosis_reply(const residual::Diagnosis& d, const std::string& title, const std::string& format) {
  if (format == "json") return {report::diagnosis_json(d), "application/json"};
  if (format == "html") {
    report::HtmlReportInput input{title, &d.screen, nullptr};
    input.diagnosis = &d;
    return {report::residual_html(input), "text/html"};
  }
  return {report::format_diagnosis_text(d), "text/plain"};
}

ResidualReply trace_reply(const residual::Trace& t, const std::string& title,
                          const std::string& format, bool series) {
  if (format == "json") return {report::trace_json(t, series), "application/json"};
  if (format == "html") {
    const residual::TraceRound* last_added = nullptr;
    for (const residual::TraceRound& r : t.rounds)
      if (r.added) last_added = &r;
    const residual::TraceRound& last = t.rounds.back();
    const residual::CandidateScore* found =
        last_added != nullptr && last_added->diagnosis.accepted ? &*last_added->diagnosis.accepted : nullptr;
    report::HtmlReportInput input{title + " (trace: " + t.stopped + ")", &last.diagnosis.screen,
                                  last_added != nullptr ? &*last_added->added : nullptr, found};
    input.diagnosis = &last.diagnosis;
    return {report::residual_html(input), "text/html"};
  }
  return {report::format_trace_text(t), "text/plain"};
}

// The reply for a model read from an unhealthy channel: one line in place of any judgement.
ResidualReply not_identified_reply(const std::string& title, const std::string& model,
                                   const std::string& reason, const std::string& format) {
  const std::string line = ingest::not_identified(reason);
  if (format == "json")
    return {"{\"model\":" + report::json_string(model) +
                ",\"not_identified\":" + report::json_string(reason) + "}",
            "application/json"};
  if (format == "html")
    return {"<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>" +
                report::html_escape(title) + "</title></head><body><p>" +
                report::html_escape(title + ": " + line) + "</p></body></html>\n",
            "text/html"};
  return {title + ": " + line + "\n", "text/plain"};
}

// Every announced model with its declared effects; a model the run cannot fit (no row: a
// manoeuvre that never meets its masks) or reads from an unhealthy channel is left out and named.
ResidualReply consistency_reply(const ingest::RunAnnouncement& announcement,
                                const std::vector<ingest::PreprocessedSegment>& segments,
                                const ingest::RunHealth& health, const ResidualRequest& request) {
  std::vector<residual::ModelParameters> fits;
  std::vector<std::string> left_out;
  for (const ingest::ModelSpec& spec : announcement.models) {
    try {
      const auto model = model::make_model(spec.model, spec.constants);
      if (const auto reason =
              ingest::unhealthy_reason(health, announcement, *model, spec.effects)) {
        left_out.push_back(spec.model + ": " + ingest::not_identified(*reason));
        continue;
      }
      fits.push_back(residual::compared_parameters(*model, spec.effects, segments, announcement));
    } catch (const InputError& e) {
      left_out.push_back(spec.model + ": " + e.what());
    }
  }
  const residual::Consistency c = residual::check_consistency(fits, request.reference);
  if (request.format == "json") return {report::consistency_json(c, left_out), "application/json"};
  return {report::format_consistency_text(c, left_out), "text/plain"};
}

// The rows SIMEX publishes where the bias test keeps least squares: the publication rule's own
// answer (residual/publication.hpp) without an IV fit.
std::vector<bool> simex_rows_where_least_squares_stands(
    const model::Model& model, const std::vector<std::string>& effects,
    const residual::SimexFit& simex, const std::vector<ingest::PreprocessedSegment>& segments,
    double rate, int odmf) {
  residual::FitOptions options;
  options.series = false;
  const residual::ModelFit ls = residual::fit_model(model, effects, segments, rate, odmf, options);
  const residual::Publication p =
      residual::publish(ls.parameters, ls.estimate, ls.column_norms, nullptr, &simex);
  if (p.estimator != residual::PublishedEstimator::kSimex)
    return std::vector<bool>(ls.parameters.size(), false);
  return p.replaced;
}

}  // namespace

ResidualReply residual_reply(const ingest::RunAnnouncement& announcement,
                             const std::vector<ingest::Chunk>& chunks, const ResidualRequest& request) {
  if (request.kind == "export") return export_reply(announcement, chunks, request);
  if (request.format != "text" && request.format != "html" && request.format != "json")
    throw InputError("residual report: format '" + request.format + "' (text, json or html)");
  if (request.rounds < 0 || request.rounds > 10)
    throw InputError("trace: rounds " + std::to_string(request.rounds) + " (0 to 10)");
  if ((request.kind == "consistency" || request.kind == "iv" || request.kind == "simex") && request.format == "html")
    throw InputError(request.kind + " report: format 'html' (text or json)");
  // The models a reference may name: the request's, or for consistency every announced one that
  // can be made (consistency_reply names those it leaves out).
  const bool consistency = request.kind == "consistency";
  const ingest::ModelSpec* spec =
      consistency ? nullptr : &announced_model(announcement, request.model);
  std::vector<std::unique_ptr<model::Model>> models;
  if (spec != nullptr) models.push_back(model::make_model(spec->model, spec->constants));
  for (std::size_t k = 0; consistency && k < announcement.models.size(); ++k) {
    try {
      models.push_back(
          model::make_model(announcement.models[k].model, announcement.models[k].constants));
    } catch (const InputError&) {  // left out, and named, by consistency_reply
    }
  }
  check_reference_names(request.reference, models, consistency);
  const ingest::RecordedRun run = ingest::assemble_run(announcement, chunks);
  const auto segments = ingest::preprocess_offline(run);
  if (segments.empty())
    throw InputError("run " + announcement.vehicle + "/" + announcement.run + ": no valid segment long enough to filter");
  const ingest::RunHealth health = ingest::channel_health(run);
  if (consistency) return consistency_reply(announcement, segments, health, request);
  const std::vector<std::string> declared = request.effects.value_or(spec->effects);
  const model::Model& model = *models.front();
  const double rate = announcement.sample_rate_hz;
  const int odmf = announcement.preprocessing.odmf;
  const std::string title = announcement.vehicle + " / " + announcement.run + " / " + spec->model;
  // The effects compared or screened read channels too: the candidate's as well as the declared.
  std::vector<std::string> read = declared;
  if (!request.effect.empty()) read.push_back(request.effect);
  if (const auto reason = ingest::unhealthy_reason(health, announcement, model, read))
    return not_identified_reply(title, spec->model, *reason, request.format);
  if (request.kind == "iv") {
    const residual::IvFit fit = iv_of(model, declared, announcement, segments);
    if (request.format == "json") return {report::iv_json(fit), "application/json"};
    return {report::format_iv_text(fit), "text/plain"};
  }
  if (request.kind == "simex") {  // the live judgement's fit (same noise, same draws), on demand
    const residual::SimexFit fit =
        simex_of(model, declared, run, segments, run_noise(run, segments));
    const std::vector<bool> by_simex =
        simex_rows_where_least_squares_stands(model, declared, fit, segments, rate, odmf);
    if (request.format == "json") return {report::simex_json(fit, by_simex), "application/json"};
    return {report::format_simex_text(fit, by_simex), "text/plain"};
  }
  if (request.kind == "trace") {
    residual::TraceOptions options;
    options.max_rounds = request.rounds;
    options.reference = request.reference;
    options.diagnosis.declared_noise = announcement.preprocessing.channel_noise;  // the profile's
    return trace_reply(residual::trace(model, declared, run, options), title, request.format,
                       request.series);
  }
  if (request.effect.empty()) {
    residual::DiagnosisOptions options;
    options.screen.only = request.candidates;
    options.declared_noise = announcement.preprocessing.channel_noise;  // the profile's
    return diagnosis_reply(residual::diagnose(model, declared, run, segments, options), title,
                           request.format);
  }
  const residual::EffectComparison cmp = residual::compare_effect(
      model, declared, request.effect, segments, rate, odmf, {}, request.reference);
  if (request.format == "json")
    return {report::comparison_json(cmp, request.series), "application/json"};
  if (request.format == "html") return {report::residual_html({title, nullptr, &cmp}), "text/html"};
  return {report::format_comparison_text(cmp), "text/plain"};
}

residual::IvFit iv_of(const model::Model& model, const std::vector<std::string>& effects,
                      const ingest::RunAnnouncement& announcement,
                      const std::vector<ingest::PreprocessedSegment>& segments) {
  residual::IvOptions options;
  options.preprocessing = announcement.preprocessing;
  return residual::iv_fit(model, effects, segments, announcement.sample_rate_hz, announcement.preprocessing.odmf,
                          options);
}

std::vector<residual::ChannelNoise> run_noise(const ingest::RecordedRun& run,
                                              const std::vector<ingest::PreprocessedSegment>& segments) {
  return residual::measure_channel_noise(run, segments, run.announcement.preprocessing.channel_noise);
}

residual::SimexFit simex_of(const model::Model& model, const std::vector<std::string>& effects,
                            const ingest::RecordedRun& run, const std::vector<ingest::PreprocessedSegment>& segments,
                            const std::vector<residual::ChannelNoise>& noise) {
  return residual::simex_fit(model, effects, run, segments, noise);
}

std::map<std::string, LiveVerdict> live_verdicts(const ingest::RunAnnouncement& announcement,
                                                 const std::vector<ingest::Chunk>& chunks,
                                                 const std::vector<std::string>& models,
                                                 bool diagnose) {
  std::map<std::string, LiveVerdict> out;
  const ingest::RecordedRun run = ingest::assemble_run(announcement, chunks);
  const auto segments = ingest::preprocess_offline(run);
  if (segments.empty()) return out;
  residual::DiagnosisOptions options;
  options.declared_noise = announcement.preprocessing.channel_noise;  // the profile's
  std::optional<std::vector<residual::ChannelNoise>> noise;  // measured once, when a model needs it
  residual::FloorCache floors(run, segments);  // the models' diagnoses share noise and draws
  const ingest::RunHealth health = ingest::channel_health(run);
  for (const ingest::ModelSpec& spec : announcement.models) {
    if (std::find(models.begin(), models.end(), spec.model) == models.end()) continue;
    LiveVerdict verdict;
    std::unique_ptr<model::Model> model;
    try {
      model = model::make_model(spec.model, spec.constants);
    } catch (const InputError&) {
      continue;  // the server folds no such model either
    }
    // No verdict on a model read from an unhealthy channel: "adequate" would read as a result.
    if (ingest::unhealthy_reason(health, announcement, *model, spec.effects)) continue;
    try {
      if (diagnose) {
        const residual::Diagnosis d =
            residual::diagnose(*model, spec.effects, run, segments, options, floors);
        const bool measured = std::all_of(
            d.floor.groups.begin(), d.floor.groups.end(),
            [](const residual::GroupFloor& g) { return g.rows == 0 || g.floor_rms > 0.0; });
        if (measured)
          verdict.verdict = residual::verdict_name(d.verdict), verdict.statement = d.statement();
      }
    } catch (const InputError&) {
      // Not diagnosable yet (no row of this model so far): no verdict rather than a wrong one.
    }
    try {
      verdict.iv = iv_of(*model, spec.effects, announcement, segments);
    } catch (const InputError&) {
      // No row yet: no IV estimate (a refusal for weak instruments is a result, not this).
    }
    // SIMEX beside IV too: where IV replaces least squares, SIMEX stands in for it when Hausman's
    // comparison of the two says its noise model holds (residual/publication.hpp).
    try {
      if (!noise) noise = run_noise(run, segments);
      verdict.simex = simex_of(*model, spec.effects, run, segments, *noise);
    } catch (const InputError&) {
      // No row yet: no correction.
    }
    if (!verdict.verdict.empty() || verdict.iv || verdict.simex) out[spec.model] = std::move(verdict);
  }
  return out;
}

}  // namespace dynid::server
